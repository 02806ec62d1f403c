// batch.cpp — output planning, the limits' defaults, the batch around the worker processes
// (cooker/cli/worker.h) and the report document (see batch.h).
#include "cooker/cli/batch.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <string_view>
#include <type_traits>

#include "cooker/cache/cook_cache.h"
#include "cooker/cli/worker.h"
#include "common/message.h"

#include <ossa/version.h>

namespace ossa::cook {
namespace fs = std::filesystem;

bool is_source_extension(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".fbx" || ext == ".gltf" || ext == ".glb" || ext == ".dae" || ext == ".bvh" || ext == ".obj";
}

std::string output_stem(const fs::path& input) {
  const std::string name = input.filename().string();
  if (is_graph_file(input)) return name.substr(0, name.size() - std::string_view(".graph.json").size());
  return input.stem().string();
}

namespace {
std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}
}  // namespace

bool is_folder_rig(const fs::path& input) { return is_source_extension(input) && has_folder_rig_name(input); }

void assign_folder_rigs(std::vector<BatchItem>& items) {
  std::map<fs::path, std::vector<const BatchItem*>> rigs;  // folder -> its rigs, by input path
  for (const BatchItem& item : items)
    if (is_folder_rig(item.input)) rigs[item.input.parent_path()].push_back(&item);
  for (auto& [folder, list] : rigs)
    std::sort(list.begin(), list.end(), [](const BatchItem* a, const BatchItem* b) { return a->input < b->input; });
  for (BatchItem& item : items) {
    if (is_folder_rig(item.input) || is_graph_file(item.input)) continue;
    const auto it = rigs.find(item.input.parent_path());
    if (it == rigs.end()) continue;
    const BatchItem* pick = it->second.front();
    for (const BatchItem* r : it->second)
      if (lower(r->input.extension().string()) == lower(item.input.extension().string())) {
        pick = r;
        break;
      }
    item.rig = pick->output;
  }
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

  // Model sources of this batch that share a stem in one folder (skeleton.dae beside skeleton.fbx)
  // keep their extension in the output name, so each gets its own: skeleton.dae.ossa, skeleton.fbx.ossa.
  std::map<std::pair<fs::path, std::string>, std::set<fs::path>> by_stem;  // (folder, stem) -> file names
  const auto folder_of = [](const fs::path& input) { return fs::absolute(input).lexically_normal().parent_path(); };
  for (const auto& entry : files)
    if (!is_graph_file(entry.first))
      by_stem[{folder_of(entry.first), output_stem(entry.first)}].insert(entry.first.filename());

  std::vector<BatchItem> items;
  std::map<fs::path, fs::path> claimed;  // output -> first input that maps to it
  std::error_code root_ec;
  if (!root.empty() && !fs::is_directory(root, root_ec))
    return Error{"--root " + root.string() + ": " +
                 (fs::exists(root, root_ec) ? "is not a directory" : "does not exist")};
  const fs::path abs_root = root.empty() ? fs::path() : fs::weakly_canonical(fs::absolute(root));
  for (const auto& [input, tree] : files) {
    fs::path sub;
    if (!root.empty()) {
      const fs::path abs_in = fs::weakly_canonical(fs::absolute(input));
      const fs::path rel = abs_in.lexically_relative(abs_root);
      if (rel.empty() || *rel.begin() == "..") return Error{input.string() + ": is not inside --root " + root.string()};
      sub = rel.parent_path();
    }
    const bool shared_stem = !is_graph_file(input) && by_stem[{folder_of(input), output_stem(input)}].size() > 1;
    const std::string name = shared_stem ? input.filename().string() : output_stem(input);
    fs::path output = (out_dir / sub / name).concat(".ossa").lexically_normal();
    auto [it, inserted] = claimed.emplace(output, input);
    if (!inserted)
      return Error{
          "inputs " + it->second.string() + " and " + input.string() + " would both write " + output.string() +
          (root.empty() ? " (use --root to mirror the source tree)" : " (cook them into separate output directories)")};
    items.push_back({input, output, tree, {}});
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
  std::transform(unit.begin(), unit.end(), unit.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
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
  // Temporaries of writers that died (a batch killed mid-write) go now, before anything is found
  // up to date: an up-to-date output is never rewritten, so no later write would remove them.
  if (options.write) {
    std::vector<fs::path> outputs;
    outputs.reserve(items.size());
    for (const BatchItem& item : items) outputs.push_back(item.output);
    remove_stale_temporaries(outputs);
  }
  size_t done = 0;
  cook_in_workers(items, options, limits, jobs, [&](size_t index, CookRecord record) {
    // A worker that found the cache unreachable: those started from now on do not ask (they are
    // forked from this process and see the mark; cook_cache.h).
    if (record.cache_down && options.cache != nullptr && !options.cache->down) {
      options.cache->down = true;
      options.cache->down_reason = record.cache_note;
    }
    records[index] = std::move(record);
    ++done;
    if (progress) progress(done, items.size(), records[index]);
  });
  return records;
}

std::optional<std::string> depfile_spelling(const std::string& path, bool target, std::string& why) {
  // The rules both readers apply (GNU Make 4.3's read.c, Ninja 1.11's depfile_parser.in.cc), checked
  // by building with each over every class of hostile name (tests/cook_depfile_test.cpp):
  // - both: "\ " is a space, "\#" a '#', "\:" a ':', "$$" a '$'; letters, digits, bytes >= 0x80
  //   and "+,-./_~()[]{}%=@!" stand for themselves in Ninja, which ends a name at anything else
  //   (';' '&' '|' quotes '*' '?' '<' '>' '^' '`', TAB, ESC, ...) and has no escape for them;
  // - Make runs what follows a ';' as a recipe, reads '=' as a variable assignment, globs "[...]",
  //   takes "x(y)" for an archive member and a '%' in a target for a pattern rule;
  // - a backslash stands for itself in both only before an ordinary character.
  const auto refuse = [&why](std::string reason) -> std::optional<std::string> {
    why = std::move(reason);
    return std::nullopt;
  };
  std::string out;
  out.reserve(path.size() + 8);
  for (size_t i = 0; i < path.size(); ++i) {
    const auto c = static_cast<unsigned char>(path[i]);
    if (c == '\n' || c == '\r') return refuse("a line break ends a rule for Make and Ninja");
    if (c == '\t') return refuse("Ninja ends a name at a TAB and has no escape for it");
    if (c < 0x20 || c == 0x7f) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "0x%02x", c);
      return refuse(std::string("Ninja ends a name at the control byte ") + hex + " and has no escape for it");
    }
    if (std::string_view(";&|`'\"*?<>^").find(static_cast<char>(c)) != std::string_view::npos)
      return refuse(std::string("Ninja ends a name at '") + static_cast<char>(c) + "' and has no escape for it" +
                    (c == ';' ? " (and Make would run what follows it as a command)" : ""));
    if (c == '=') return refuse("Make reads a rule with '=' as a variable assignment");
    if (c == '[' && path.find(']', i) != std::string::npos) return refuse("Make would read \"[...]\" as a wildcard");
    if (c == '%' && target) return refuse("Make would read a target with '%' as a pattern rule");
    if (c == '\\') {
      const char next = i + 1 < path.size() ? path[i + 1] : '\0';
      if (next == '\0' || std::string_view(" #:$%").find(next) != std::string_view::npos)
        return refuse("a backslash at the end of a name or before one of ' #:$%' reads differently in Make and Ninja");
      out += '\\';
    } else if (c == ' ' || c == '#' || c == ':') {
      if (c == ':' && i + 1 == path.size()) return refuse("Ninja cannot read a name that ends with ':'");
      out += '\\';
      out += static_cast<char>(c);
    } else if (c == '$') {
      out += "$$";
    } else {
      out += static_cast<char>(c);
    }
  }
  if (!path.empty() && path.back() == ')' && path.find('(') != std::string::npos)
    return refuse("Make would read \"name(member)\" as a member of an archive");
  return out;
}

