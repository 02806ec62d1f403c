// batch.cpp — output planning, the limits' defaults, the batch around the worker processes
// (cooker/cli/worker.h) and the report document (see batch.h).
#include "cooker/cli/batch.h"

#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <set>

#include "cooker/cli/worker.h"
#include "runtime/internal/message.h"

#include <ossa/version.h>

namespace ossa::cook {
namespace fs = std::filesystem;

bool is_source_extension(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".fbx" || ext == ".gltf" || ext == ".glb" || ext == ".dae" || ext == ".bvh" || ext == ".obj";
}

std::string output_stem(const fs::path& input) {
  const std::string name = input.filename().string();
  if (is_graph_file(input)) return name.substr(0, name.size() - std::string_view(".graph.json").size());
  return input.stem().string();
}

Result<std::vector<BatchItem>> plan_batch(const std::vector<fs::path>& inputs, const fs::path& out_dir,
                                          const fs::path& root) {
  std::vector<std::pair<fs::path, fs::path>> files;  // input, its tree
  for (const fs::path& input : inputs) {
    std::error_code ec;
    if (fs::is_directory(input, ec)) {
      std::vector<fs::path> found;
      for (fs::recursive_directory_iterator it(input, ec), end; !ec && it != end; it.increment(ec))
        if (it->is_regular_file(ec) && (is_source_extension(it->path()) || is_graph_file(it->path())))
          found.push_back(it->path());
      if (ec) return Error{input.string() + ": cannot list directory: " + ec.message()};
      std::sort(found.begin(), found.end());
      for (fs::path& f : found) files.push_back({std::move(f), input});
    } else {
      files.push_back({input, input.parent_path()});
    }
  }

  std::vector<BatchItem> items;
  std::map<fs::path, fs::path> claimed;  // output -> first input that maps to it
  std::error_code root_ec;
  if (!root.empty() && !fs::is_directory(root, root_ec))
    return Error{"--root " + root.string() + ": " + (fs::exists(root, root_ec) ? "is not a directory" : "does not exist")};
  const fs::path abs_root = root.empty() ? fs::path() : fs::weakly_canonical(fs::absolute(root));
  for (const auto& [input, tree] : files) {
    fs::path sub;
    if (!root.empty()) {
      const fs::path abs_in = fs::weakly_canonical(fs::absolute(input));
      const fs::path rel = abs_in.lexically_relative(abs_root);
      if (rel.empty() || *rel.begin() == "..")
        return Error{input.string() + ": is not inside --root " + root.string()};
      sub = rel.parent_path();
    }
    fs::path output = (out_dir / sub / output_stem(input)).concat(".ossa").lexically_normal();
    auto [it, inserted] = claimed.emplace(output, input);
    if (!inserted)
      return Error{"inputs " + it->second.string() + " and " + input.string() + " would both write " +
                   output.string() +
                   (root.empty() ? " (use --root to mirror the source tree)" : " (cook them into separate output directories)")};
    items.push_back({input, output, tree});
  }
  return items;
}

uint64_t default_max_memory(unsigned workers) {
  uint64_t available = 0;
  const long pages = ::sysconf(_SC_PHYS_PAGES), page_size = ::sysconf(_SC_PAGESIZE);
  if (pages > 0 && page_size > 0) available = static_cast<uint64_t>(pages) * static_cast<uint64_t>(page_size);
  // In a container the cgroup's limit, not the machine's memory, is what the kernel enforces.
  for (const char* file : {"/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"}) {
    std::ifstream in(file);
    uint64_t limit = 0;
    if (in >> limit && limit > 0 && (available == 0 || limit < available)) available = limit;
  }
  constexpr uint64_t kGiB = uint64_t{1} << 30, kMiB = uint64_t{1} << 20;
  const uint64_t share = static_cast<uint64_t>(0.8 * static_cast<double>(available)) / std::max(1u, workers);
  return std::max(kGiB, share / kMiB * kMiB);
}

std::optional<uint64_t> parse_size(const std::string& text) {
  double value = 0.0;
  const char* const end = text.data() + text.size();
  const auto [unit_at, ec] = std::from_chars(text.data(), end, value, std::chars_format::fixed);
  if (ec != std::errc() || !(value >= 0.0)) return std::nullopt;
  std::string unit(unit_at, end);
  std::transform(unit.begin(), unit.end(), unit.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  double scale = 1.0;
  if (!unit.empty() && unit != "b") {
    const size_t power = std::string_view("kmgt").find(unit[0]);
    const std::string rest = unit.substr(1);
    if (power == std::string_view::npos || !(rest.empty() || rest == "b" || rest == "ib")) return std::nullopt;
    scale = std::pow(1024.0, static_cast<double>(power + 1));
  }
  const double bytes = value * scale;
  if (!(bytes < 18446744073709549568.0)) return std::nullopt;  // the largest double below 2^64
  return static_cast<uint64_t>(bytes);
}

std::vector<CookRecord> run_batch(const std::vector<BatchItem>& items, const CookOptions& options,
                                  const BatchLimits& limits, unsigned jobs, const BatchProgress& progress) {
  std::vector<CookRecord> records(items.size());
  size_t done = 0;
  cook_in_workers(items, options, limits, jobs, [&](size_t index, CookRecord record) {
    records[index] = std::move(record);
    ++done;
    if (progress) progress(done, items.size(), records[index]);
  });
  return records;
}

namespace {

std::string make_escaped(const std::string& path) {
  std::string out;
  for (char c : path) {
    if (c == ' ' || c == '#') out += '\\';
    if (c == '$') out += '$';
    out += c;
  }
  return out;
}

}  // namespace

Status write_depfile(const fs::path& path, const std::vector<CookRecord>& records) {
  std::string text;
  for (const CookRecord& r : records) {
    if (!r.ok) continue;
    text += make_escaped(fs::absolute(r.output).lexically_normal().string()) + ":";
    std::set<std::string> deps;
    for (const InputFile& f : r.inputs_read) {
      if (f.present) {
        deps.insert(f.path);
      } else {
        // A file looked for and absent cannot be a prerequisite, but its folder can: creating the
        // file changes the folder's mtime, so the build tool re-runs the cook, which then reads it.
        std::error_code ec;
        const fs::path dir = fs::path(f.path).parent_path();
        if (fs::is_directory(dir, ec)) deps.insert(dir.string());
      }
    }
    for (const std::string& d : deps) text += " \\\n  " + make_escaped(d);
    text += "\n";
  }
  return write_file_atomic(path, std::vector<uint8_t>(text.begin(), text.end()));
}

namespace {

/// `text` as UTF-8: valid sequences kept, every other byte read as Latin-1 (what old FBX files
/// carry in names) and encoded as that code point. JSON text must be UTF-8, and a report must be
/// written whatever bytes a path, a joint name or a message holds.
std::string as_utf8(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (size_t i = 0; i < text.size();) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c < 0x80) {
      out += static_cast<char>(c);
      ++i;
    } else if (const size_t n = detail::utf8_sequence_length(text, i); n != 0) {
      out.append(text, i, n);
      i += n;
    } else {
      out += static_cast<char>(0xC0 | (c >> 6));
      out += static_cast<char>(0x80 | (c & 0x3F));
      ++i;
    }
  }
  return out;
}

void make_utf8(nlohmann::ordered_json& j) {
  if (j.is_string()) {
    j = as_utf8(j.get_ref<const std::string&>());
  } else if (j.is_array() || j.is_object()) {
    for (auto& v : j) make_utf8(v);
  }
}

}  // namespace

