// cook_graph.cpp — a graph file (`*.graph.json`, docs/GRAPH.md) cooked into one self-contained
// character: the rig and meshes of its "skeleton" source, the meshes of its "meshes" sources
// bound to that rig, its clips (each from its source, bound to the rig, renamed to the graph's
// name for it, with events) and the compiled graph.
//
// Every source is imported as `ossa-cook --skeleton` would import it against the rig
// (ImportOptions::reference), so clips authored on a superset rig (Pab's clips carry an extra
// "Bip01 Footsteps" joint) bind by joint name. A source used by several clip entries is imported
// once. Every file it reads (the graph file, sources and their event sidecars) goes into the
// cook's input log, so the cook key changes when any of them does.
// Messages about a source start with the graph file's position of the entry naming it and then
// carry the source's own message (which names the source). A retarget node's source rig and map
// file (docs/RETARGET.md) are read here too, and its rigs mapped, for the compiler.
#include <functional>
#include <map>
#include <optional>
#include <span>

#include "cooker/clip/clip_events.h"
#include "cooker/cook_internal.h"
#include "cooker/graph/graph_compile.h"
#include "cooker/import/import_scene.h"
#include "cooker/json/json_source.h"
#include "cooker/mesh/mesh_build.h"
#include "cooker/write/write_ossa.h"
#include "cooker/texture/texture_cook.h"
#include "tools/retarget/map_file.h"
#include <ossa/format/hash.h>
#include <ossa/loader/asset.h>
#include <ossa/retarget/humanoid.h>
#include <ossa/retarget/retarget.h>

namespace ossa::cook::detail {
namespace fs = std::filesystem;

namespace {

/// A source skeleton's joints as map_rig takes them (names view the skeleton's strings).
Result<tools::MappedRig> map_rig(const SourceSkeleton& skeleton, const tools::HumanoidMapFile* map,
                                 const std::string& map_name, const char* role, const std::string& name) {
  std::vector<std::string_view> names;
  std::vector<int16_t> parents;
  std::vector<Transform> bind;
  for (const SourceJoint& j : skeleton.joints) {
    names.emplace_back(j.name);
    parents.push_back(static_cast<int16_t>(j.parent));
    bind.push_back(Transform{j.translation, j.rotation, j.scale});
  }
  return tools::map_rig(std::move(names), std::move(parents), std::move(bind), map, map_name, role, name);
}

std::vector<RetargetRestRotationDef> rest_rotations_of(const tools::AppliedRigMap& applied) {
  std::vector<RetargetRestRotationDef> out;
  for (const RestRotation& r : applied.rest_rotations) {
    RetargetRestRotationDef d;
    d.joint = static_cast<uint16_t>(r.joint);
    d.rotation[0] = r.rotation.x;
    d.rotation[1] = r.rotation.y;
    d.rotation[2] = r.rotation.z;
    d.rotation[3] = r.rotation.w;
    out.push_back(d);
  }
  return out;
}

/// A retarget node's rigs (graph_compile.h): the source rig (a cooked .ossa, or a source file
/// imported as ossa-cook imports it: the same names and parents, so the same skeleton hash as its
/// cook) and the map file, both read through the cook's input log (keyed inputs), both rigs
/// mapped and the retarget map built once, so a rig the retarget cannot use fails the cook with
/// the bones it lacks named.
Result<GraphRetargetRigs> retarget_rigs(const fs::path& rig_path, const fs::path& map_path,
                                        const SourceSkeleton& target,
                                        const std::function<void(const std::vector<uint8_t>&)>& add) {
  std::error_code ec;
  if (!fs::is_regular_file(rig_path, ec)) return Error{rig_path.string() + ": no such rig file"};
  auto bytes = read_bytes(rig_path);
  if (!bytes) return bytes.error();
  add(*bytes);
  SourceSkeleton source;
  uint64_t hash = 0;
  if (rig_path.extension() == ".ossa") {
    auto asset = Asset::from_bytes(*bytes, rig_path.string());
    if (!asset) return asset.error();
    const SkeletonView sk = asset->skeleton();
    if (sk.empty() || sk.joint_count() == 0) return Error{rig_path.string() + ": holds no skeleton to retarget from"};
    for (size_t i = 0; i < sk.joint_count(); ++i) {
      SourceJoint j;
      j.name = std::string(sk.joint_name(i));
      j.parent = sk.parents()[i];
      const fb::Vec3& t = sk.bind_translations()[i];
      const fb::Quat& q = sk.bind_rotations()[i];
      const fb::Vec3& sc = sk.bind_scales()[i];
      j.translation = {t.x(), t.y(), t.z()};
      j.rotation = glm::quat(q.w(), q.x(), q.y(), q.z());
      j.scale = {sc.x(), sc.y(), sc.z()};
      source.joints.push_back(std::move(j));
    }
    hash = sk.hash();
  } else {
    auto scene = import_scene(rig_path.string());
    if (!scene) return scene.error();
    if (scene->skeleton.joints.empty()) return Error{rig_path.string() + ": has no skeleton to retarget from"};
    source = std::move(scene->skeleton);
    hash = skeleton_hash_of(source);
  }
  if (source.joints.size() > 65535) return Error{rig_path.string() + ": more than 65535 joints"};
  std::optional<tools::HumanoidMapFile> map;
  if (!map_path.empty()) {
    std::error_code map_ec;
    if (!fs::is_regular_file(map_path, map_ec)) return Error{map_path.string() + ": no such map file"};
    auto text = read_bytes(map_path);
    if (!text) return text.error();
    add(*text);
    auto parsed = tools::parse_humanoid_map_file(
        std::string_view(reinterpret_cast<const char*>(text->data()), text->size()), map_path.string());
    if (!parsed) return parsed.error();
    map = std::move(*parsed);
  }
  const tools::HumanoidMapFile* map_file = map ? &*map : nullptr;
  const std::string source_name = rig_path.filename().string() + " (the retarget node's source rig)";
  auto from = map_rig(source, map_file, map_path.string(), "source", source_name);
  if (!from) return from.error();
  auto to = map_rig(target, map_file, map_path.string(), "target", "the graph's rig");
  if (!to) return to.error();
  tools::finish_mapped_rig(*from, source_name);
  tools::finish_mapped_rig(*to, "the graph's rig");
  if (Status st = check_humanoid(from->rig.humanoid, from->parents, source_name); !st) return st.error();
  if (Status st = check_humanoid(to->rig.humanoid, to->parents, "the graph's rig"); !st) return st.error();
  if (auto built = make_retarget_map(from->rig, to->rig); !built) return built.error();
  GraphRetargetRigs out;
  out.source_skeleton_hash = hash;
  out.source_joint_count = static_cast<uint16_t>(source.joints.size());
  out.source_bones.assign(from->applied.humanoid.joints.begin(), from->applied.humanoid.joints.end());
  out.target_bones.assign(to->applied.humanoid.joints.begin(), to->applied.humanoid.joints.end());
  out.source_rest = from->applied.rest == RestPose::Bind ? 1 : 0;
  out.target_rest = to->applied.rest == RestPose::Bind ? 1 : 0;
  out.source_rest_rotations = rest_rotations_of(from->applied);
  out.target_rest_rotations = rest_rotations_of(to->applied);
  return out;
}

/// The bytes the graph reads besides itself (each file it reads is in the cook's input log).
struct SourceTally {
  uint64_t bytes = 0;
  void add(const std::vector<uint8_t>& data) { bytes += data.size(); }
};

struct GraphCook {
  CookRecord& record;
  const fs::path& input;
  fs::path dir;
  SourceTally tally;
  std::map<fs::path, SourceScene> clip_sources;  // imported against the rig, by path

