// describe.cpp — builds ossa-inspect's description of a verified asset and renders it as text
// (see describe.h for why the text is rendered from the JSON rather than from the asset).
//
// Everything read here comes through an Asset, so validation has already proven the indices and
// counts used below; the only defensive work left is making file text safe to print, which
// printable() does for the text output and nlohmann's "replace" error handler does for JSON.
#include "tools/inspect/describe.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include <ossa/format/hash.h>
#include <ossa/skinning/skinning.h>
#include "common/message.h"
#include "tools/inspect/describe_parts.h"

namespace ossa::inspect {
namespace {

using detail::format;
using parts::json;
using parts::str;

template <class V>
size_t count_of(const V* v) {
  return v ? v->size() : 0;
}

json vec3(const fb::Vec3* v) {
  if (!v) return nullptr;
  return json::array({round6(v->x()), round6(v->y()), round6(v->z())});
}

json describe_skeleton(const SkeletonView& skeleton) {
  if (skeleton.empty()) return nullptr;
  const auto parents = skeleton.parents();
  std::vector<int> depth(parents.size(), 0);
  json joints = json::array();
  for (size_t i = 0; i < parents.size(); ++i) {
    // Validation proved parents[i] < i, so the parent's depth is already known.
    depth[i] = parents[i] < 0 ? 0 : depth[static_cast<size_t>(parents[i])] + 1;
    joints.push_back(
        json{{"index", i}, {"name", std::string(skeleton.joint_name(i))}, {"parent", parents[i]}, {"depth", depth[i]}});
  }
  return json{{"joint_count", skeleton.joint_count()}, {"hash", hex16(skeleton.hash())}, {"joints", std::move(joints)}};
}

/// A mesh's morph targets (format v5): what each stores and the error the cooker achieved.
json describe_morph_targets(const MeshView& mesh, float metres_per_unit) {
  json list = json::array();
  for (size_t t = 0; t < mesh.morph_target_count(); ++t) {
    const fb::MorphTarget& target = mesh.morph_target(t);
    const size_t listed = target.vertices()->size();
    const size_t normals = target.normal_deltas() ? target.normal_deltas()->size() : 0;
    const size_t tangents = target.tangent_deltas() ? target.tangent_deltas()->size() : 0;
    const size_t bytes = 4 * listed + 2 * (target.position_deltas()->size() + normals + tangents);
    list.push_back(json{{"name", str(target.name())},
                        {"vertices", listed},
                        {"normals", normals != 0},
                        {"tangents", tangents != 0},
                        {"bytes", bytes},
                        {"default_weight", round6(target.default_weight())},
                        {"position_error", round6(target.position_error())},
                        {"position_error_mm", round6(1000.0 * metres_per_unit * target.position_error())},
                        {"normal_error_deg", round6(target.normal_error() * 57.29577951308232)}});
  }
  return list;
}

json describe_mesh(const MeshView& mesh, float metres_per_unit, const DescribeOptions& options) {
  json layout = json::array();
  for (const fb::VertexAttribute& a : mesh.layout())
    layout.push_back(json{{"semantic", fb::EnumNameVertexSemantic(a.semantic())},
                          {"format", fb::EnumNameVertexFormat(a.format())},
                          {"offset", a.offset()}});
  json submeshes = json::array();
  for (const fb::Submesh& s : mesh.submeshes())
    submeshes.push_back(
        json{{"first_index", s.first_index()}, {"index_count", s.index_count()}, {"material", s.material()}});
  const fb::Mesh& m = *mesh.fb;
  json out{{"name", std::string(mesh.name())},
           {"vertex_count", mesh.vertex_count()},
           {"triangle_count", mesh.index_count() / 3},
           {"vertex_stride", mesh.vertex_stride()},
           {"vertex_bytes", mesh.vertex_bytes().size()},
           {"index_format", fb::EnumNameIndexFormat(mesh.index_format())},
           {"index_count", mesh.index_count()},
           {"index_bytes", mesh.index_bytes().size()},
           {"layout", std::move(layout)},
           {"submeshes", std::move(submeshes)},
           {"joint_slots", mesh.joints().size()},
           {"bounds", json{{"min", vec3(m.bounds_min())}, {"max", vec3(m.bounds_max())}}},
           {"position_offset", vec3(m.position_offset())},
           {"position_scale", vec3(m.position_scale())}};
  if (options.influences) {
    if (const InfluenceOrder o = influence_order(mesh); o.unorm8_weights)
      out["influences"] = json{
          {"vertices_by_class", o.vertices_by_class}, {"class_runs", o.class_runs}, {"class_ordered", o.class_ordered}};
  }
  // Only when present, so files without targets describe as they did before format v5.
  if (mesh.morph_target_count() > 0) out["morph_targets"] = describe_morph_targets(mesh, metres_per_unit);
  if (const fb::Cloth* c = m.cloth()) {  // format v10 (docs/CLOTH.md)
    size_t fixed = 0;
    for (const float w : *c->inverse_masses()) fixed += w == 0.0f ? 1 : 0;
    const auto size = [](const auto* v) { return v ? static_cast<size_t>(v->size()) : size_t{0}; };
    out["cloth"] = json{{"particles", c->particle_vertices()->size()},
                        {"fixed", fixed},
                        {"vertices", c->vertices()->size()},
                        {"stretch", size(c->stretch())},
                        {"bend", size(c->bend())},
                        {"tethers", size(c->tethers())},
                        {"colliders", size(c->colliders())},
                        {"thickness_m", c->thickness() * metres_per_unit}};
  }
  return out;
}

/// Clip payload bytes: what its channel tables and key streams take in the file.
size_t clip_bytes(const ClipView& clip) {
  return clip.constants().size_bytes() + clip.animated().size_bytes() + clip.key_frames().size_bytes() +
         clip.key_values().size_bytes();
}

json describe_compression(const ClipView& clip, const SkeletonView& skeleton, float metres_per_unit) {
  const fb::ClipCompression* c = clip.compression();
  if (!c) return nullptr;
  const double mm = 1000.0 * metres_per_unit;
  const size_t bytes = clip_bytes(clip);
  // The worst joint is named only when this file's skeleton is the clip's rig; a clip-only file
  // knows just the index.
  const bool named =
      !skeleton.empty() && skeleton.hash() == clip.skeleton_hash() && c->worst_joint() < skeleton.joint_count();
  return json{{"tolerance", round6(c->tolerance())},
              {"tolerance_mm", round6(c->tolerance() * mm)},
              {"probe_distance", round6(c->probe_distance())},
              {"max_error", round6(c->max_error())},
              {"max_error_mm", round6(c->max_error() * mm)},
              {"mean_error", round6(c->mean_error())},
              {"mean_error_mm", round6(c->mean_error() * mm)},
              {"worst_joint", c->worst_joint()},
              {"worst_joint_name", named ? json(std::string(skeleton.joint_name(c->worst_joint()))) : json(nullptr)},
              {"raw_bytes", c->raw_bytes()},
              {"ratio", bytes ? round6(static_cast<double>(c->raw_bytes()) / static_cast<double>(bytes)) : 0.0}};
}

/// Every channel of a clip, by joint then kind: how it is stored (-v).
json describe_channels(const ClipView& clip, const SkeletonView& skeleton) {
  static const char* const kKinds[] = {"translation", "rotation", "scale"};
  struct Row {
    uint16_t joint;
    size_t kind;
    bool animated;
    uint32_t keys;
    uint32_t bits[3];  // per stored component
  };
  std::vector<Row> rows;
  // Validation proved every channel enum is 0..2.
  for (const fb::ConstantChannel& c : clip.constants())
    rows.push_back({c.joint(), static_cast<size_t>(c.channel()), false, 1, {32, 32, 32}});
  for (const fb::AnimatedChannel& a : clip.animated())
    rows.push_back({a.joint(),
                    static_cast<size_t>(a.channel()),
                    true,
                    a.key_count(),
                    {a.bits()->Get(0), a.bits()->Get(1), a.bits()->Get(2)}});
  std::sort(rows.begin(), rows.end(),
            [](const Row& x, const Row& y) { return x.joint != y.joint ? x.joint < y.joint : x.kind < y.kind; });
  // Joint names only when this file's skeleton is the clip's rig (as for worst_joint_name).
  const bool named = !skeleton.empty() && skeleton.hash() == clip.skeleton_hash();
  json out = json::array();
  for (const Row& r : rows)
    out.push_back(
        json{{"joint", r.joint},
             {"joint_name", named && r.joint < skeleton.joint_count() ? json(std::string(skeleton.joint_name(r.joint)))
                                                                      : json(nullptr)},
             {"channel", kKinds[r.kind]},
             {"storage", r.animated ? "animated" : "constant"},
             {"key_count", r.keys},
             {"bits", json::array({r.bits[0], r.bits[1], r.bits[2]})}});
  return out;
}

json describe_clip(const ClipView& clip, const SkeletonView& skeleton, float metres_per_unit,
                   const DescribeOptions& options) {
  size_t constants[3] = {0, 0, 0}, animated[3] = {0, 0, 0}, keys[3] = {0, 0, 0};
  // Validation proved every channel enum is 0..2.
  for (const fb::ConstantChannel& c : clip.constants()) ++constants[static_cast<size_t>(c.channel())];
  for (const fb::AnimatedChannel& a : clip.animated()) {
    ++animated[static_cast<size_t>(a.channel())];
    keys[static_cast<size_t>(a.channel())] += a.key_count();
  }
  const auto by_kind = [](const size_t v[3]) {
    return json{{"translation", v[0]}, {"rotation", v[1]}, {"scale", v[2]}};
  };
  json root_motion = nullptr;
  if (const fb::RootMotion* rm = clip.root_motion()) {
    static const char* const kAxes[] = {"x", "y", "z"};
    root_motion = json{{"up_axis", rm->up_axis() <= 2 ? kAxes[rm->up_axis()] : "?"}};
  }
  json out{{"name", std::string(clip.name())},
           {"duration", round6(clip.duration())},
           {"sample_rate", round6(clip.sample_rate())},
           {"frame_count", clip.frame_count()},
           {"skeleton_hash", hex16(clip.skeleton_hash())},
           {"joint_count", clip.joint_count()},
           {"binds_to_file_skeleton", !skeleton.empty() && skeleton.hash() == clip.skeleton_hash()},
           {"constant_channels", by_kind(constants)},
           {"animated_channels", by_kind(animated)},
           {"key_count", clip.key_count()},
           {"animated_keys", by_kind(keys)},
           {"bytes", clip_bytes(clip)},
           {"compression", describe_compression(clip, skeleton, metres_per_unit)},
           {"root_motion", std::move(root_motion)}};
  // Only when present, so files without events describe as they did before format v3.
  if (const auto* events = clip.fb->events(); events && events->size() > 0) {
    json list = json::array();
    for (const fb::ClipEvent* e : *events) list.push_back(json{{"name", str(e->name())}, {"time", round6(e->time())}});
    out["events"] = std::move(list);
  }
  if (clip.morph_track_count() > 0) {
    json list = json::array();
    for (size_t k = 0; k < clip.morph_track_count(); ++k) {
      const fb::MorphTrack& t = clip.morph_track(k);
      list.push_back(json{{"name", str(t.name())},
                          {"keys", t.key_frames()->size()},
                          {"min", round6(t.range_min())},
                          {"max", round6(t.range_min() + t.range_extent())},
                          {"max_error", round6(t.max_error())}});
    }
    out["morph_weights"] = std::move(list);
  }
  if (options.channels) out["channels"] = describe_channels(clip, skeleton);
  return out;
}

json describe_material(const fb::Material& m) {
  json textures = json::array();
  if (m.textures()) {
    for (const fb::Texture* t : *m.textures())
      textures.push_back(json{{"role", fb::EnumNameTextureRole(t->role())},
                              {"mime", str(t->mime())},
                              {"bytes", count_of(t->data())},
                              {"path", str(t->path())},
                              {"encoding", fb::EnumNameTextureEncoding(t->encoding())},
                              {"srgb", t->srgb()},
                              {"width", t->width()},
                              {"height", t->height()},
                              {"mips", static_cast<unsigned>(t->mip_count())}});
  }
  return json{
      {"name", str(m.name())},
      {"ambient", vec3(m.ambient())},
      {"diffuse", vec3(m.diffuse())},
      {"specular", vec3(m.specular())},
      {"shininess", round6(m.shininess())},
      {"opacity", round6(m.opacity())},
      {"emissive", m.emissive() ? vec3(m.emissive()) : json::array({0.0, 0.0, 0.0})},
      {"pbr", m.pbr() ? json{{"metallic", round6(m.pbr()->metallic())}, {"roughness", round6(m.pbr()->roughness())}}
                      : json(nullptr)},
      {"textures", std::move(textures)}};
}

// ---- text ----------------------------------------------------------------------------------

/// A JSON number or string as text; floats in %g so "1" stays "1".
std::string text(const json& v) {
  if (v.is_string()) return detail::printable(v.get<std::string>(), 1000);
  if (v.is_number_float()) return format("%g", v.get<double>());
  if (v.is_null()) return "-";
  return v.dump();
}

std::string vec_text(const json& v) {
  if (!v.is_array()) return "-";
  std::string out = "(";
  for (size_t i = 0; i < v.size(); ++i) out += (i ? ", " : "") + text(v[i]);
  return out + ")";
}

std::string quoted_name(const json& v) {
  const std::string name = text(v);
  return name.empty() ? std::string() : " '" + name + "'";
}

}  // namespace

std::string hex16(uint64_t value) { return format("%016llx", static_cast<unsigned long long>(value)); }

double round6(double value) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", value);
  const double r = std::strtod(buf, nullptr);
  return r == 0.0 ? 0.0 : r;
}

