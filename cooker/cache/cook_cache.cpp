// cook_cache.cpp — the two-level lookup and the store of the shared cook cache (see cook_cache.h).
// Manifests are CBOR (through nlohmann, as the worker's records): paths are carried as raw bytes,
// so a file name that is not UTF-8 round-trips unchanged.
#include "cooker/cache/cook_cache.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <nlohmann/json.hpp>

#include <ossa/loader/asset.h>

namespace ossa::cook {
namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

constexpr const char* kManifestKind = "ossa-cook-cache-manifest";
constexpr int kManifestVersion = 1;

struct Manifest {
  uint64_t cook_key = 0;
  uint64_t output_size = 0, output_hash = 0;  // of the output at cas/<cook key>
  std::vector<InputFile> inputs;              // relative to the source's folder
};

std::vector<uint8_t> encode_manifest(const std::string& source, const std::string& canonical, uint64_t key,
                                     std::span<const uint8_t> output, const std::vector<InputFile>& inputs) {
  json j;
  j["kind"] = kManifestKind;
  j["version"] = kManifestVersion;
  j["source"] = source;
  j["options"] = canonical;
  j["cook_key"] = key;
  j["output_size"] = output.size();
  j["output_hash"] = input_hash(output);
  json list = json::array();
  for (const InputFile& f : inputs) list.push_back({f.path, f.present, f.size, f.hash});
  j["inputs"] = std::move(list);
  return json::to_cbor(j);
}

/// The manifest, or nullopt when the bytes are not one for this source and these options.
std::optional<Manifest> decode_manifest(const std::vector<uint8_t>& bytes, const std::string& source,
                                        const std::string& canonical) {
  const json j = json::from_cbor(bytes, /*strict=*/true, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object()) return std::nullopt;
  try {
    if (j.at("kind") != kManifestKind || j.at("version") != kManifestVersion) return std::nullopt;
    if (j.at("source").get<std::string>() != source || j.at("options").get<std::string>() != canonical)
      return std::nullopt;
    Manifest m;
    m.cook_key = j.at("cook_key").get<uint64_t>();
    m.output_size = j.at("output_size").get<uint64_t>();
    m.output_hash = j.at("output_hash").get<uint64_t>();
    for (const json& f : j.at("inputs")) {
      if (!f.is_array() || f.size() != 4) return std::nullopt;
      InputFile in;
      in.path = f[0].get<std::string>();
      in.present = f[1].get<bool>();
      in.size = f[2].get<uint64_t>();
      in.hash = f[3].get<uint64_t>();
      m.inputs.push_back(std::move(in));
    }
    return m;
  } catch (const json::exception&) {
    return std::nullopt;
  }
}

void note(CookRecord& record, const CacheTrouble& trouble) {
  if (record.cache_note.empty()) record.cache_note = trouble.message;
  record.cache_down = record.cache_down || trouble.unreachable;
}

/// The provenance of verified bytes, checked to be this source's output for these options.
std::optional<std::string> foreign(const Asset& asset, const std::string& source, const std::string& canonical,
                                   uint64_t key) {
  const fb::Provenance* prov = asset.file().provenance();
  if (prov == nullptr) return "no provenance";
  if (prov->cook_key() != key) return "its cook key is " + hex64(prov->cook_key()) + ", not " + hex64(key);
  if (flatbuffers::GetStringView(prov->source_name()) != source) return "it is the output of another source";
  if (flatbuffers::GetStringView(prov->options()) != canonical) return "it was cooked with other options";
  return std::nullopt;
}

}  // namespace

std::optional<CacheMode> parse_cache_mode(std::string_view text) {
  if (text == "off") return CacheMode::Off;
  if (text == "read") return CacheMode::Read;
  if (text == "readwrite") return CacheMode::ReadWrite;
  return std::nullopt;
}

const char* cache_mode_name(CacheMode mode) {
  switch (mode) {
    case CacheMode::Off: return "off";
    case CacheMode::Read: return "read";
    case CacheMode::ReadWrite: return "readwrite";
  }
  return "off";
}

uint64_t manifest_key(std::string_view source_name, uint64_t source_size, uint64_t source_hash,
                      std::string_view canonical) {
  // The cook key's own hash over a one-file list, in a namespace of its own (the suffix), so a
  // manifest key never equals a cook key.
  const InputFile source{std::string(source_name), source_hash, source_size, true};
  return cook_key(std::span<const InputFile>(&source, 1), std::string(canonical) + "\ncache-manifest");
}