Status write_depfile(const fs::path& path, const std::vector<CookRecord>& records) {
  std::string text;
  std::string problem;
  size_t problems = 0;
  const auto spell = [&](const std::string& name, bool target, const CookRecord& r) {
    std::string why;
    std::optional<std::string> spelled = depfile_spelling(name, target, why);
    if (spelled) return std::move(*spelled);
    if (problems++ == 0)
      problem = r.input + ": " + (target ? "its output " : "it reads ") + "'" + detail::printable(name, 400) +
                "', a name no depfile spells alike for Make and Ninja: " + why;
    return std::string();
  };
  for (const CookRecord& r : records) {
    if (!r.ok) continue;
    text += spell(fs::absolute(r.output).lexically_normal().string(), true, r) + ":";
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
    for (const std::string& d : deps) text += " \\\n  " + spell(d, false, r);
    text += "\n";
  }
  if (problems > 0) {
    // No depfile rather than one that means something else to the build tool (an older one would
    // still name the previous inputs).
    std::error_code ec;
    fs::remove(path, ec);
    return Error{path.string() + ": not written: " + problem +
                 (problems > 1 ? " (and " + std::to_string(problems - 1) + " more such names)" : "") +
                 "; rename it, or cook without --depfile"};
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

template <class T>
struct is_optional : std::false_type {};
template <class T>
struct is_optional<std::optional<T>> : std::true_type {};

double ratio(uint64_t raw, uint64_t stored) {
  return stored > 0 ? static_cast<double>(raw) / static_cast<double>(stored) : 0.0;
}

/// A clip's compression: its fields, with raw / cooked as "ratio" after the sizes.
nlohmann::ordered_json clip_json(const ClipRecord& c) {
  nlohmann::ordered_json j;
  clip_record_fields(
      [&](const char* key, const auto& value) {
        j[key] = value;
        if (std::string_view(key) == "cooked_bytes") j["ratio"] = ratio(c.raw_bytes, c.cooked_bytes);
      },
      c);
  return j;
}

/// A cooked texture: its fields; the angles to the source's normals only for a normal map.
nlohmann::ordered_json texture_json(const TextureRecord& t) {
  nlohmann::ordered_json j;
  texture_record_fields(
      [&](const char* key, const auto& value) {
        const std::string_view k(key);
        if ((k == "normal_mean_deg" || k == "normal_max_deg") && t.role != "normal") return;
        j[key] = value;
      },
      t);
  return j;
}

/// A cooked morph target: its fields, with raw / stored as "ratio" after the sizes.
nlohmann::ordered_json morph_json(const MorphRecord& m) {
  nlohmann::ordered_json j;
  morph_record_fields(
      [&](const char* key, const auto& value) {
        j[key] = value;
        if (std::string_view(key) == "stored_bytes") j["ratio"] = ratio(m.raw_bytes, m.stored_bytes);
      },
      m);
  return j;
}

/// A file the cook read (path relative to the input's directory, like provenance): its hash in hex
/// and its size as "bytes" when present, "absent": true otherwise.
nlohmann::ordered_json input_json(const InputFile& f) {
  nlohmann::ordered_json j;
  input_file_fields(
      [&](const char* key, const auto& value) {
        const std::string_view k(key);
        if (k == "path") j[key] = value;
        else if (k == "hash" && f.present) j[key] = hex64(f.hash);
        else if (k == "size" && f.present) j["bytes"] = value;
        else if (k == "present" && !f.present) j["absent"] = true;
      },
      f);
  return j;
}

/// A retargeted clip's contact: its fields, the foot by name.
nlohmann::ordered_json retarget_contact_json(const RetargetContactRecord& c) {
  nlohmann::ordered_json j;
  retarget_contact_record_fields(
      [&](const char* key, const auto& value) {
        if (std::string_view(key) == "foot") j[key] = c.foot == 0 ? "left" : "right";
        else j[key] = value;
      },
      c);
  return j;
}

/// A retargeted clip: its fields, contacts as above.
nlohmann::ordered_json retarget_json(const RetargetRecord& t) {
  nlohmann::ordered_json j;
  retarget_record_fields(
      [&](const char* key, const auto& value) {
        using T = std::decay_t<decltype(value)>;
        if constexpr (std::is_same_v<T, std::vector<RetargetContactRecord>>) {
          nlohmann::ordered_json list = nlohmann::ordered_json::array();
          for (const RetargetContactRecord& c : value) list.push_back(retarget_contact_json(c));
          j[key] = std::move(list);
        } else {
          j[key] = value;
        }
      },
      t);
  return j;
}

template <class Record>
nlohmann::ordered_json json_list(const std::vector<Record>& records, nlohmann::ordered_json (*one)(const Record&)) {
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  for (const Record& r : records) list.push_back(one(r));
  return list;
}

/// One record of the report: CookRecord's field list in its order, under the report's names and
/// rules (docs/JSON.md). "ok" is "status"; only a file that was written is named (cook.h), with its
/// size, whether it was up to date and its cook key; an error only for a failed input; counts as far
/// as the cook got (all of them when ok, those counted before the failure otherwise); per-clip
/// records always, texture and morph records when there are any.
nlohmann::ordered_json report_record(const CookRecord& r) {
  nlohmann::ordered_json j;
  cook_record_fields(
      [&](const char* key, const auto& value) {
        using T = std::decay_t<decltype(value)>;
        const std::string_view k(key);
        if constexpr (is_optional<T>::value) {
          if (value) j[key] = *value;
        } else if constexpr (std::is_same_v<T, std::vector<ClipRecord>>) {
          j["clip_compression"] = json_list(value, clip_json);
        } else if constexpr (std::is_same_v<T, std::vector<TextureRecord>>) {
          if (!value.empty()) j["textures_cooked"] = json_list(value, texture_json);
        } else if constexpr (std::is_same_v<T, std::vector<MorphRecord>>) {
          if (!value.empty()) j["morph_targets"] = json_list(value, morph_json);
        } else if constexpr (std::is_same_v<T, std::vector<RetargetRecord>>) {
          if (!value.empty()) j["retarget"] = json_list(value, retarget_json);
        } else if constexpr (std::is_same_v<T, std::vector<InputFile>>) {
          j[key] = json_list(relative_inputs(value, fs::path(r.input).parent_path()), input_json);
        } else if (k == "ok") {
          j["status"] = r.ok ? "ok" : "failed";
        } else if (k == "error") {
          if (!r.ok) j[key] = value;
        } else if (k == "cook_key") {
          if (r.ok) j[key] = hex64(r.cook_key);
        } else if (k == "output" || k == "cooked_bytes" || k == "up_to_date" || k == "cache_hit") {
          if (r.ok) j[key] = value;
        } else if (k == "cache_down") {
          // said by cache_note; the batch's own business (it stops asking)
        } else if (k == "cache_note" || k == "cache_bytes_fetched" || k == "cache_bytes_stored") {
          if constexpr (std::is_same_v<T, std::string> || std::is_same_v<T, uint64_t>)
            if (value != T{}) j[key] = value;
        } else {
          j[key] = value;
        }
      },
      r);
  return j;
}

}  // namespace

CacheTotals cache_totals(const std::vector<CookRecord>& records) {
  CacheTotals t;
  for (const CookRecord& r : records) {
    if (r.cache_hit) ++t.hits;
    else if (!r.up_to_date) ++t.misses;
    t.bytes_fetched += r.cache_bytes_fetched;
    t.bytes_stored += r.cache_bytes_stored;
    if (!r.cache_note.empty()) {
      ++t.troubled;
      if (t.first_trouble.empty()) t.first_trouble = r.cache_note;
    }
  }
  return t;
}

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
    if (!r.ok) ++failed;
    list.push_back(report_record(r));
  }
  doc["inputs"] = records.size();
  doc["failed"] = failed;
  if (options.cache != nullptr) {
    const CacheTotals t = cache_totals(records);
    nlohmann::ordered_json c;
    c["location"] = options.cache->store ? options.cache->store->name() : std::string();
    c["mode"] = cache_mode_name(options.cache->mode);
    c["hits"] = t.hits;
    c["misses"] = t.misses;
    c["bytes_fetched"] = t.bytes_fetched;
    c["bytes_stored"] = t.bytes_stored;
    c["inputs_with_trouble"] = t.troubled;
    if (!t.first_trouble.empty()) c["trouble"] = t.first_trouble;
    doc["cache"] = std::move(c);
  }
  doc["records"] = std::move(list);
  make_utf8(doc);  // keys are ours (ASCII); values may carry any bytes
  return doc;
}

}  // namespace ossa::cook