json describe(const Asset& asset, std::string_view file_name, const DescribeOptions& options) {
  const fb::File& file = asset.file();
  json provenance = nullptr;
  if (const fb::Provenance* p = file.provenance()) {
    provenance = json{{"source_name", str(p->source_name())},
                      {"source_hash", hex16(p->source_hash())},
                      {"cooker_version", str(p->cooker_version())},
                      {"options", str(p->options())}};
    // Format v4: every file the cook read, and the key a build cache compares.
    if (const auto* inputs = p->inputs()) {
      json list = json::array();
      for (const fb::InputFile* f : *inputs) {
        json entry{{"path", str(f->path())}};
        if (f->absent()) entry["absent"] = true;
        else entry.update(json{{"hash", hex16(f->hash())}, {"bytes", f->size()}});
        list.push_back(std::move(entry));
      }
      provenance["inputs"] = std::move(list);
      provenance["cook_key"] = hex16(p->cook_key());
    }
  }
  const SkeletonView skeleton = asset.skeleton();
  json meshes = json::array(), clips = json::array(), materials = json::array();
  for (size_t i = 0; i < asset.mesh_count(); ++i)
    meshes.push_back(describe_mesh(asset.mesh(i), asset.file().metres_per_unit(), options));
  for (size_t i = 0; i < asset.clip_count(); ++i)
    clips.push_back(describe_clip(asset.clip(i), skeleton, file.metres_per_unit(), options));
  for (size_t i = 0; i < asset.material_count(); ++i) materials.push_back(describe_material(asset.material(i)));
  json out{{"schema", kSchema},
           {"schema_version", kSchemaVersion},
           {"file", std::string(file_name)},
           {"file_bytes", asset.bytes().size()},
           // Hash of every byte: goldens and build caches see any change in cooked output, not
           // only changes in the counts and sizes summarised below.
           {"content_hash", hex16(hash_bytes(asset.bytes().data(), asset.bytes().size()))},
           {"format_version", file.version()},
           {"metres_per_unit", round6(file.metres_per_unit())},
           {"provenance", std::move(provenance)},
           {"skeleton", describe_skeleton(skeleton)},
           {"meshes", std::move(meshes)},
           {"clips", std::move(clips)},
           {"materials", std::move(materials)}};
  if (const auto* graphs = file.graphs(); graphs && graphs->size() > 0) {
    json list = json::array();
    for (const fb::Graph* g : *graphs) list.push_back(parts::describe_graph(*g));
    out["graphs"] = std::move(list);
  }
  return out;
}

