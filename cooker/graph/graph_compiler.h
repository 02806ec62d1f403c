// graph_compiler.h — the graph compiler's class, shared by the files that define its members
// (internal to cooker/graph/): graph_compile.cpp (document, manifest, parameters, named nodes),
// graph_compile_nodes.cpp (the node dispatch and the blend-tree nodes), graph_compile_procedural.cpp
// (IK, aim, foot placement/lock, spring) and graph_compile_machine.cpp (state machines). One class
// because every reader shares the Checker, the GraphDef being built and the name indices; several
// files because each node family reads on its own.
#pragma once

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <map>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "cooker/clip/clip_events.h"
#include "cooker/graph/graph_compile.h"
#include "cooker/graph/graph_condition.h"
#include "cooker/graph/graph_montage.h"
#include "cooker/json/json_check.h"

namespace ossa::cook::graph_detail {

using json::Checker;
using json::Member;
using json::Pos;
using json::Type;
using json::Value;

constexpr double kFloatMax = 3.4e38;      // Parameter.min_value / max_value defaults
constexpr double kIntLimit = 16777216.0;  // ints are held as floats: exact up to 2^24
inline const std::vector<std::string_view> kNodeKinds = {
    "clip", "blend",       "select", "layered",        "blend_space", "additive", "state_machine", "morph",
    "use",  "two_bone_ik", "aim",    "foot_placement", "foot_lock",   "spring",   "slot",          "retarget"};
constexpr double kDegrees = 3.14159265358979323846 / 180.0;
// The loader's bounds (runtime/loader/validate_graph.cpp). A value past one compiled into a file
// that failed verification ("internal error, cooked bytes fail verification"): each is refused
// here instead, where the file writes it.
constexpr double kMaxRate = 1000.0, kMaxWeight = 100.0, kMaxSeconds = 1e6, kMaxCoordinate = 1e6;
constexpr size_t kMaxBlendSamples = 1024;

std::string a_type(ParamType t);
std::string quoted(const std::vector<std::string>& names);
std::string number_text(double v);
void read_manifest(Checker& check, const Value& root, GraphManifest& out);

class GraphCompiler {
 public:
  GraphCompiler(const json::Document& doc, const GraphContext& context) : check_(doc), ctx_(context) {}
  GraphCompiler(const GraphCompiler&) = delete;  // montage_ points into this object

  Result<CompiledGraph> run() {
    const Value& root = check_.doc().root;
    GraphManifest manifest;
    read_manifest(check_, root, manifest);
    if (!root.is(Type::Object)) return Error{check_.message()};
    g_.name = manifest.name;
    read_skeleton();
    read_clips(root, manifest);
    read_parameters(root.find("parameters"));
    read_named_nodes(root.find("nodes"));

    const Value* root_node = root.find("root");
    int index = -1;
    if (!root_node) check_.error(root.pos, "a graph needs a \"root\" node");
    else index = node(*root_node, "");
    if (index >= 0) g_.root = static_cast<uint16_t>(index);
    montage_.montages(root.find("montages"));  // after the root: tracks name its slots
    montage_.check_slot_placement();
    check_unused();
    if (!check_.ok()) return Error{check_.message()};

    CompiledGraph out;
    out.graph = std::move(g_);
    out.clip_events = std::move(clip_events_);
    out.warnings = std::move(warnings_);
    return out;
  }

 private:
  Checker check_;
  const GraphContext& ctx_;
  GraphDef g_;
  std::vector<std::vector<SourceEvent>> clip_events_;
  std::vector<float> clip_duration_;
  std::vector<bool> clip_used_;
  std::vector<Pos> clip_pos_;
  std::vector<bool> param_bad_;  // a parameter already reported: its uses are not checked again
  std::vector<std::string> warnings_;

  struct Named {
    const Member* member = nullptr;
    size_t uses = 0;
    bool checked = false;  // its node has been compiled once (the unused pass needs it no more)
  };
  std::vector<Named> named_;
  // Name lookups by hash: a file can declare tens of thousands of each, and every reference
  // looked up by a scan made the checks quadratic in the file's size.
  std::unordered_map<std::string_view, size_t> named_index_;
  std::unordered_map<std::string_view, int> param_index_, clip_index_, joint_index_;
  std::unordered_map<std::string_view, int> retarget_clip_index_;  // clips of other rigs, by name
  std::map<std::pair<std::string, std::string>, Result<GraphRetargetRigs>> retarget_rigs_;  // by rig and map file
  std::vector<std::string> use_stack_;
  size_t visits_ = 0;
  bool too_many_ = false;
  bool checking_unused_ = false;  // the node limit then only bounds the work, it is no error
  uint32_t depth_ = 0;            // node() frames on the path, uses included (bounds the recursion)
  uint32_t output_depth_ = 0;     // nodes on the path that are written (uses excluded)
  MontageCompiler montage_{check_,
                           g_,
                           clip_duration_,
                           [this](const Value& v, const std::string& role) { return clip(v, role); },
                           [this](const Value& v, const std::string& role) { return joint(v, role); },
                           [this](const Value& v, const std::string& name) { return node(v, name); },
                           {},
                           true};

  void warn(Pos pos, const std::string& what);

  // ---- small readers -----------------------------------------------------------------------

  bool read_float(const Value& v, const std::string& what, float* out, double lo = -kFloatMax, double hi = kFloatMax);

  bool read_bool(const Value& v, const std::string& what, bool* out);

