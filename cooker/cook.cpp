// cook.cpp — one source file to one .ossa file (see cook.h): import, attach sidecar events, build
// meshes, compress clips, write, rename. Graph files go to cook_graph.cpp, which shares these steps.
#include "cooker/cook.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>

#include "cooker/clip/clip_events.h"
#include "cooker/cook_internal.h"
#include "cooker/cook_settings.h"
#include "cooker/import/import_scene.h"
#include "cooker/mesh/mesh_build.h"
#include "cooker/clip/root_motion.h"
#include "cooker/write/write_ossa.h"
#include "cooker/texture/texture_cook.h"
#include <ossa/format/hash.h>
#include <ossa/loader/asset.h>

namespace ossa::cook {
namespace fs = std::filesystem;

bool is_graph_file(const fs::path& path) {
  std::string name = path.filename().string();
  std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  constexpr std::string_view kSuffix = ".graph.json";
  return name.size() > kSuffix.size() && name.compare(name.size() - kSuffix.size(), kSuffix.size(), kSuffix) == 0;
}

std::string CookOptions::canonical() const {
  std::string s = float_vertices ? "vertices=float32" : "vertices=quantized";
  if (!clips.enabled) {
    s += ";clips=lossless";
  } else {
    char buf[96];
    std::snprintf(buf, sizeof buf, ";clips=%gm@%gm", static_cast<double>(clips.tolerance_metres),
                  static_cast<double>(clips.probe_metres));
    s += buf;
  }
  if (root_motion) s += std::string(";root_motion=") + "xyz"[up_axis % 3];
  if (textures != TextureOutput::Compressed) s += std::string(";textures=") + texture_output_name(textures);
  if (metres_per_unit > 0.0f) {
    char unit[64];
    std::snprintf(unit, sizeof unit, ";unit=%gm", static_cast<double>(metres_per_unit));
    s += unit;
  }
  // The rig by name and content: the reference usually lives in the output tree, outside the
  // input's directory, so it enters the key through its hash here rather than as a relative path.
  if (reference != nullptr) {
    s += ";skeleton=" + reference_name;
    if (reference_input.present) s += "@" + hex64(reference_input.hash);
  }
  if (retarget_target != nullptr) {
    s += ";retarget=" + retarget_name;
    if (retarget_input.present) s += "@" + hex64(retarget_input.hash);
  }
  if (retarget_map != nullptr) {
    s += ";map=" + retarget_map_name;
    if (retarget_map_input.present) s += "@" + hex64(retarget_map_input.hash);
  }
  return s;
}

namespace detail {

Result<std::vector<uint8_t>> read_bytes(const fs::path& path) { return read_input(path); }

bool finish_provenance(WriteProvenance& provenance, CookRecord& record, const fs::path& input,
                       const CookOptions& options) {
  provenance.source_name = input.filename().string();
  provenance.options = options.canonical();
  const InputLog* log = current_input_log();
  record.inputs_read = log != nullptr ? log->files() : std::vector<InputFile>{};
  provenance.inputs = relative_inputs(record.inputs_read, input.parent_path());
  provenance.cook_key = cook_key(provenance.inputs, provenance.options);
  record.cook_key = provenance.cook_key;
  for (const InputFile& f : provenance.inputs)
    if (f.path == provenance.source_name) provenance.source_hash = f.hash;
  if (log != nullptr && !log->refusals().empty()) {
    record.error = refusal_error(input, *log);
    return false;
  }
  return true;
}

std::string refusal_error(const fs::path& input, const InputLog& log) {
  const auto& refusals = log.refusals();
  std::string s = input.string() + ": " + refusals.front();
  if (refusals.size() > 1) s += " (and " + std::to_string(refusals.size() - 1) + " more refused reads)";
  return s;
}

Result<std::vector<CompressedClip>> cook_clips(SourceScene& scene, const CookOptions& options, CookRecord& record,
                                               const std::string& label) {
  if (options.root_motion) {
    for (SourceClip& clip : scene.clips) {
      if (Status st = extract_root_motion(clip, scene.skeleton, options.up_axis); !st)
        return Error{label + ": " + st.message()};
    }
  }
  std::vector<CompressedClip> clips;
  for (const SourceClip& clip : scene.clips) {
    auto compressed = compress_clip(clip, scene.skeleton, scene.metres_per_unit, options.clips);
    if (!compressed) return Error{label + ": " + compressed.error().message};
    ClipRecord cr;
    cr.name = compressed->name;
    cr.joints = static_cast<uint32_t>(scene.skeleton.joints.size());
    cr.frames = compressed->grid.frame_count;
    cr.raw_bytes = compressed->raw_bytes;
    cr.cooked_bytes = compressed->cooked_bytes;
    cr.max_error_mm = compressed->max_error * scene.metres_per_unit * 1000.0f;
    cr.mean_error_mm = compressed->mean_error * scene.metres_per_unit * 1000.0f;
    if (compressed->worst_joint < scene.skeleton.joints.size())
      cr.worst_joint = scene.skeleton.joints[compressed->worst_joint].name;
    if (compressed->tolerance > 0.0f && compressed->max_error > compressed->tolerance) {
      char buf[160];
      std::snprintf(buf, sizeof buf, "clip '%s': max error %.4f mm exceeds the %.4f mm tolerance", cr.name.c_str(),
                    static_cast<double>(cr.max_error_mm),
                    static_cast<double>(compressed->tolerance * scene.metres_per_unit * 1000.0f));
      record.warnings.push_back(buf);
    }
    record.clip_records.push_back(std::move(cr));
    clips.push_back(std::move(*compressed));
  }
  return clips;
}

void count_scene(CookRecord& record, const SourceScene& scene) {
  record.joints = static_cast<uint32_t>(scene.skeleton.joints.size());
  record.clips = static_cast<uint32_t>(scene.clips.size());
  record.materials = static_cast<uint32_t>(scene.materials.size());
  uint32_t textures = 0;
  for (const SourceMaterial& m : scene.materials) textures += static_cast<uint32_t>(m.textures.size());
  record.textures = textures;
  record.vertices_over_4_influences = scene.vertices_over_4_influences;
}

void count_meshes(CookRecord& record, const std::vector<CookedMesh>& meshes, const MeshBuildStats& stats) {
  record.meshes = static_cast<uint32_t>(meshes.size());
  uint32_t submeshes = 0;
  for (const CookedMesh& m : meshes) submeshes += static_cast<uint32_t>(m.submeshes.size());
  record.submeshes = submeshes;
  record.vertices = stats.cooked_vertices;
  record.triangles = stats.triangles;
}

void record_morphs(CookRecord& record, const std::vector<CookedMesh>& meshes, float metres_per_unit) {
  const double mm = 1000.0 * (metres_per_unit > 0.0f ? metres_per_unit : 1.0f);
  for (const CookedMesh& m : meshes)
    for (const CookedMorphTarget& t : m.morph_targets) {
      MorphRecord r;
      r.mesh = m.name;
      r.name = t.name;
      r.vertices = static_cast<uint32_t>(t.vertices.size());
      r.raw_bytes = t.source_bytes;
      r.stored_bytes = static_cast<uint32_t>(4 * t.vertices.size() +
                                             2 * (t.position_deltas.size() + t.normal_deltas.size() + t.tangent_deltas.size()));
      r.position_error_mm = static_cast<float>(mm * t.position_error);
      r.normal_error_deg = static_cast<float>(t.normal_error * 57.29577951308232);
      record.morph_records.push_back(std::move(r));
    }
}

bool write_verified(CookRecord& record, const std::vector<uint8_t>& bytes, const fs::path& input,
                    const fs::path& output, bool write) {
  // The writer's output must pass the same checks every reader makes; a cooker bug is caught here
  // rather than in a game.
  if (Status st = verify_buffer(bytes, output.filename().string()); !st) {
    record.error = input.string() + ": internal error, cooked bytes fail verification: " + st.message();
    return false;
  }
  if (!write) return true;  // --list-inputs: the cook ran to the end, nothing is written
  if (Status st = write_file_atomic(output, bytes); !st) {
    record.error = st.message();
    return false;
  }
  record.cooked_bytes = bytes.size();
  return true;
}

}  // namespace detail

namespace {

using detail::count_meshes;
using detail::count_scene;
using detail::read_bytes;

/// The up-to-date check (cook.h): the existing output's provenance lists what its cook read;
/// those files are re-read and re-hashed (a file listed absent must still be absent) and the key
/// recomputed with today's options and versions. Any doubt (no output, one that does not verify,
/// an older format without a key, a listed file now unreadable) means "cook it".
bool up_to_date(CookRecord& record, const fs::path& input, const fs::path& output, const CookOptions& options) {
  std::error_code ec;
  if (!fs::is_regular_file(output, ec)) return false;
  auto asset = Asset::open(output.string(), OpenMode::kRead);
  if (!asset) return false;
  const fb::Provenance* prov = asset->file().provenance();
  if (prov == nullptr || prov->inputs() == nullptr || prov->inputs()->size() == 0) return false;
  const std::string canonical = options.canonical();
  if (flatbuffers::GetStringView(prov->options()) != canonical) return false;
  const fs::path base = input.parent_path();
  InputLog log;
  InputLogScope scope(&log);
  for (const fb::InputFile* f : *prov->inputs()) {
    if (f->path() == nullptr) return false;
    const fs::path path = (base / fs::path(f->path()->str())).lexically_normal();
    if (f->absent()) {
      if (probe_input(path)) return false;  // it appeared: the cook would read it
    } else if (!hash_input(path)) {
      return false;
    }
  }
  const std::vector<InputFile> files = log.files();
  if (cook_key(relative_inputs(files, base), canonical) != prov->cook_key()) return false;
  record.ok = true;
  record.up_to_date = true;
  record.inputs_read = files;
  record.cook_key = prov->cook_key();
  record.cooked_bytes = fs::file_size(output, ec);
  const std::string main_input = fs::absolute(input, ec).lexically_normal().string();
  for (const InputFile& f : files)
    if (f.present && f.path == main_input) record.source_bytes = f.size;
  const SkeletonView sk = asset->skeleton();
  record.joints = static_cast<uint32_t>(sk.empty() ? 0 : sk.joint_count());
  record.meshes = static_cast<uint32_t>(asset->mesh_count());
  uint32_t vertices = 0, triangles = 0;
  for (size_t m = 0; m < asset->mesh_count(); ++m) {
    vertices += asset->mesh(m).vertex_count();
    triangles += asset->mesh(m).index_count() / 3;
  }
  record.vertices = vertices;
  record.triangles = triangles;
  record.clips = static_cast<uint32_t>(asset->clip_count());
  return true;
}

void cook_into(CookRecord& record, const fs::path& input, const fs::path& output, const CookOptions& options,
               const AppliedSettings& settings) {
  std::error_code ec;
  if (fs::is_directory(input, ec)) {
    record.error = input.string() + ": is a directory, not a source file";
    return;
  }
  if (is_graph_file(input) && options.retarget_target != nullptr) {
    record.error = input.string() + ": --retarget-to applies to sources, not graph files (a graph's retarget node "
                   "plays clips of another rig: docs/RETARGET.md)";
    return;
  }
  if (is_graph_file(input)) {
    if (!settings.clip_names.empty())
      record.warnings.push_back("\"clip_names\" in cook settings is not used for a graph file: the graph names its clips");
    detail::cook_graph(record, input, output, options);
    return;
  }
  auto source = read_bytes(input);
  if (!source) {
    record.error = source.error().message;
    return;
  }
  record.source_bytes = source->size();

  ImportOptions import_options;
  import_options.reference = options.reference;
  import_options.metres_per_unit = options.metres_per_unit;
  auto scene = import_scene(input.string(), import_options);
  if (!scene) {
    record.error = scene.error().message;
    return;
  }
  record.warnings = scene->warnings;
  count_scene(record, *scene);
  // Events authored beside the source (clip_events.h); its bytes count as the source's.
  auto sidecar = attach_sidecar_events(input, scene->clips);
  if (!sidecar) {
    record.error = sidecar.error().message;  // names the sidecar, line and column
    return;
  }
  if (sidecar->present) record.source_bytes += sidecar->bytes.size();
  // Settings rename clips after the sidecar (which speaks of the source's own clip names).
  if (Status st = rename_clips(settings.clip_names, scene->clips, input.string()); !st) {
    record.error = st.message();
    return;
  }
  if (options.retarget_target != nullptr) {
    RetargetTarget target{options.retarget_target, options.retarget_name, options.retarget_map, options.retarget_map_name};
    if (Status st = retarget_scene(*scene, target, input.string(), &record.retarget_records); !st) {
      record.error = st.message();
      return;
    }
    count_scene(record, *scene);
  }

  MeshOptions mesh_options;
  mesh_options.float_vertices = options.float_vertices;
  MeshBuildStats stats;
  auto meshes = build_meshes(*scene, mesh_options, &stats, &record.warnings);
  if (!meshes) {
    record.error = input.string() + ": " + meshes.error().message;
    return;
  }
  count_meshes(record, *meshes, stats);
  detail::record_morphs(record, *meshes, scene->metres_per_unit);

  auto clips = detail::cook_clips(*scene, options, record, input.string());
  if (!clips) {
    record.error = clips.error().message;
    return;
  }
  if (Status st = cook_textures(*scene, options.textures, input.string(), record.texture_records); !st) {
    record.error = st.message();
    return;
  }

  WriteProvenance provenance;
  if (!detail::finish_provenance(provenance, record, input, options)) return;
  // A clip-only file binds to its rig by hash and carries no skeleton; a file with meshes always
  // carries the rig its joint palettes index (with --skeleton, the reference's, hash-identical).
  WriteOptions write_options;
  write_options.include_skeleton = (options.reference == nullptr && options.retarget_target == nullptr) || !meshes->empty();
  const std::vector<uint8_t> bytes = write_ossa(*scene, *meshes, *clips, provenance, write_options);
  if (!detail::write_verified(record, bytes, input, output, options.write)) return;

  record.ok = true;
  if (!write_options.include_skeleton) record.joints = 0;  // the file carries no rig of its own
}

}  // namespace

namespace {

/// cook_file's body. With only_if_up_to_date, stops after the up-to-date check: the record of an
/// up-to-date output, or nullopt for anything else (settings that fail, --force, a stale output).
std::optional<CookRecord> cook_or_check(const fs::path& input, const fs::path& output, const CookOptions& batch_options,
                                        bool only_if_up_to_date) {
  CookRecord record;
  record.input = input.string();
  record.output = output.string();
  const auto start = std::chrono::steady_clock::now();
  InputLog log;
  InputLogScope scope(&log);
  // The batch's options with this input's settings files layered over them (cook_settings.h).
  CookOptions options = batch_options;
  AppliedSettings settings;
  std::vector<fs::path> allowed = options.allow_dirs;
  allowed.push_back(options.root.empty() ? input.parent_path() : options.root);
  if (allowed.back().empty()) allowed.back() = ".";
  ReadSandboxScope sandbox(allowed);
  try {
    if (Status st = apply_cook_settings(input, options, settings); !st) {
      if (only_if_up_to_date) return std::nullopt;
      record.error = input.string() + ": cook settings: " + st.message();
    } else if (options.force || !up_to_date(record, input, output, options)) {
      if (only_if_up_to_date) return std::nullopt;
      cook_into(record, input, output, options, settings);
    }
  } catch (const std::exception& e) {
    if (only_if_up_to_date) return std::nullopt;
    record.ok = false;
    record.error = input.string() + ": unexpected failure: " + e.what();
  } catch (...) {
    if (only_if_up_to_date) return std::nullopt;
    record.ok = false;
    record.error = input.string() + ": unexpected failure";
  }
  if (!record.ok && record.inputs_read.empty()) record.inputs_read = log.files();  // as far as it got
  // A read the sandbox refused is the cause to name, whatever the importer made of the missing file.
  if (!record.ok && !log.refusals().empty() && record.error.find(log.refusals().front()) == std::string::npos)
    record.error = detail::refusal_error(input, log) + "; then: " + record.error;
  // --skeleton's, --retarget-to's and --map's files are keyed through the options (canonical());
  // the depfile still names them.
  if (!is_graph_file(input)) {
    const std::pair<bool, const InputFile*> keyed[] = {{options.reference != nullptr, &options.reference_input},
                                                       {options.retarget_target != nullptr, &options.retarget_input},
                                                       {options.retarget_map != nullptr, &options.retarget_map_input}};
    bool added = false;
    for (const auto& [used, file] : keyed)
      if (used && file->present) record.inputs_read.push_back(*file), added = true;
    if (added)
      std::sort(record.inputs_read.begin(), record.inputs_read.end(),
                [](const InputFile& a, const InputFile& b) { return a.path < b.path; });
  }
  record.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return record;
}

}  // namespace

CookRecord cook_file(const fs::path& input, const fs::path& output, const CookOptions& batch_options) {
  return *cook_or_check(input, output, batch_options, false);
}

std::optional<CookRecord> up_to_date_record(const fs::path& input, const fs::path& output,
                                            const CookOptions& batch_options) {
  return cook_or_check(input, output, batch_options, true);
}

Result<SourceSkeleton> load_reference_skeleton(const fs::path& ossa_file, InputFile* as_read) {
  if (as_read != nullptr) {
    InputLog log;
    InputLogScope scope(&log);
    auto bytes = read_input(ossa_file);
    if (!bytes) return bytes.error();
    *as_read = log.files().front();
  }
  auto asset = Asset::open(ossa_file.string());
  if (!asset) return asset.error();
  const SkeletonView sk = asset->skeleton();
  if (sk.empty() || sk.joint_count() == 0) return Error{ossa_file.string() + ": holds no skeleton to cook against"};
  SourceSkeleton out;
  out.metres_per_unit = asset->file().metres_per_unit();
  out.joints.resize(sk.joint_count());
  for (size_t i = 0; i < sk.joint_count(); ++i) {
    SourceJoint& j = out.joints[i];
    j.name = std::string(sk.joint_name(i));
    j.parent = sk.parents()[i];
    const fb::Vec3& t = sk.bind_translations()[i];
    const fb::Quat& r = sk.bind_rotations()[i];
    const fb::Vec3& s = sk.bind_scales()[i];
    j.translation = {t.x(), t.y(), t.z()};
    j.rotation = glm::quat(r.w(), r.x(), r.y(), r.z());
    j.scale = {s.x(), s.y(), s.z()};
    const auto* m = sk.inverse_bind()[i].m();
    for (int c = 0; c < 4; ++c)
      for (int r4 = 0; r4 < 4; ++r4) j.inverse_bind[c][r4] = m->Get(static_cast<flatbuffers::uoffset_t>(c * 4 + r4));
  }
  return out;
}

Result<tools::HumanoidMapFile> load_humanoid_map_file(const fs::path& path, InputFile* as_read) {
  InputLog log;
  InputLogScope scope(&log);
  auto bytes = read_input(path);
  if (!bytes) return bytes.error();
  if (as_read != nullptr) *as_read = log.files().front();
  return tools::parse_humanoid_map_file(std::string_view(reinterpret_cast<const char*>(bytes->data()), bytes->size()),
                                        path.string());
}

namespace {

/// Removes `.<name>.tmp-<pid>-<n>` files in `dir` left by a cook whose process no longer exists
/// (a worker or a whole ossa-cook killed mid-write). A live process's temporaries are kept.
void remove_stale_temporaries(const fs::path& dir, const std::string& name) {
  const std::string prefix = "." + name + ".tmp-";
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string entry = it->path().filename().string();
    if (entry.rfind(prefix, 0) != 0) continue;
    const long pid = std::strtol(entry.c_str() + prefix.size(), nullptr, 10);
    if (pid <= 0 || pid == static_cast<long>(::getpid())) continue;
    if (::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH) ::unlink(it->path().c_str());
  }
}

}  // namespace

