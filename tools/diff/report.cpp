// report.cpp — DiffReport as JSON and as text (report.h).
//
// The JSON mirrors the report struct field for field, with units in the key names (_mm, _deg,
// _s, _hz) so a reader never guesses; floats are rounded to 6 significant digits (as
// ossa-inspect does) so outputs are stable across machines. The text names every difference on
// its own line, which is what a CI log shows a person, and with -v every item's figures.
#include "tools/diff/report.h"

#include <cstdio>
#include <string>

#include "tools/inspect/describe.h"
#include "common/message.h"

namespace ossa::diff {
namespace {

using json = nlohmann::ordered_json;
using inspect::hex16;
using inspect::round6;
using ossa::detail::format;

json optional_number(const std::optional<double>& v) { return v ? json(round6(*v)) : json(nullptr); }

json file_json(const FileFacts& f) {
  return json{{"path", f.path},
              {"bytes", f.bytes},
              {"metres_per_unit", round6(f.metres_per_unit)},
              {"format_version", f.format_version},
              {"source_name", f.source_name},
              {"source_hash", hex16(f.source_hash)},
              {"cooker_version", f.cooker_version},
              {"options", f.options}};
}

json skeleton_json(const SkeletonSection& s) {
  json renamed = json::array(), parents = json::array(), joints = json::array();
  for (const auto& [o, n] : s.renamed) renamed.push_back(json{{"old", o}, {"new", n}});
  for (const auto& p : s.parent_changed)
    parents.push_back(json{{"joint", p.joint}, {"old_parent", p.old_parent}, {"new_parent", p.new_parent}});
  for (const JointBind& j : s.bind)
    joints.push_back(json{{"name", j.name},
                          {"translation_mm", round6(j.translation_mm)},
                          {"rotation_deg", round6(j.rotation_deg)},
                          {"scale_delta", round6(j.scale_delta)},
                          {"probe_mm", round6(j.probe_mm)}});
  return json{{"old_present", s.old_present},
              {"new_present", s.new_present},
              {"old_joints", s.old_joints},
              {"new_joints", s.new_joints},
              {"old_hash", hex16(s.old_hash)},
              {"new_hash", hex16(s.new_hash)},
              {"added", s.added},
              {"removed", s.removed},
              {"renamed", renamed},
              {"reordered", s.reordered},
              {"parent_changed", parents},
              {"max_bind_mm", round6(s.max_bind_mm)},
              {"worst_joint", s.worst_joint},
              {"joints", joints}};
}

json mesh_shape_json(const MeshShape& s) {
  return json{{"vertex_count", s.vertex_count},
              {"index_count", s.index_count},
              {"submesh_count", s.submesh_count},
              {"vertex_stride", s.vertex_stride},
              {"layout", s.layout}};
}

json meshes_json(const MeshSection& s) {
  json items = json::array();
  for (const MeshItem& m : s.items)
    items.push_back(json{{"name", m.name},
                         {"old", mesh_shape_json(m.old_shape)},
                         {"new", mesh_shape_json(m.new_shape)},
                         {"topology_same", m.topology_same},
                         {"index_data_same", m.index_data_same},
                         {"layout_same", m.layout_same},
                         {"max_displacement_mm", optional_number(m.max_displacement_mm)},
                         {"worst_vertex", m.max_displacement_mm ? json(m.worst_vertex) : json(nullptr)},
                         {"note", m.note}});
  return json{{"old_count", s.old_count},
              {"new_count", s.new_count},
              {"added", s.added},
              {"removed", s.removed},
              {"max_displacement_mm", round6(s.max_displacement_mm)},
              {"items", items}};
}

json clip_side_json(const ClipSide& s) {
  json events = json::array();
  for (const ClipEventFact& e : s.events) events.push_back(json{{"name", e.name}, {"time_s", round6(e.time_s)}});
  return json{{"duration_s", round6(s.duration_s)},
              {"rate_hz", round6(s.rate_hz)},
              {"frame_count", s.frame_count},
              {"root_motion", s.root_motion},
              {"events", events},
              {"cooker_max_error_mm", optional_number(s.cooker_max_error_mm)}};
}

json clips_json(const ClipSection& s) {
  json items = json::array();
  for (const ClipItem& c : s.items)
    items.push_back(json{{"name", c.name},
                         {"old", clip_side_json(c.old_side)},
                         {"new", clip_side_json(c.new_side)},
                         {"sampled", c.sampled},
                         {"times", c.times},
                         {"joints_compared", c.joints_compared},
                         {"joints_skipped", c.joints_skipped},
                         {"max_error_mm", round6(c.max_error_mm)},
                         {"max_error_at_frames_mm", round6(c.max_error_at_frames_mm)},
                         {"worst_joint", c.worst_joint},
                         {"worst_time_s", round6(c.worst_time_s)},
                         {"root_motion_mm", optional_number(c.root_motion_mm)},
                         {"root_motion_deg", optional_number(c.root_motion_deg)},
                         {"events_same", c.events_same},
                         {"morph_tracks_compared", c.morph_tracks_compared},
                         {"max_morph_weight_error", round6(c.max_morph_weight_error)},
                         {"note", c.note}});
  return json{{"old_count", s.old_count},
              {"new_count", s.new_count},
              {"added", s.added},
              {"removed", s.removed},
              {"max_error_mm", round6(s.max_error_mm)},
              {"items", items}};
}

json textures_json(const std::vector<TextureFact>& textures) {
  json out = json::array();
  for (const TextureFact& t : textures)
    out.push_back(json{{"role", t.role},
                       {"path", t.path},
                       {"mime", t.mime},
                       {"bytes", t.bytes},
                       {"hash", hex16(t.hash)},
                       {"encoding", t.encoding},
                       {"srgb", t.srgb},
                       {"width", t.width},
                       {"height", t.height},
                       {"mips", t.mips}});
  return out;
}

json materials_json(const MaterialSection& s) {
  json items = json::array();
  for (const MaterialItem& m : s.items)
    items.push_back(json{{"name", m.name},
                         {"changed", m.changed},
                         {"old_textures", textures_json(m.old_textures)},
                         {"new_textures", textures_json(m.new_textures)}});
  return json{{"old_count", s.old_count},
              {"new_count", s.new_count},
              {"added", s.added},
              {"removed", s.removed},
              {"items", items}};
}

json graph_shape_json(const GraphShape& s) {
  return json{{"parameters", s.parameters}, {"clips", s.clips},   {"nodes", s.nodes},
              {"machines", s.machines},     {"states", s.states}, {"transitions", s.transitions}};
}

json graphs_json(const GraphSection& s) {
  json items = json::array();
  for (const GraphItem& g : s.items)
    items.push_back(json{{"name", g.name},
                         {"old", graph_shape_json(g.old_shape)},
                         {"new", graph_shape_json(g.new_shape)},
                         {"same", g.same},
                         {"changed", g.changed}});
  return json{{"old_count", s.old_count},
              {"new_count", s.new_count},
              {"added", s.added},
              {"removed", s.removed},
              {"items", items}};
}

std::string figure(double value, const std::string& unit) {
  return format("%.4g", value) + (unit.empty() ? "" : " " + unit);
}

}  // namespace

json to_json(const DiffReport& r) {
  json differences = json::array();
  for (const Difference& d : r.differences)
    differences.push_back(json{{"section", d.section},
                               {"item", d.item},
                               {"what", d.what},
                               {"value", d.value ? json(round6(*d.value)) : json(d.text)},
                               {"unit", d.unit},
                               {"limit", optional_number(d.limit)},
                               {"detail", d.detail}});
  const auto change = static_cast<double>(r.new_file.bytes) - static_cast<double>(r.old_file.bytes);
  return json{
      {"schema", "ossa-diff"},
      {"schema_version", kJsonSchemaVersion},
      {"old", file_json(r.old_file)},
      {"new", file_json(r.new_file)},
      {"tolerance_mm", round6(r.tolerance_mm)},
      {"same", r.same()},
      {"sections",
       json{{"file", json{{"bytes_change", static_cast<int64_t>(change)},
                          {"bytes_change_percent",
                           r.old_file.bytes ? round6(100.0 * change / static_cast<double>(r.old_file.bytes)) : 0.0}}},
            {"skeleton", skeleton_json(r.skeleton)},
            {"meshes", meshes_json(r.meshes)},
            {"clips", clips_json(r.clips)},
            {"materials", materials_json(r.materials)},
            {"graphs", graphs_json(r.graphs)}}},
      {"differences", differences},
      {"notes", r.notes}};
}

std::string difference_line(const Difference& d) {
  std::string line = d.section + (d.item.empty() ? "" : " '" + d.item + "'") + ": " + d.what + ": ";
  line += d.value ? figure(*d.value, d.unit) : ossa::detail::printable(d.text, 400);
  if (d.value && d.limit) line += " > " + figure(*d.limit, d.unit);
  if (!d.detail.empty()) line += " (" + ossa::detail::printable(d.detail, 400) + ")";
  return line;
}

std::string to_text(const DiffReport& r, bool verbose) {
  std::string out;
  const auto line = [&](const std::string& s) { out += s + "\n"; };
  const auto file = [](const FileFacts& f) {
    return ossa::detail::printable(f.path, 400) + " (" + std::to_string(f.bytes) + " bytes)";
  };
  line("old " + file(r.old_file));
  line("new " + file(r.new_file));
  for (const Difference& d : r.differences) line(difference_line(d));
  if (verbose) {
    const SkeletonSection& s = r.skeleton;
    if (s.old_present && s.new_present)
      line(format("  skeleton: %zu -> %zu joints, hash %s, bind pose max %.4g mm", s.old_joints, s.new_joints,
                  s.old_hash == s.new_hash ? "same" : "changed", s.max_bind_mm) +
           (s.worst_joint.empty() ? "" : " (joint '" + ossa::detail::printable(s.worst_joint) + "')"));
    for (const MeshItem& m : r.meshes.items)
      line(format("  mesh '%s': %u -> %u vertices, topology %s, layout %s, ", m.name.c_str(), m.old_shape.vertex_count,
                  m.new_shape.vertex_count, m.topology_same ? "same" : "changed", m.layout_same ? "same" : "changed") +
           (m.max_displacement_mm
                ? format("max displacement %.4g mm (vertex %u)", *m.max_displacement_mm, m.worst_vertex)
                : std::string("displacement not measured")));
    for (const ClipItem& c : r.clips.items) {
      std::string text =
          format("  clip '%s': %.4g s at %.4g Hz", c.name.c_str(), c.old_side.duration_s, c.old_side.rate_hz);
      if (c.sampled)
        text += format(", %zu times x %zu joints, max joint error %.4g mm (joint '%s' at %.4g s; at frames %.4g mm)",
                       c.times, c.joints_compared, c.max_error_mm, ossa::detail::printable(c.worst_joint).c_str(),
                       c.worst_time_s, c.max_error_at_frames_mm);
      if (c.morph_tracks_compared > 0)
        text +=
            format(", %zu morph tracks, max weight difference %.4g", c.morph_tracks_compared, c.max_morph_weight_error);
      if (c.old_side.cooker_max_error_mm && c.new_side.cooker_max_error_mm)
        text += format(", cooker's error %.4g -> %.4g mm", *c.old_side.cooker_max_error_mm,
                       *c.new_side.cooker_max_error_mm);
      line(text);
    }
    for (const MaterialItem& m : r.materials.items)
      line("  material '" + m.name +
           "': " + (m.changed.empty() ? "same" : std::to_string(m.changed.size()) + " changes"));
    for (const GraphItem& g : r.graphs.items) line("  graph '" + g.name + "': " + (g.same ? "same" : "changed"));
    for (const std::string& n : r.notes) line("  note: " + ossa::detail::printable(n, 400));
  }
  if (r.same()) line(format("same within %g mm", r.tolerance_mm));
  else
    line(format("differs: %zu difference%s (tolerance %g mm)", r.differences.size(),
                r.differences.size() == 1 ? "" : "s", r.tolerance_mm));
  return out;
}

}  // namespace ossa::diff