  bool fail(json::Pos pos, const std::string& what) {
    record.error = json::where(input.string(), pos) + what;
    return false;
  }

  fs::path resolve(const std::string& relative) const { return (dir / relative).lexically_normal(); }

  /// Hashes and counts bytes read (the record keeps the count even if a later step fails).
  void add(const std::vector<uint8_t>& bytes) {
    tally.add(bytes);
    record.source_bytes = tally.bytes;
  }

  /// Reads the file for the hash, then imports it. Errors name the graph entry and the source.
  bool import(const fs::path& path, json::Pos pos, const ImportOptions& options, SourceScene* out) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) return fail(pos, path.string() + ": no such source file");
    auto bytes = read_bytes(path);
    if (!bytes) return fail(pos, bytes.error().message);
    add(*bytes);
    auto scene = import_scene(path.string(), options);
    if (!scene) return fail(pos, scene.error().message);
    for (const std::string& w : scene->warnings) record.warnings.push_back(path.filename().string() + ": " + w);
    *out = std::move(*scene);
    return true;
  }
};

}  // namespace

void cook_graph(CookRecord& record, const fs::path& input, const fs::path& output, const CookOptions& options_in) {
  // The graph names its rig; --skeleton (meant for the batch's clip files) does not apply.
  CookOptions options = options_in;
  if (options.reference != nullptr)
    record.warnings.push_back("--skeleton is not used for a graph file: its \"skeleton\" names the rig");
  options.reference = nullptr;
  options.reference_name.clear();

  auto text = read_bytes(input);
  if (!text) {
    record.error = text.error().message;
    return;
  }
  GraphCook cook{record, input, input.parent_path(), {}, {}};
  cook.tally.bytes = text->size();
  record.source_bytes = text->size();
  auto doc = json::parse(std::string_view(reinterpret_cast<const char*>(text->data()), text->size()), input.string());
  if (!doc) {
    record.error = doc.error().message;
    return;
  }
  auto manifest = read_graph_manifest(*doc);
  if (!manifest) {
    record.error = manifest.error().message;
    return;
  }

  // The rig, and its meshes.
  SourceScene character;
  ImportOptions rig_options;
  rig_options.up_axis = options.up_axis;
  if (!cook.import(cook.resolve(manifest->skeleton), manifest->skeleton_pos, rig_options, &character)) return;
  if (character.skeleton.joints.empty()) {
    cook.fail(manifest->skeleton_pos,
              cook.resolve(manifest->skeleton).string() + ": has no skeleton for the graph to animate");
    return;
  }
  character.clips.clear();           // only the clips the graph names are cooked
  if (!manifest->skeleton_meshes) {  // the rig alone: its source's own body is not the character's
    character.meshes.clear();
    character.materials.clear();
    character.vertices_over_4_influences = 0;
  }
  SourceSkeleton rig = character.skeleton;
  rig.metres_per_unit = character.metres_per_unit;  // clips in other units are converted into the rig's
  record.joints = static_cast<uint32_t>(rig.joints.size());
  ImportOptions against_rig;
  against_rig.reference = &rig;
  against_rig.up_axis = options.up_axis;

  // Mesh sources bound to the rig: their meshes and materials appended, material indices moved.
  for (size_t m = 0; m < manifest->meshes.size(); ++m) {
    const fs::path path = cook.resolve(manifest->meshes[m]);
    SourceScene part;
    if (!cook.import(path, manifest->mesh_pos[m], against_rig, &part)) return;
    if (part.meshes.empty()) record.warnings.push_back(path.filename().string() + ": has no mesh");
    if (part.metres_per_unit != character.metres_per_unit)
      record.warnings.push_back(
          path.filename().string() +
          ": its unit differs from the skeleton source's; its meshes are kept in their own units");
    const auto offset = static_cast<uint32_t>(character.materials.size());
    for (SourceMesh& mesh : part.meshes) {
      mesh.material += offset;
      character.meshes.push_back(std::move(mesh));
    }
    for (SourceMaterial& material : part.materials) character.materials.push_back(std::move(material));
    character.vertices_over_4_influences += part.vertices_over_4_influences;
  }

  // Clips: each from its source (imported once, with its event sidecar), renamed.
  GraphContext context;
  context.skeleton = &rig;
  context.retarget_rigs = [&](const std::string& rig_file, const std::string& map_file) {
    return retarget_rigs(cook.resolve(rig_file), map_file.empty() ? fs::path() : cook.resolve(map_file), rig,
                         [&](const std::vector<uint8_t>& bytes) { cook.add(bytes); });
  };
  for (const GraphClipSource& entry : manifest->clips) {
    const fs::path path = cook.resolve(entry.source);
    auto it = cook.clip_sources.find(path);
    if (it == cook.clip_sources.end()) {
      SourceScene scene;
      if (!cook.import(path, entry.pos, against_rig, &scene)) return;
      auto sidecar = attach_sidecar_events(path, scene.clips);
      if (!sidecar) {
        cook.fail(entry.pos, sidecar.error().message);
        return;
      }
      if (sidecar->present) cook.add(sidecar->bytes);
      it = cook.clip_sources.emplace(path, std::move(scene)).first;
    }
    const std::vector<SourceClip>& available = it->second.clips;
    const SourceClip* picked = nullptr;
    for (const SourceClip& c : available)
      if (entry.source_clip.empty() || clip_named(c, entry.source_clip)) {
        picked = &c;
        break;
      }
    if (!picked) {
      std::string names;
      for (const SourceClip& c : available) names += (names.empty() ? "'" : ", '") + c.name + "'";
      cook.fail(entry.pos,
                "clip '" + entry.name + "': " + path.string() +
                    (available.empty() ? " has no animation"
                                       : " has no clip named '" + entry.source_clip + "' (its clips: " + names + ")"));
      return;
    }
    SourceClip clip = *picked;
    clip.name = entry.name;
    context.clips.push_back({clip.name, event_duration(clip), clip.events});
    character.clips.push_back(std::move(clip));
  }
  count_scene(record, character);

  auto compiled = compile_graph(*doc, context);
  if (!compiled) {
    record.error = compiled.error().message;
    return;
  }
  for (size_t c = 0; c < character.clips.size(); ++c) character.clips[c].events = compiled->clip_events[c];
  for (const std::string& w : compiled->warnings) record.warnings.push_back(w);

  MeshOptions mesh_options;
  mesh_options.float_vertices = options.float_vertices;
  mesh_options.cloth = options.cloth;
  MeshBuildStats stats;
  auto meshes = build_meshes(character, mesh_options, &stats, &record.warnings);
  if (!meshes) {
    record.error = input.string() + ": " + meshes.error().message;
    return;
  }
  count_meshes(record, *meshes, stats);
  auto clips = cook_clips(character, options, record, input.string());
  if (!clips) {
    record.error = clips.error().message;
    return;
  }
  if (Status st = cook_textures(character, options.textures, input.string(), record.texture_records); !st) {
    record.error = st.message();
    return;
  }

  WriteProvenance provenance;
  if (!finish_provenance(provenance, record, input, options)) return;
  WriteOptions write_options;
  write_options.include_skeleton = true;
  write_options.graphs = std::span<const GraphDef>(&compiled->graph, 1);
  const std::vector<uint8_t> bytes = write_ossa(character, *meshes, *clips, provenance, write_options);
  if (!write_verified(record, bytes, input, output, options.write)) return;

  record.ok = true;
}

}  // namespace ossa::cook::detail