Status write_file_atomic(const fs::path& path, const std::vector<uint8_t>& bytes) {
  static std::atomic<unsigned> counter{0};
  std::error_code ec;
  const fs::path dir = path.parent_path().empty() ? fs::path(".") : path.parent_path();
  // A read-only file is the user's way of saying "do not replace": rename(2) would, so it is
  // refused here (by its mode bits, which also hold for root, whom access(2) lets write anything).
  struct stat existing{};
  if (::stat(path.c_str(), &existing) == 0 && S_ISREG(existing.st_mode) &&
      (existing.st_mode & (S_IWUSR | S_IWGRP | S_IWOTH)) == 0)
    return Error{path.string() + ": is read-only, not replaced (make it writable or remove it)"};
  fs::create_directories(dir, ec);
  if (ec) return Error{path.string() + ": cannot create directory " + dir.string() + ": " + ec.message()};
  remove_stale_temporaries(dir, path.filename().string());
  const fs::path tmp = dir / ("." + path.filename().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                              std::to_string(counter.fetch_add(1)));
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) return Error{path.string() + ": cannot create " + tmp.string() + ": " + std::strerror(errno)};
  size_t done = 0;
  bool ok = true;
  std::string why;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      ok = false;
      why = std::strerror(errno);
      break;
    }
    done += static_cast<size_t>(n);
  }
  if (ok && ::fsync(fd) != 0) {
    ok = false;
    why = std::strerror(errno);
  }
  if (::close(fd) != 0 && ok) {
    ok = false;
    why = std::strerror(errno);
  }
  if (ok && std::rename(tmp.c_str(), path.c_str()) != 0) {
    ok = false;
    why = std::strerror(errno);
  }
  if (!ok) {
    ::unlink(tmp.c_str());
    return Error{path.string() + ": write failed: " + why};
  }
  return {};
}

}  // namespace ossa::cook