std::optional<std::vector<uint8_t>> cache_lookup(const CookCache& cache, CookRecord& record, const fs::path& input,
                                                 const std::string& canonical) {
  if (cache.mode == CacheMode::Off || cache.down || !cache.store) return std::nullopt;
  const fs::path base = input.parent_path();
  const std::string source = input.filename().string();
  InputLog log;  // this lookup's own: the cook's log records only what the cook reads
  InputLogScope scope(&log);
  if (!hash_input(input) || !log.refusals().empty()) return std::nullopt;  // the cook says why
  const std::vector<InputFile> first = log.files();
  if (first.size() != 1 || !first[0].present) return std::nullopt;
  const std::string mkey = hex64(manifest_key(source, first[0].size, first[0].hash, canonical));

  CacheGet got = cache.store->get("ac", mkey);
  if (got.trouble) note(record, *got.trouble);
  if (!got.bytes) return std::nullopt;
  record.cache_bytes_fetched += got.bytes->size();
  const std::optional<Manifest> manifest = decode_manifest(*got.bytes, source, canonical);
  if (!manifest) {
    note(record,
         {cache.store->name() + ": ac/" + mkey + ": not a manifest of " + source + " with these options", false});
    return std::nullopt;
  }
  for (const InputFile& f : manifest->inputs) {
    const fs::path path = (base / fs::path(f.path)).lexically_normal();
    if (!f.present) probe_input(path);
    else if (!hash_input(path)) return std::nullopt;  // unreadable here: the cook will say why
  }
  if (!log.refusals().empty()) {
    note(record,
         {cache.store->name() + ": ac/" + mkey + ": names a file this cook may not read: " + log.refusals().front(),
          false});
    return std::nullopt;
  }
  const uint64_t key = cook_key(relative_inputs(log.files(), base), canonical);
  if (key != manifest->cook_key) return std::nullopt;  // this tree's other inputs differ: a miss

  const std::string ckey = hex64(key);
  got = cache.store->get("cas", ckey);
  if (got.trouble) note(record, *got.trouble);
  if (!got.bytes) return std::nullopt;
  record.cache_bytes_fetched += got.bytes->size();
  // The loader's checks see structure, not every byte (a vertex flipped in a damaged entry still
  // verifies): the manifest's hash of the output catches that.
  if (got.bytes->size() != manifest->output_size || input_hash(*got.bytes) != manifest->output_hash) {
    note(record, {cache.store->name() + ": cas/" + ckey + ": " + std::to_string(got.bytes->size()) +
                      " bytes that are not the output its manifest describes (damaged or truncated)",
                  false});
    return std::nullopt;
  }
  auto asset = Asset::from_bytes(*got.bytes, cache.store->name() + "/cas/" + ckey);
  if (!asset) {
    note(record, {asset.error().message, false});
    return std::nullopt;
  }
  if (const std::optional<std::string> why = foreign(*asset, source, canonical, key)) {
    note(record, {cache.store->name() + ": cas/" + ckey + ": not this output: " + *why, false});
    return std::nullopt;
  }
  return std::move(*got.bytes);
}

void cache_store_output(const CookCache& cache, CookRecord& record, const fs::path& output,
                        const std::string& canonical) {
  if (cache.mode != CacheMode::ReadWrite || cache.down || record.cache_down || !cache.store) return;
  // The output as written (not an input of the cook: read directly, outside the input log).
  std::vector<uint8_t> bytes;
  {
    const int fd = ::open(output.c_str(), O_RDONLY | O_CLOEXEC);
    struct stat st {};
    if (fd < 0 || ::fstat(fd, &st) != 0) {
      if (fd >= 0) ::close(fd);
      return;
    }
    bytes.resize(static_cast<size_t>(st.st_size));
    size_t done = 0;
    while (done < bytes.size()) {
      const ssize_t n = ::read(fd, bytes.data() + done, bytes.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      done += static_cast<size_t>(n);
    }
    ::close(fd);
    if (done != bytes.size()) return;
  }
  auto asset = Asset::from_bytes(bytes, output.string());
  if (!asset) return;
  const fb::Provenance* prov = asset->file().provenance();
  if (prov == nullptr || prov->inputs() == nullptr || prov->cook_key() != record.cook_key)
    return;  // rewritten meanwhile
  const std::string source = flatbuffers::GetString(prov->source_name());
  if (flatbuffers::GetStringView(prov->options()) != canonical) return;
  std::vector<InputFile> inputs;
  uint64_t source_size = 0;
  bool source_listed = false;
  for (const fb::InputFile* f : *prov->inputs()) {
    if (f->path() == nullptr) return;
    inputs.push_back(InputFile{f->path()->str(), f->hash(), f->size(), !f->absent()});
    if (f->path()->str() == source && !f->absent()) source_size = f->size(), source_listed = true;
  }
  if (!source_listed) return;
  const std::string ckey = hex64(prov->cook_key());
  // The output first: a manifest is never stored before what it leads to.
  if (std::optional<CacheTrouble> t = cache.store->put("cas", ckey, bytes)) return note(record, *t);
  record.cache_bytes_stored += bytes.size();
  const std::vector<uint8_t> manifest = encode_manifest(source, canonical, prov->cook_key(), bytes, inputs);
  const std::string mkey = hex64(manifest_key(source, source_size, prov->source_hash(), canonical));
  if (std::optional<CacheTrouble> t = cache.store->put("ac", mkey, manifest)) return note(record, *t);
  record.cache_bytes_stored += manifest.size();
}

}  // namespace ossa::cook