nlohmann::ordered_json report_json(const std::vector<CookRecord>& records, const CookOptions& options,
                                   const BatchLimits& limits) {
  nlohmann::ordered_json doc;
  doc["schema"] = kReportSchema;
  doc["schema_version"] = kReportSchemaVersion;
  doc["cooker_version"] = kCookerVersion;
  doc["format_version"] = kFormatVersion;
  doc["options"] = options.canonical();
  doc["limits"] = {{"max_memory_bytes", limits.max_memory_bytes}, {"timeout_seconds", limits.timeout_seconds}};
  size_t failed = 0;
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  for (const CookRecord& r : records) {
    nlohmann::ordered_json j;
    j["input"] = r.input;
    j["status"] = r.ok ? "ok" : "failed";
    // Only a file that was written is named: a failed input leaves none (cook.h).
    if (r.ok) j["output"] = r.output;
    if (!r.ok) {
      ++failed;
      j["error"] = r.error;
    }
    // Counts as far as the cook got: all of them when ok, those counted before the failure otherwise.
    const auto count = [&j](const char* key, const std::optional<uint32_t>& value) {
      if (value) j[key] = *value;
    };
    count("joints", r.joints);
    count("meshes", r.meshes);
    count("submeshes", r.submeshes);
    count("vertices", r.vertices);
    count("triangles", r.triangles);
    count("clips", r.clips);
    count("materials", r.materials);
    count("textures", r.textures);
    count("vertices_over_4_influences", r.vertices_over_4_influences);
    nlohmann::ordered_json clips = nlohmann::ordered_json::array();
    for (const ClipRecord& c : r.clip_records) {
      nlohmann::ordered_json cj;
      cj["name"] = c.name;
      cj["joints"] = c.joints;
      cj["frames"] = c.frames;
      cj["raw_bytes"] = c.raw_bytes;
      cj["cooked_bytes"] = c.cooked_bytes;
      cj["ratio"] = c.cooked_bytes > 0 ? static_cast<double>(c.raw_bytes) / c.cooked_bytes : 0.0;
      cj["max_error_mm"] = c.max_error_mm;
      cj["mean_error_mm"] = c.mean_error_mm;
      cj["worst_joint"] = c.worst_joint;
      clips.push_back(std::move(cj));
    }
    j["clip_compression"] = std::move(clips);
    if (!r.texture_records.empty()) {
      nlohmann::ordered_json textures = nlohmann::ordered_json::array();
      for (const TextureRecord& t : r.texture_records) {
        nlohmann::ordered_json tj;
        tj["name"] = t.name;
        tj["role"] = t.role;
        tj["encoding"] = t.encoding;
        tj["srgb"] = t.srgb;
        tj["width"] = t.width;
        tj["height"] = t.height;
        tj["mips"] = t.mips;
        tj["source_bytes"] = t.source_bytes;
        tj["cooked_bytes"] = t.cooked_bytes;
        tj["gpu_rgba8_bytes"] = t.gpu_rgba8_bytes;
        tj["psnr_db"] = t.psnr_db;
        if (t.role == "normal") {
          tj["normal_mean_deg"] = t.normal_mean_deg;
          tj["normal_max_deg"] = t.normal_max_deg;
        }
        textures.push_back(std::move(tj));
      }
      j["textures_cooked"] = std::move(textures);
    }
    if (!r.morph_records.empty()) {
      nlohmann::ordered_json morphs = nlohmann::ordered_json::array();
      for (const MorphRecord& m : r.morph_records) {
        nlohmann::ordered_json mj;
        mj["mesh"] = m.mesh;
        mj["name"] = m.name;
        mj["vertices"] = m.vertices;
        mj["raw_bytes"] = m.raw_bytes;
        mj["stored_bytes"] = m.stored_bytes;
        mj["ratio"] = m.stored_bytes > 0 ? static_cast<double>(m.raw_bytes) / m.stored_bytes : 0.0;
        mj["position_error_mm"] = m.position_error_mm;
        mj["normal_error_deg"] = m.normal_error_deg;
        morphs.push_back(std::move(mj));
      }
      j["morph_targets"] = std::move(morphs);
    }
    if (!r.retarget_records.empty()) {
      nlohmann::ordered_json retargets = nlohmann::ordered_json::array();
      for (const RetargetRecord& t : r.retarget_records) {
        nlohmann::ordered_json tj;
        tj["clip"] = t.clip;
        tj["frames"] = t.frames;
        tj["hips_ratio"] = t.hips_ratio;
        tj["floor_mm"] = t.floor_mm;
        tj["limb_max_deg"] = t.limb_max_deg;
        tj["guard_max_deg"] = t.guard_max_deg;
        tj["hand_max_deg"] = t.hand_max_deg;
        tj["foot_max_deg"] = t.foot_max_deg;
        tj["crossing_frames"] = t.crossing_frames;
        tj["guarded_frames"] = t.guarded_frames;
        nlohmann::ordered_json contacts = nlohmann::ordered_json::array();
        for (const RetargetContactRecord& c : t.contacts) {
          nlohmann::ordered_json cj;
          cj["foot"] = c.foot == 0 ? "left" : "right";
          cj["start"] = c.start;
          cj["end"] = c.end;
          cj["held_mm"] = c.held_mm;
          cj["slide_mm"] = c.slide_mm;
          cj["source_slide_mm"] = c.source_slide_mm;
          contacts.push_back(std::move(cj));
        }
        tj["contacts"] = std::move(contacts);
        retargets.push_back(std::move(tj));
      }
      j["retarget"] = std::move(retargets);
    }
    j["source_bytes"] = r.source_bytes;
    if (r.ok) j["cooked_bytes"] = r.cooked_bytes;
    if (r.ok) j["up_to_date"] = r.up_to_date;
    if (r.ok) j["cook_key"] = hex64(r.cook_key);
    // What the cook read (as far as it got), relative to the input's directory like provenance.
    nlohmann::ordered_json inputs = nlohmann::ordered_json::array();
    for (const InputFile& f : relative_inputs(r.inputs_read, fs::path(r.input).parent_path())) {
      nlohmann::ordered_json fj;
      fj["path"] = f.path;
      if (f.present) {
        fj["hash"] = hex64(f.hash);
        fj["bytes"] = f.size;
      } else {
        fj["absent"] = true;
      }
      inputs.push_back(std::move(fj));
    }
    j["inputs_read"] = std::move(inputs);
    j["seconds"] = r.seconds;
    j["warnings"] = r.warnings;
    list.push_back(std::move(j));
  }
  doc["inputs"] = records.size();
  doc["failed"] = failed;
  doc["records"] = std::move(list);
  make_utf8(doc);  // keys are ours (ASCII); values may carry any bytes
  return doc;
}

}  // namespace ossa::cook
