// batch.cpp — output planning, the cooking thread pool and the report document (see batch.h).
#include "cooker/cli/batch.h"

#include <algorithm>
#include <atomic>
#include <map>
#include <mutex>
#include <set>
#include <thread>

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
  std::vector<fs::path> files;
  for (const fs::path& input : inputs) {
    std::error_code ec;
    if (fs::is_directory(input, ec)) {
      std::vector<fs::path> found;
      for (fs::recursive_directory_iterator it(input, ec), end; !ec && it != end; it.increment(ec))
        if (it->is_regular_file(ec) && (is_source_extension(it->path()) || is_graph_file(it->path())))
          found.push_back(it->path());
      if (ec) return Error{input.string() + ": cannot list directory: " + ec.message()};
      std::sort(found.begin(), found.end());
      files.insert(files.end(), found.begin(), found.end());
    } else {
      files.push_back(input);
    }
  }

  std::vector<BatchItem> items;
  std::map<fs::path, fs::path> claimed;  // output -> first input that maps to it
  const fs::path abs_root = root.empty() ? fs::path() : fs::weakly_canonical(fs::absolute(root));
  for (const fs::path& input : files) {
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
    items.push_back({input, output});
  }
  return items;
}

std::vector<CookRecord> run_batch(const std::vector<BatchItem>& items, const CookOptions& options, unsigned jobs,
                                  const BatchProgress& progress) {
  std::vector<CookRecord> records(items.size());
  std::atomic<size_t> next{0};
  size_t done = 0;
  std::mutex mutex;
  auto worker = [&] {
    for (size_t i = next.fetch_add(1); i < items.size(); i = next.fetch_add(1)) {
      CookRecord record = cook_file(items[i].input, items[i].output, options);
      std::lock_guard<std::mutex> lock(mutex);
      records[i] = std::move(record);
      ++done;
      if (progress) progress(done, items.size(), records[i]);
    }
  };
  const unsigned n = std::max(1u, std::min<unsigned>(jobs, static_cast<unsigned>(std::max<size_t>(1, items.size()))));
  std::vector<std::thread> threads;
  for (unsigned t = 1; t < n; ++t) threads.emplace_back(worker);
  worker();
  for (std::thread& t : threads) t.join();
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

nlohmann::ordered_json report_json(const std::vector<CookRecord>& records, const CookOptions& options) {
  nlohmann::ordered_json doc;
  doc["schema"] = kReportSchema;
  doc["schema_version"] = kReportSchemaVersion;
  doc["cooker_version"] = kCookerVersion;
  doc["format_version"] = kFormatVersion;
  doc["options"] = options.canonical();
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
  return doc;
}

}  // namespace ossa::cook