  /// A parameter named by the string v, of one of the allowed types; -1 (reported) otherwise.
  int parameter(const Value& v, std::initializer_list<ParamType> allowed, const std::string& role);

  /// A clip named by the string v; -1 (reported) otherwise.
  int clip(const Value& v, const std::string& role);

  /// A required member; reports its absence.
  const Value* required(const Value& object, std::string_view key, const std::string& what);

  // ---- top level ---------------------------------------------------------------------------

  void read_skeleton();

  void read_clips(const Value& root, const GraphManifest& manifest);

  void read_parameters(const Value* params);

  bool read_parameter(const Member& m, GraphParameter& p);

  void read_named_nodes(const Value* nodes);

  /// Named nodes no "use" reached and declared clips no node plays are warnings; the former are
  /// still compiled (and thrown away) so their problems are reported.
  void check_unused();

  // ---- nodes ---------------------------------------------------------------------------------

  int emit(std::string name, NodeKind kind);

  /// Compiles the node written at v (and its subtree) and returns its index, or -1.
  int node(const Value& v, const std::string& default_name);

  int use_node(const Value& v, const std::string& name, bool named_here);

  int clip_node(const Value& v, const std::string& name);

  int blend_node(const Value& v, const std::string& name);

  int select_node(const Value& v, const std::string& name);

  int joint(const Value& v, const std::string& role = "a mask");

  int layered_node(const Value& v, const std::string& name);

  int blend_space_node(const Value& v, const std::string& name);

  int additive_node(const Value& v, const std::string& name);

  /// {"morph": INPUT, "drives": [{"target": "smile", "parameter": "happy", "scale": 1}, ...]}
  int morph_node(const Value& v, const std::string& name);

  // ---- procedural nodes (format v6) ----------------------------------------------------------
  // Lengths in the graph file are metres (converted to the rig's units), angles degrees.

  /// Rig units per metre (the rig's unit unknown: 1).
  double units() const;

  bool read_vec3(const Value& v, const std::string& what, double scale, Vec3Def* out);
  /// A length in metres, >= lo, stored in rig units.
  bool read_length(const Value& v, const std::string& what, float* out, double lo = 0.0);
  bool read_degrees(const Value& v, const std::string& what, float* out, double lo, double hi);
  /// "weight" in [0, 1] and "weight_parameter" (float or bool).
  bool read_weight(const Value& v, float* weight, int16_t* weight_parameter);
  /// A required joint member; -1 reported.
  int joint_member(const Value& v, std::string_view key, const std::string& what);
  /// Joint j's model-space rotation at the bind pose.
  glm::quat bind_rotation(uint32_t j) const;
  /// Whether joint a is a strict ancestor of b.
  bool ancestor(int a, int b) const;
  bool check_chain(const Value& at, std::initializer_list<int> joints, const std::string& what);

  /// {"two_bone_ik": INPUT, "start": J, "mid": J, "end": J, "target": VECTOR, "pole": VECTOR | [x, y, z],
  ///  "mid_axis": [x, y, z], "twist": degrees, "soften": (0, 1], "weight", "weight_parameter"}
  int two_bone_node(const Value& v, const std::string& name);

  /// {"aim": INPUT, "chain": [{"joint": J, "weight": w, "max_angle": degrees}, ...] (base first),
  ///  "target": VECTOR, "forward": [x, y, z], "up": [x, y, z], "pole": [x, y, z], "weight", "weight_parameter"}
  int aim_node(const Value& v, const std::string& name);

  bool read_legs(const Value& v, bool lock, std::vector<FootLegDef>* out);

  /// {"foot_placement": INPUT, "pelvis": J, "legs": [{"hip", "knee", "ankle", "ground": FLOAT, "normal": VECTOR}],
  ///  "up": [x, y, z], "max_pelvis_drop": metres, "align": [0, 1], "soften", "weight", "weight_parameter"}
  /// {"foot_lock": INPUT, "legs": [{"hip", "knee", "ankle", "planted": FLOAT|BOOL, "plant_event", "lift_event"}],
  ///  "release_radius": metres, "blend_time": seconds, "weight", "weight_parameter"}
  int foot_node(const Value& v, const std::string& name, bool lock);

  /// {"spring": INPUT, "chains": [{"joints": [J, ...] (parent first), "stiffness", "drag", "gravity": [x, y, z] m/s^2,
  ///  "radius": metres, "tail_length": metres}], "colliders": [{"joint": J, "offset": [..] m, "tail": [..] m,
  ///  "radius": m}], "step": seconds, "teleport_distance": metres, "weight", "weight_parameter"}
  int spring_node(const Value& v, const std::string& name);

  // ---- retarget (format v10) -------------------------------------------------------------------

  /// {"retarget": CLIP, "rig": "source rig (.ossa or a source file)", "map": "map.json", "rate",
  ///  "rate_parameter", "loop", "start", "contacts"}: a clip of another humanoid rig, not imported: the
  /// runtime finds it by name among the clip files it is given, bound to that rig (docs/RETARGET.md).
  int retarget_node(const Value& v, const std::string& name);

  // ---- state machines ------------------------------------------------------------------------

  int machine_node(const Value& v, const std::string& name);

  template <class StateIndex, class UnknownState>
  bool transition(const Value& t, const StateIndex& state_index, const UnknownState& unknown_state, TransitionDef& out,
                  long long& priority);
};

}  // namespace ossa::cook::graph_detail