std::string describe_text(const json& d) {
  std::string out;
  const auto line = [&](const std::string& s) { out += s + "\n"; };
  line("file             " + text(d["file"]) + " (" + text(d["file_bytes"]) + " bytes, content hash " +
       text(d["content_hash"]) + ")");
  line("format version   " + text(d["format_version"]));
  line("metres per unit  " + text(d["metres_per_unit"]));
  if (const json& p = d["provenance"]; p.is_object()) {
    line("provenance       source '" + text(p["source_name"]) + "' (hash " + text(p["source_hash"]) + "), " +
         text(p["cooker_version"]) + ", options '" + text(p["options"]) + "'");
    if (p.contains("cook_key")) line("cook key         " + text(p["cook_key"]));
    if (p.contains("inputs"))
      for (const json& f : p["inputs"])
        line("  input          " + text(f["path"]) +
             (f.contains("absent") ? std::string(" (absent)")
                                   : " (" + text(f["bytes"]) + " bytes, hash " + text(f["hash"]) + ")"));
  } else line("provenance       -");

  if (const json& s = d["skeleton"]; s.is_object()) {
    line("");
    line("skeleton: " + text(s["joint_count"]) + " joints, hash " + text(s["hash"]));
    // Indentation shows the tree, up to kMaxIndent levels; deeper joints say their depth instead,
    // so a 30,000-joint chain prints 30,000 short lines, not gigabytes of spaces.
    constexpr int kMaxIndent = 32;
    for (const json& j : s["joints"]) {
      const int depth = j["depth"].get<int>();
      line(std::string(2 + 2 * static_cast<size_t>(std::min(depth, kMaxIndent)), ' ') +
           (depth > kMaxIndent ? "(depth " + std::to_string(depth) + ") " : std::string()) + "[" + text(j["index"]) +
           "] " + text(j["name"]));
    }
  } else {
    line("");
    line("skeleton: none");
  }

  size_t index = 0;
  for (const json& m : d["meshes"]) {
    line("");
    line(format("mesh %zu", index++) + quoted_name(m["name"]) + ": " + text(m["vertex_count"]) + " vertices, " +
         text(m["triangle_count"]) + " triangles, " + text(m["vertex_stride"]) + " bytes/vertex");
    line("  vertex bytes   " + text(m["vertex_bytes"]));
    line("  index bytes    " + text(m["index_bytes"]) + " (" + text(m["index_format"]) + ", " + text(m["index_count"]) +
         " indices)");
    std::string layout;
    for (const json& a : m["layout"])
      layout += (layout.empty() ? "" : ", ") + text(a["semantic"]) + " " + text(a["format"]) + " @" + text(a["offset"]);
    line("  layout         " + (layout.empty() ? std::string("-") : layout));
    size_t k = 0;
    for (const json& s : m["submeshes"])
      line(format("  submesh %-6zu first %s, count %s, material %s", k++, text(s["first_index"]).c_str(),
                  text(s["index_count"]).c_str(), text(s["material"]).c_str()));
    line("  joint slots    " + text(m["joint_slots"]));
    line("  bounds         " + vec_text(m["bounds"]["min"]) + " .. " + vec_text(m["bounds"]["max"]));
    if (m.contains("influences")) {
      const json& in = m["influences"];
      const json& c = in["vertices_by_class"];
      const std::string runs = text(in["class_runs"]);
      line("  influences     " + text(c[0]) + " one joint, " + text(c[1]) + " up to 1, " + text(c[2]) + " up to 2, " +
           text(c[3]) + " up to 3, " + text(c[4]) + " up to 4 (vertices)");
      line(in["class_ordered"].get<bool>()
               ? "  vertex order   by influence class (" + runs + " ranges: skin_cpu skins each in one loop)"
               : "  vertex order   not by influence class (" + runs +
                     " runs: skin_cpu classifies it batch by batch; cooking it again orders it)");
    }
    if (m.contains("cloth")) {
      const json& c = m["cloth"];
      line("  cloth          " + text(c["particles"]) + " particles (" + text(c["fixed"]) + " fixed) on " +
           text(c["vertices"]) + " vertices, " + text(c["stretch"]) + " stretch + " + text(c["bend"]) +
           " bend edges, " + text(c["tethers"]) + " tethers, " + text(c["colliders"]) + " colliders");
    }
    if (m.contains("morph_targets")) {
      size_t t = 0;
      for (const json& mt : m["morph_targets"])
        line(format("  morph %-8zu ", t++) + "'" + text(mt["name"]) + "': " + text(mt["vertices"]) + " vertices" +
             (mt["normals"].get<bool>() ? " + normals" : "") + (mt["tangents"].get<bool>() ? " + tangents" : "") +
             ", " + text(mt["bytes"]) + " bytes, error " + text(mt["position_error_mm"]) + " mm / " +
             text(mt["normal_error_deg"]) + " deg, default weight " + text(mt["default_weight"]));
    }
  }

  index = 0;
  for (const json& c : d["clips"]) {
    const auto kinds = [](const json& k) {
      return text(k["translation"]) + " translation, " + text(k["rotation"]) + " rotation, " + text(k["scale"]) +
             " scale";
    };
    line("");
    line(format("clip %zu", index++) + quoted_name(c["name"]) + ": " + text(c["duration"]) + " s, " +
         text(c["frame_count"]) + " frames at " + text(c["sample_rate"]) + " frames/s, " + text(c["key_count"]) +
         " keys, " + text(c["bytes"]) + " bytes");
    line("  skeleton       " + text(c["skeleton_hash"]) + ", " + text(c["joint_count"]) + " joints" +
         (c["binds_to_file_skeleton"].get<bool>() ? " (this file's skeleton)" : " (another file's skeleton)"));
    line("  constant       " + kinds(c["constant_channels"]));
    line("  animated       " + kinds(c["animated_channels"]) + " (keys: " + kinds(c["animated_keys"]) + ")");
    if (const json& k = c["compression"]; k.is_object()) {
      const std::string worst = k["worst_joint_name"].is_string() ? " '" + text(k["worst_joint_name"]) + "'" : "";
      line("  compression    tolerance " + text(k["tolerance"]) + " (" + text(k["tolerance_mm"]) + " mm), max error " +
           text(k["max_error"]) + " (" + text(k["max_error_mm"]) + " mm) at joint " + text(k["worst_joint"]) + worst +
           ", mean " + text(k["mean_error"]) + " (" + text(k["mean_error_mm"]) + " mm), probe " +
           text(k["probe_distance"]));
      line("  size           " + text(c["bytes"]) + " bytes, raw " + text(k["raw_bytes"]) + " bytes, ratio " +
           text(k["ratio"]) + ":1");
    } else {
      line("  compression    -");
    }
    line("  root motion    " +
         (c["root_motion"].is_object() ? "yes, up axis " + text(c["root_motion"]["up_axis"]) : std::string("no")));
    if (c.contains("morph_weights")) {
      std::string tracks;
      for (const json& t : c["morph_weights"])
        tracks += (tracks.empty() ? "" : ", ") + text(t["name"]) + " (" + text(t["keys"]) + " keys, " + text(t["min"]) +
                  ".." + text(t["max"]) + ", error " + text(t["max_error"]) + ")";
      line("  morph weights  " + tracks);
    }
    if (c.contains("events")) {
      std::string events;
      for (const json& e : c["events"])
        events += (events.empty() ? "" : ", ") + text(e["name"]) + " @" + text(e["time"]);
      line("  events         " + events);
    }
    if (c.contains("channels")) {
      line("  channels       " + text(json(c["channels"].size())));
      for (const json& ch : c["channels"]) {
        const bool animated = ch["storage"] == "animated";
        line("    joint " + text(ch["joint"]) + (ch["joint_name"].is_string() ? quoted_name(ch["joint_name"]) : "") +
             " " + text(ch["channel"]) + ": " +
             (animated ? text(ch["key_count"]) + " keys at " + text(ch["bits"][0]) + "+" + text(ch["bits"][1]) + "+" +
                             text(ch["bits"][2]) + " bits"
                       : std::string("constant")));
      }
    }
  }

  if (d.contains("graphs")) {
    for (const json& g : d["graphs"]) {
      line("");
      line("graph '" + text(g["name"]) + "': " + text(g["node_count"]) + " nodes, clips " + [&] {
        std::string c;
        for (const json& n : g["clips"]) c += (c.empty() ? "" : ", ") + text(n);
        return c;
      }());
      for (const json& p : g["parameters"])
        line("  parameter      " + text(p["name"]) + " (" + text(p["type"]) + ", default " + text(p["default"]) + ")");
      for (const json& m : g["machines"]) {
        std::string states;
        for (const json& st : m["states"]) states += (states.empty() ? "" : ", ") + text(st);
        line("  machine        " + text(m["name"]) + ": states " + states + "; entry " + text(m["entry"]));
        for (const json& t : m["transitions"])
          line("    " + text(t["from"]) + " -> " + text(t["to"]) + " when " + text(t["when"]) +
               (t.contains("exit_time") ? ", exit time " + text(t["exit_time"]) : std::string()) + ": " +
               text(t["mode"]) + " " + text(t["duration"]) + " s");
      }
      for (const json& m : g.value("montages", json::array())) {
        std::string sections;
        for (const json& sec : m["sections"])
          sections += (sections.empty() ? "" : ", ") + text(sec["name"]) + " -> " +
                      (sec["next"].get<std::string>().empty() ? std::string("end") : text(sec["next"]));
        line("  montage        " + text(m["name"]) + " (group " + text(m["group"]) + "): " + text(m["length"]) +
             " s, sections " + sections + "; blend in " + text(m["blend_in"]) + ", out " + text(m["blend_out"]));
      }
    }
  }

  index = 0;
  for (const json& m : d["materials"]) {
    line("");
    line(format("material %zu", index++) + quoted_name(m["name"]));
    line("  colours        ambient " + vec_text(m["ambient"]) + ", diffuse " + vec_text(m["diffuse"]) + ", specular " +
         vec_text(m["specular"]));
    line("  shininess      " + text(m["shininess"]) + ", opacity " + text(m["opacity"]));
    if (m["emissive"] != json::array({0.0, 0.0, 0.0})) line("  emissive       " + vec_text(m["emissive"]));
    if (!m["pbr"].is_null())
      line("  pbr            metallic " + text(m["pbr"]["metallic"]) + ", roughness " + text(m["pbr"]["roughness"]));
    for (const json& t : m["textures"]) {
      std::string where;
      if (t["bytes"].get<size_t>() > 0 && t["encoding"].get<std::string>() != "Source")
        where = text(t["encoding"]) + (t["srgb"].get<bool>() ? " sRGB " : " ") + text(t["width"]) + " x " +
                text(t["height"]) + ", " + text(t["mips"]) + " mips, " + text(t["bytes"]) + " bytes embedded";
      else if (t["bytes"].get<size_t>() > 0)
        where = text(t["bytes"]) + " bytes embedded" +
                (t["mime"].get<std::string>().empty() ? "" : " (" + text(t["mime"]) + ")");
      if (!t["path"].get<std::string>().empty())
        where += (where.empty() ? "" : ", ") + ("path '" + text(t["path"]) + "'");
      line(format("  texture %-6s %s", text(t["role"]).c_str(), where.c_str()));
    }
  }
  return out;
}

}  // namespace ossa::inspect
