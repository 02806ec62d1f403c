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
#include <memory>

#include "cooker/cache/cook_cache.h"
#include "cooker/clip/clip_events.h"
#include "cooker/cook_internal.h"
#include "cooker/model/cook_settings.h"
#include "cooker/import/import_scene.h"
#include "cooker/mesh/mesh_build.h"
#include "cooker/clip/root_motion.h"
#include "cooker/retarget/retarget_clips.h"
#include "cooker/write/write_ossa.h"
#include "cooker/texture/texture_cook.h"
#include <ossa/format/hash.h>
#include <ossa/loader/asset.h>

namespace ossa::cook {
namespace fs = std::filesystem;

namespace detail {

Result<std::vector<uint8_t>> read_bytes(const fs::path& path) { return read_input(path); }

/// What a cook read, every file counted: the source and what it references (a glTF's buffers and
/// images, an OBJ's materials), its sidecar and settings files, a graph's sources.
uint64_t bytes_read(const std::vector<InputFile>& files) {
  uint64_t total = 0;
  for (const InputFile& f : files)
    if (f.present) total += f.size;
  return total;
}

/// A warning as the output keeps it: the input's directory (as given and absolute) left out of the
/// paths it names, so the bytes do not depend on where the tree lives or where the cook ran from.
std::string portable_warning(std::string warning, const fs::path& input) {
  std::error_code ec;
  const fs::path given = input.parent_path();
  const fs::path absolute = fs::absolute(input, ec).lexically_normal().parent_path();
  for (const fs::path& dir : {absolute, given}) {
    if (dir.empty()) continue;
    const std::string prefix = dir.string() + "/";
    for (size_t at = warning.find(prefix); at != std::string::npos; at = warning.find(prefix, at))
      warning.erase(at, prefix.size());
  }
  return warning;
}

bool finish_provenance(WriteProvenance& provenance, CookRecord& record, const fs::path& input,
                       const CookOptions& options) {
  provenance.source_name = input.filename().string();
  for (const std::string& w : record.warnings) provenance.warnings.push_back(portable_warning(w, input));
  provenance.options = options.canonical();
  const InputLog* log = current_input_log();
  record.inputs_read = log != nullptr ? log->files() : std::vector<InputFile>{};
  record.source_bytes = bytes_read(record.inputs_read);
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
      if (Status st = extract_root_motion(clip, scene.skeleton, 1); !st) return Error{label + ": " + st.message()};
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
      r.stored_bytes = static_cast<uint32_t>(
          4 * t.vertices.size() + 2 * (t.position_deltas.size() + t.normal_deltas.size() + t.tangent_deltas.size()));
      r.position_error_mm = static_cast<float>(mm * t.position_error);
      r.position_bound_mm = static_cast<float>(mm * t.position_bound);
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
    record.error = input.string() + ": " + st.message();  // the input it concerns, then the file and the cause
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
  // The output must be this input's: `x.obj` then `x.gltf` cooked into one folder share an output
  // name, and the OBJ's inputs being unchanged says nothing about the glTF. The recorded source
  // (its name, which carries its kind: importer by extension, or graph) must be this input, and
  // be among the inputs re-hashed below.
  const std::string source_name = input.filename().string();
  if (flatbuffers::GetStringView(prov->source_name()) != source_name) return false;
  bool source_listed = false;
  for (const fb::InputFile* f : *prov->inputs())
    source_listed |= f->path() != nullptr && f->path()->string_view() == source_name && !f->absent();
  if (!source_listed) return false;
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
  record.source_bytes = detail::bytes_read(files);
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
  // The warnings of the cook that wrote it; a file from a cooker before the field has none to give.
  record.warnings.clear();
  if (prov->warnings() != nullptr)
    for (const flatbuffers::String* w : *prov->warnings())
      if (w != nullptr) record.warnings.push_back(w->str());
  return true;
}

/// A hit of the shared cook cache (cooker/cache/cook_cache.h): the verified output written
/// atomically as a cook writes it, and the record the up-to-date check of the written file gives
/// (so its counts and inputs are those of the file). False on a miss, or when the files changed
/// between the lookup and the check (the cook then runs and rewrites the output).
bool from_cache(CookRecord& record, const fs::path& input, const fs::path& output, const CookOptions& options) {
  if (options.cache == nullptr || options.cache_looked_up || options.force || !options.write) return false;
  const std::optional<std::vector<uint8_t>> bytes = cache_lookup(*options.cache, record, input, options.canonical());
  if (!bytes) return false;
  if (Status st = write_file_atomic(output, *bytes); !st) return false;  // the cook meets it too and says so
  if (!up_to_date(record, input, output, options)) return false;
  record.up_to_date = false;
  record.cache_hit = true;
  record.cooked_bytes = bytes->size();
  return true;
}

/// The warning for a source with clips and no mesh cooked with a rig of its own: its clips play
/// only on that rig. Not for a folder's rig itself, nor for BVH (motion capture brings its rig).
void warn_own_rig(CookRecord& record, const fs::path& input, const CookOptions& options) {
  std::string ext = input.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".bvh" || has_folder_rig_name(input)) return;
  std::string why =
      "holds clips and no mesh, so it is cooked with a rig of its own and its clips play only on that rig";
  if (!options.folder_rig.empty())
    why += " (its folder's rig " + options.folder_rig.filename().string() + " could not be read)";
  record.warnings.push_back(why +
                            ": name the character's rig with --skeleton RIG.ossa or a \"skeleton\" cook setting, or "
                            "cook it in one batch with a skeleton.* or <folder>.* source beside it (docs/COOKING.md)");
}

/// Cooks `input` with `options`, or with `rig_options` (the folder rig's) when it holds clips and no
/// mesh; `*used` says which (true: rig_options).
void cook_into(CookRecord& record, const fs::path& input, const fs::path& output, const CookOptions& options,
               const AppliedSettings& settings, const CookOptions* rig_options = nullptr, bool* used = nullptr) {
  std::error_code ec;
  if (fs::is_directory(input, ec)) {
    record.error = input.string() + ": is a directory, not a source file";
    return;
  }
  if (is_graph_file(input) && options.retarget_target != nullptr) {
    record.error = input.string() +
                   ": --retarget-to applies to sources, not graph files (retarget the clips a graph "
                   "plays, then cook the graph: docs/RETARGET.md)";
    return;
  }
  if (is_graph_file(input)) {
    if (!settings.clip_names.empty())
      record.warnings.push_back(
          "\"clip_names\" in cook settings is not used for a graph file: the graph names its clips");
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
  import_options.up_axis = options.up_axis;
  auto scene = import_scene(input.string(), import_options);
  if (!scene) {
    record.error = scene.error().message;
    return;
  }
  record.warnings = scene->warnings;
  count_scene(record, *scene);
  if (scene->meshes.empty() && !scene->clips.empty() && options.reference == nullptr &&
      options.retarget_target == nullptr) {
    // Clips without a mesh: against the folder's rig when the batch has one, else said.
    if (rig_options != nullptr) {
      if (used != nullptr) *used = true;
      return cook_into(record, input, output, *rig_options, settings);
    }
    warn_own_rig(record, input, options);
  }
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
    RetargetTarget target{options.retarget_target, options.retarget_name, options.retarget_map,
                          options.retarget_map_name};
    if (Status st = retarget_scene(*scene, target, input.string(), &record.retarget_records); !st) {
      record.error = st.message();
      return;
    }
    count_scene(record, *scene);
  }

  MeshOptions mesh_options;
  mesh_options.float_vertices = options.float_vertices;
  mesh_options.cloth = options.cloth;
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
  write_options.include_skeleton =
      (options.reference == nullptr && options.retarget_target == nullptr) || !meshes->empty();
  const std::vector<uint8_t> bytes = write_ossa(*scene, *meshes, *clips, provenance, write_options);
  if (!detail::write_verified(record, bytes, input, output, options.write)) return;

  record.ok = true;
  if (!write_options.include_skeleton) record.joints = 0;  // the file carries no rig of its own
}

}  // namespace

namespace {

/// cook_file's body. With only_if_up_to_date, stops after the up-to-date check and the cache
/// lookup: the record of an up-to-date output or a cache hit, or nullopt for anything else
/// (settings that fail, --force, a stale output and a miss: the miss's cache fields go to `miss`).
std::optional<CookRecord> cook_or_check(const fs::path& input, const fs::path& output, const CookOptions& batch_options,
                                        bool only_if_up_to_date, CookRecord* miss = nullptr) {
  CookRecord record;
  record.input = input.string();
  record.output = output.string();
  const auto start = std::chrono::steady_clock::now();
  InputLog log;
  InputLogScope scope(&log);
  // The batch's options with this input's settings files layered over them (cook_settings.h).
  CookOptions options = batch_options;
  // The folder rig (cook_options.h) lies in the output tree, outside the read sandbox: read before
  // it, and kept out of this input's log (it enters the key through canonical(), as --skeleton's).
  std::unique_ptr<SourceSkeleton> folder_rig;
  InputFile folder_rig_input;
  if (!options.folder_rig.empty() && options.reference == nullptr && options.retarget_target == nullptr &&
      !is_graph_file(input)) {
    InputLog rig_log;
    InputLogScope rig_scope(&rig_log);
    if (auto rig = load_reference_skeleton(options.folder_rig, &folder_rig_input))
      folder_rig = std::make_unique<SourceSkeleton>(std::move(*rig));
  }
  AppliedSettings settings;
  std::vector<fs::path> allowed = options.allow_dirs;
  allowed.push_back(options.root.empty() ? input.parent_path() : options.root);
  if (allowed.back().empty()) allowed.back() = ".";
  ReadSandboxScope sandbox(allowed, options.allow_hard_links);
  try {
    if (Status st = apply_cook_settings(input, options, settings); !st) {
      if (only_if_up_to_date) return std::nullopt;
      record.error = input.string() + ": cook settings: " + st.message();
    } else {
      // The folder rig applies unless a settings file named a rig; an output cooked either way
      // may be up to date.
      CookOptions rig_options = options;
      const bool rig = folder_rig != nullptr && options.reference == nullptr;
      if (rig) {
        rig_options.reference = folder_rig.get();
        rig_options.reference_name = options.folder_rig.filename().string();
        rig_options.reference_input = folder_rig_input;
      }
      const bool fresh = !options.force && (up_to_date(record, input, output, options) ||
                                            (rig && up_to_date(record, input, output, rig_options)));
      if (fresh) {
        // the record is the output's
      } else if (only_if_up_to_date) {
        if (!from_cache(record, input, output, options) && !(rig && from_cache(record, input, output, rig_options))) {
          if (miss != nullptr) {
            miss->cache_note = record.cache_note;
            miss->cache_down = record.cache_down;
            miss->cache_bytes_fetched = record.cache_bytes_fetched;
          }
          return std::nullopt;
        }
      } else if (!from_cache(record, input, output, options) &&
                 !(rig && from_cache(record, input, output, rig_options))) {
        bool used_rig = false;
        cook_into(record, input, output, options, settings, rig ? &rig_options : nullptr, &used_rig);
        if (record.ok && options.write && options.cache != nullptr)  // under the key of the options it took
          cache_store_output(*options.cache, record, output, (used_rig ? rig_options : options).canonical());
      }
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
                                            const CookOptions& batch_options, CookRecord* cache_miss) {
  return cook_or_check(input, output, batch_options, true, cache_miss);
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

}  // namespace ossa::cook
