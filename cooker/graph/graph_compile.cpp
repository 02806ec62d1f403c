// graph_compile.cpp — graph JSON -> GraphDef (graph_compile.h; the format is docs/GRAPH.md).
//
// One pass over the document with a Checker collecting every problem. A function that reads a
// part returns what it built or a "failed" mark (-1 for an index); its parent then emits nothing
// but still reads its other parts, so their problems are reported too. Since any problem fails
// the whole compile, a partly built GraphDef is never returned.
#include "cooker/graph/graph_compile.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>
#include <unordered_set>

#include "cooker/clip/clip_events.h"
#include "cooker/graph/graph_condition.h"
#include "cooker/graph/graph_montage.h"
#include "cooker/json/json_check.h"
#include <ossa/anim/blend_space.h>
#include <ossa/loader/validate.h>

namespace ossa::cook {
namespace {

using json::Checker;
using json::Member;
using json::Pos;
using json::Type;
using json::Value;

constexpr double kFloatMax = 3.4e38;      // Parameter.min_value / max_value defaults
constexpr double kIntLimit = 16777216.0;  // ints are held as floats: exact up to 2^24
const std::vector<std::string_view> kNodeKinds = {
    "clip",  "blend",      "select",         "layered",   "blend_space", "additive", "state_machine", "morph",
    "use",   "two_bone_ik", "aim",           "foot_placement", "foot_lock", "spring", "slot"};
constexpr double kDegrees = 3.14159265358979323846 / 180.0;
// The loader's bounds (runtime/loader/validate_graph.cpp). A value past one compiled into a file
// that failed verification ("internal error, cooked bytes fail verification"): each is refused
// here instead, where the file writes it.
constexpr double kMaxRate = 1000.0, kMaxWeight = 100.0, kMaxSeconds = 1e6, kMaxCoordinate = 1e6;
constexpr size_t kMaxBlendSamples = 1024;

std::string a_type(ParamType t) {
  return (t == ParamType::Int || t == ParamType::Enum ? "an " : "a ") + std::string(type_word(t));
}

/// "'a', 'b', 'c'": the names a message lists, at most 20 (then "... (N in all)"): a file can
/// declare tens of thousands, and a message per mistake must not list them all.
std::string quoted(const std::vector<std::string>& names) {
  constexpr size_t kListed = 20;
  std::string out;
  for (size_t i = 0; i < names.size() && i < kListed; ++i) out += (out.empty() ? "'" : ", '") + names[i] + "'";
  if (names.size() > kListed) out += ", ... (" + std::to_string(names.size()) + " in all)";
  return out;
}

std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

/// The shape of the top level and the import entries (shared by read_graph_manifest and
/// compile_graph, so both report the same problems).
void read_manifest(Checker& check, const Value& root, GraphManifest& out) {
  if (!check.expect(root, Type::Object, "a graph file")) return;
  check.expect_keys(root, {"ossa_graph", "name", "skeleton", "meshes", "clips", "parameters", "nodes", "root",
                           "montages"},
                    "a graph file");
  const Value* version = root.find("ossa_graph");
  if (!version) {
    check.error(root.pos, "not a graph file: \"ossa_graph\": 1 is missing");
  } else if (!version->is(Type::Number) || version->number != 1.0) {
    check.error(version->pos, "\"ossa_graph\" must be 1 (the only version this cooker reads)");
  }
  if (const Value* name = root.find("name")) check.expect_name(*name, "\"name\"", &out.name);
  else check.error(root.pos, "a graph needs a \"name\" (what a game asks the file for)");

  if (const Value* skeleton = root.find("skeleton")) {
    out.skeleton_pos = skeleton->pos;
    if (skeleton->is(Type::Object)) {
      // {"source": "rig.fbx", "meshes": false}: the rig without the meshes its source carries.
      check.expect_keys(*skeleton, {"source", "meshes"}, "\"skeleton\"");
      if (const Value* source = skeleton->find("source"))
        check.expect_name(*source, "\"skeleton\" \"source\" (the rig's source file)", &out.skeleton);
      else
        check.error(skeleton->pos, "\"skeleton\" needs a \"source\": the rig's source file");
      if (const Value* meshes = skeleton->find("meshes"); meshes && check.expect(*meshes, Type::Bool, "\"meshes\""))
        out.skeleton_meshes = meshes->boolean;
    } else {
      check.expect_name(*skeleton, "\"skeleton\" (the rig's source file)", &out.skeleton);
    }
  } else {
    check.error(root.pos, "a graph needs a \"skeleton\": the source file of its rig, relative to the graph file");
  }
  if (const Value* meshes = root.find("meshes"); meshes && check.expect(*meshes, Type::Array, "\"meshes\"")) {
    for (const Value& m : meshes->items) {
      std::string path;
      if (!check.expect_name(m, "a \"meshes\" entry (a source file)", &path)) continue;
      out.meshes.push_back(std::move(path));
      out.mesh_pos.push_back(m.pos);
    }
  }

  const Value* clips = root.find("clips");
  if (!clips) {
    check.error(root.pos, "a graph needs \"clips\": {\"<clip name>\": \"<source file>\", ...}");
    return;
  }
  if (!check.expect(*clips, Type::Object, "\"clips\"")) return;
  if (clips->members.size() > kMaxGraphClips)
    check.error(clips->pos, "more than " + std::to_string(kMaxGraphClips) + " clips");
  for (const Member& m : clips->members) {
    GraphClipSource c;
    c.name = m.key;
    c.pos = m.value.pos;
    if (m.key.empty()) check.error(m.key_pos, "a clip name must not be empty");
    if (m.value.is(Type::String)) {
      check.expect_name(m.value, "clip '" + m.key + "' (its source file)", &c.source);
    } else if (check.expect(m.value, Type::Object, "clip '" + m.key + "' (a source file, or {\"source\": ...})")) {
      check.expect_keys(m.value, {"source", "clip", "events"}, "clip '" + m.key + "'");
      if (const Value* source = m.value.find("source")) check.expect_name(*source, "\"source\"", &c.source);
      else check.error(m.value.pos, "clip '" + m.key + "' needs a \"source\" file");
      if (const Value* pick = m.value.find("clip"))
        check.expect_name(*pick, "\"clip\" (a clip name in the source)", &c.source_clip);
      if (const Value* events = m.value.find("events")) check.expect(*events, Type::Array, "\"events\"");
    }
    out.clips.push_back(std::move(c));
  }
}

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
  std::vector<std::string> use_stack_;
  size_t visits_ = 0;
  bool too_many_ = false;
  bool checking_unused_ = false;  // the node limit then only bounds the work, it is no error
  uint32_t depth_ = 0;            // node() frames on the path, uses included (bounds the recursion)
  uint32_t output_depth_ = 0;     // nodes on the path that are written (uses excluded)
  MontageCompiler montage_{check_, g_, clip_duration_,
                           [this](const Value& v, const std::string& role) { return clip(v, role); },
                           [this](const Value& v, const std::string& role) { return joint(v, role); },
                           [this](const Value& v, const std::string& name) { return node(v, name); },
                           {},
                           true};

  void warn(Pos pos, const std::string& what) { warnings_.push_back(json::where(check_.doc().file, pos) + what); }

  // ---- small readers -----------------------------------------------------------------------

  bool read_float(const Value& v, const std::string& what, float* out, double lo = -kFloatMax, double hi = kFloatMax) {
    double d = 0.0;
    if (!check_.expect_number(v, what, &d)) return false;
    if (d < lo || d > hi) {
      // Below 0 where the upper bound is none, or 1e6 s (no real time nears it): name the lower only.
      if (d < lo && lo > -kFloatMax && (hi >= kFloatMax || (lo == 0.0 && hi == kMaxSeconds)))
        return check_.error(v.pos, what + " must be >= " + number_text(lo) + ", not " + number_text(d));
      return check_.error(
          v.pos, what + " must be within [" + number_text(lo) + ", " + number_text(hi) + "], not " + number_text(d));
    }
    *out = static_cast<float>(d);
    return true;
  }

  bool read_bool(const Value& v, const std::string& what, bool* out) {
    if (!check_.expect(v, Type::Bool, what)) return false;
    *out = v.boolean;
    return true;
  }

  /// A parameter named by the string v, of one of the allowed types; -1 (reported) otherwise.
  int parameter(const Value& v, std::initializer_list<ParamType> allowed, const std::string& role) {
    if (!check_.expect(v, Type::String, role + " (a parameter name)")) return -1;
    const auto found = param_index_.find(v.string);
    const int index = found == param_index_.end() ? -1 : found->second;
    if (index < 0) {
      if (check_.full()) return check_.error(v.pos, "unknown parameter '" + v.string + "' in " + role), -1;
      std::vector<std::string> names;
      for (const GraphParameter& p : g_.parameters) names.push_back(p.name);
      const std::string hint = json::closest_name(v.string, names);
      check_.error(v.pos,
                   "unknown parameter '" + v.string + "' in " + role +
                       (hint.empty() ? "" : " (did you mean '" + hint + "'?)") +
                       (names.empty() ? "; the graph declares no \"parameters\"" : "; parameters: " + quoted(names)));
      return -1;
    }
    if (param_bad_[static_cast<size_t>(index)]) return -1;
    const ParamType type = g_.parameters[static_cast<size_t>(index)].type;
    if (std::find(allowed.begin(), allowed.end(), type) != allowed.end()) return index;
    std::string want;  // "float", "float or bool", "bool, int or enum"
    size_t listed = 0;
    for (ParamType t : allowed) {
      if (listed > 0) want += listed + 1 == allowed.size() ? " or " : ", ";
      want += type_word(t);
      ++listed;
    }
    check_.error(v.pos, "parameter '" + v.string + "' is " + a_type(type) + "; " + role + " needs " +
                            (*allowed.begin() == ParamType::Int || *allowed.begin() == ParamType::Enum ? "an " : "a ") +
                            want + " parameter");
    return -1;
  }

  /// A clip named by the string v; -1 (reported) otherwise.
  int clip(const Value& v, const std::string& role) {
    if (!check_.expect(v, Type::String, role + " (a clip name)")) return -1;
    if (const auto found = clip_index_.find(v.string); found != clip_index_.end()) {
      clip_used_[static_cast<size_t>(found->second)] = true;
      return found->second;
    }
    if (check_.full()) return check_.error(v.pos, "unknown clip '" + v.string + "'"), -1;
    const std::string hint = json::closest_name(v.string, g_.clips);
    check_.error(v.pos, "unknown clip '" + v.string + "'" + (hint.empty() ? "" : " (did you mean '" + hint + "'?)") +
                            (g_.clips.empty() ? "; \"clips\" declares none" : "; clips: " + quoted(g_.clips)));
    return -1;
  }

  /// A required member; reports its absence.
  const Value* required(const Value& object, std::string_view key, const std::string& what) {
    const Value* v = object.find(key);
    if (!v) check_.error(object.pos, what + " needs \"" + std::string(key) + "\"");
    return v;
  }

  // ---- top level ---------------------------------------------------------------------------

  void read_skeleton() {
    const SourceSkeleton* sk = ctx_.skeleton;
    if (!sk || sk->joints.empty()) {
      check_.error(check_.doc().root.pos, "the graph's skeleton has no joints");
      return;
    }
    if (sk->joints.size() > 65535) {
      check_.error(check_.doc().root.pos, "the skeleton has more than 65535 joints");
      return;
    }
    g_.skeleton_hash = skeleton_hash_of(*sk);
    g_.joint_count = static_cast<uint16_t>(sk->joints.size());
  }

  void read_clips(const Value& root, const GraphManifest& manifest) {
    const Value* clips = root.find("clips");
    std::unordered_map<std::string_view, const GraphClipInfo*> imported;
    for (const GraphClipInfo& c : ctx_.clips) imported[c.name] = &c;  // the last of a name, as a scan found it
    std::unordered_map<std::string_view, const Value*> written;
    if (clips && clips->is(Type::Object))
      for (const Member& m : clips->members) written.emplace(m.key, &m.value);
    for (const GraphClipSource& entry : manifest.clips) {
      g_.clips.push_back(entry.name);
      clip_used_.push_back(false);
      clip_pos_.push_back(entry.pos);
      const auto found = imported.find(entry.name);
      const GraphClipInfo* info = found == imported.end() ? nullptr : found->second;
      std::vector<SourceEvent> events;
      float duration = 0.0f;
      if (!info) {
        check_.error(entry.pos, "clip '" + entry.name + "' was not imported");
      } else {
        duration = info->duration;
        events = info->events;
        const auto w = written.find(entry.name);
        const Value* value = w == written.end() ? nullptr : w->second;
        const Value* list = value && value->is(Type::Object) ? value->find("events") : nullptr;
        if (list && list->is(Type::Array))
          read_event_list(check_, *list, duration, "clip '" + entry.name + "'", events);
        sort_events(events);
      }
      clip_events_.push_back(std::move(events));
      clip_duration_.push_back(duration);
    }
    for (size_t c = 0; c < g_.clips.size(); ++c) clip_index_.emplace(g_.clips[c], static_cast<int>(c));
  }

  void read_parameters(const Value* params) {
    if (!params || !check_.expect(*params, Type::Object, "\"parameters\"")) return;
    if (params->members.size() > kMaxGraphParameters)
      check_.error(params->pos, "more than " + std::to_string(kMaxGraphParameters) + " parameters");
    for (const Member& m : params->members) {
      GraphParameter p;
      p.name = m.key;
      const bool ok = read_parameter(m, p);
      g_.parameters.push_back(std::move(p));
      param_bad_.push_back(!ok);
    }
    for (size_t p = 0; p < g_.parameters.size(); ++p) param_index_.emplace(g_.parameters[p].name, static_cast<int>(p));
  }

  bool read_parameter(const Member& m, GraphParameter& p) {
    const std::string what = "parameter '" + m.key + "'";
    bool ok = true;
    if (!is_condition_identifier(m.key))
      ok = check_.error(m.key_pos, "parameter name '" + m.key +
                                       "' must be an identifier (letters, digits and '_', not starting with a digit, "
                                       "not true/false/and/or/not) so conditions can name it");
    const Value& v = m.value;
    if (!check_.expect(v, Type::Object, what)) return false;
    const Value* type = v.find("type");
    static const std::vector<std::string_view> kTypes = {"float", "int", "bool", "enum", "trigger", "vector"};
    if (!type) return check_.error(v.pos, what + " needs a \"type\": float, int, bool, enum, trigger or vector");
    if (!check_.expect(*type, Type::String, "\"type\"")) return false;
    const auto found = std::find(kTypes.begin(), kTypes.end(), type->string);
    if (found == kTypes.end()) {
      const std::string hint = json::closest_name(type->string, kTypes);
      return check_.error(type->pos, "unknown parameter type '" + type->string + "'" +
                                         (hint.empty() ? "" : " (did you mean '" + hint + "'?)") +
                                         "; types: float, int, bool, enum, trigger, vector");
    }
    p.type = static_cast<ParamType>(found - kTypes.begin());
    const Value* def = v.find("default");
    switch (p.type) {
      case ParamType::Float:
      case ParamType::Int: {
        const bool is_int = p.type == ParamType::Int;
        ok &= check_.expect_keys(v, {"type", "default", "min", "max"}, what);
        double lo = -kFloatMax, hi = kFloatMax, d = 0.0;
        const double limit = is_int ? kIntLimit : kFloatMax;
        const auto read = [&](const char* key, double* out) {
          const Value* x = v.find(key);
          if (!x) return true;
          if (!check_.expect_number(*x, what + " \"" + key + "\"", out)) return false;
          if (is_int && *out != std::floor(*out))
            return check_.error(x->pos, what + " \"" + key + "\" must be a whole number");
          if (std::abs(*out) > limit)
            return check_.error(x->pos, what + " \"" + key + "\" must be within +-" + number_text(limit));
          return true;
        };
        const bool min_ok = read("min", &lo);
        const bool max_ok = read("max", &hi);
        const bool have_range = min_ok && max_ok;
        ok &= have_range;
        if (have_range && lo > hi) {
          ok = check_.error(v.find("min")->pos,
                            what + ": min " + number_text(lo) + " is greater than max " + number_text(hi));
        } else if (have_range) {
          d = std::clamp(0.0, lo, hi);  // no default: 0, or the range's nearest end
          if (def && !read("default", &d)) {
            ok = false;
          } else if (def && (d < lo || d > hi)) {
            ok = check_.error(def->pos, what + ": default " + number_text(d) + " is outside [min, max] = [" +
                                            number_text(lo) + ", " + number_text(hi) + "]");
          }
        }
        p.min_value = static_cast<float>(lo);
        p.max_value = static_cast<float>(hi);
        p.default_value = static_cast<float>(d);
        return ok;
      }
      case ParamType::Bool:
        ok &= check_.expect_keys(v, {"type", "default"}, what);
        if (def) {
          bool b = false;
          ok &= read_bool(*def, what + " \"default\"", &b);
          p.default_value = b ? 1.0f : 0.0f;
        }
        return ok;
      case ParamType::Trigger: return check_.expect_keys(v, {"type"}, what) && ok;
      case ParamType::Vector: {
        // A point's default is in metres (converted to the rig's units); a direction's is unitless.
        ok &= check_.expect_keys(v, {"type", "default", "space", "direction"}, what);
        bool direction = false;
        if (const Value* dir = v.find("direction")) ok &= read_bool(*dir, what + " \"direction\"", &direction);
        Vec3Def d{0.0f, 0.0f, 0.0f};
        if (def) ok &= read_vec3(*def, what + (direction ? " \"default\"" : " \"default\" (metres)"), direction ? 1.0 : units(), &d);
        std::copy(d.begin(), d.end(), p.default_vector);
        if (const Value* space = v.find("space")) {
          if (!check_.expect(*space, Type::String, what + " \"space\"")) return false;
          if (space->string != "model" && space->string != "world")
            return check_.error(space->pos, what + " \"space\" is '" + space->string + "'; spaces: model, world");
          p.world = space->string == "world";
        }
        return ok;
      }
      case ParamType::Enum: {
        ok &= check_.expect_keys(v, {"type", "values", "default"}, what);
        const Value* values = v.find("values");
        if (!values) return check_.error(v.pos, what + " needs \"values\": [\"<name>\", ...]");
        if (!check_.expect(*values, Type::Array, what + " \"values\"")) return false;
        if (values->items.empty()) return check_.error(values->pos, what + " needs at least one value");
        if (values->items.size() > 65535) return check_.error(values->pos, what + " has more than 65535 values");
        std::unordered_set<std::string_view> seen;
        for (const Value& name : values->items) {
          if (!check_.expect(name, Type::String, "an enum value")) {
            ok = false;
            continue;
          }
          if (!is_condition_identifier(name.string)) {
            ok = check_.error(name.pos, "enum value '" + name.string +
                                            "' must be an identifier (letters, digits and '_', not starting with a "
                                            "digit, not true/false/and/or/not) so conditions can name it");
          } else if (!seen.insert(name.string).second) {
            ok = check_.error(name.pos, what + ": value '" + name.string + "' is listed twice");
          }
          p.enum_values.push_back(name.string);
        }
        if (def && check_.expect(*def, Type::String, what + " \"default\" (one of its values)")) {
          const auto at = std::find(p.enum_values.begin(), p.enum_values.end(), def->string);
          if (at == p.enum_values.end())
            ok = check_.error(def->pos, what + ": default '" + def->string + "' is not one of its values (" +
                                            quoted(p.enum_values) + ")");
          else p.default_value = static_cast<float>(at - p.enum_values.begin());
        } else if (def) {
          ok = false;
        }
        return ok;
      }
    }
    return false;
  }

  void read_named_nodes(const Value* nodes) {
    if (!nodes || !check_.expect(*nodes, Type::Object, "\"nodes\" (named nodes)")) return;
    for (const Member& m : nodes->members) {
      if (m.key.empty()) check_.error(m.key_pos, "a named node's name must not be empty");
      named_index_.emplace(m.key, named_.size());
      named_.push_back({&m, 0});
    }
  }

  /// Named nodes no "use" reached and declared clips no node plays are warnings; the former are
  /// still compiled (and thrown away) so their problems are reported.
  void check_unused() {
    for (Named& n : named_) {
      if (n.uses > 0) continue;
      warn(n.member->key_pos, "named node '" + n.member->key + "' is never used");
      // Compiled once already, inside another unused node's expansion: its problems are known.
      if (n.checked) continue;
      const size_t nodes = g_.nodes.size(), machines = g_.machines.size();
      visits_ = 0;
      too_many_ = false;
      checking_unused_ = true;
      montage_.collecting = false;
      use_stack_ = {n.member->key};
      ++n.uses;
      (void)node(n.member->value, n.member->key);
      n.checked = true;
      use_stack_.clear();
      g_.nodes.resize(nodes);
      g_.machines.resize(machines);
    }
    checking_unused_ = false;
    for (size_t c = 0; c < clip_used_.size(); ++c)
      if (!clip_used_[c]) warn(clip_pos_[c], "clip '" + g_.clips[c] + "' is declared but no node plays it");
  }

  // ---- nodes ---------------------------------------------------------------------------------

  int emit(std::string name, NodeKind kind) {
    g_.nodes.push_back({std::move(name), std::move(kind)});
    return static_cast<int>(g_.nodes.size() - 1);
  }

  /// Compiles the node written at v (and its subtree) and returns its index, or -1.
  int node(const Value& v, const std::string& default_name) {
    if (too_many_) return -1;
    if (!check_.expect(v, Type::Object, "a node")) return -1;
    const Member* kind = nullptr;
    for (const Member& m : v.members) {
      if (std::find(kNodeKinds.begin(), kNodeKinds.end(), m.key) == kNodeKinds.end()) continue;
      if (kind) {
        check_.error(m.key_pos,
                     "a node is exactly one kind, but this one has both \"" + kind->key + "\" and \"" + m.key + "\"");
        return -1;
      }
      kind = &m;
    }
    if (!kind) {
      if (check_.expect_keys(
              v, {"clip", "blend", "select", "layered", "blend_space", "additive", "state_machine", "morph", "use",
                  "two_bone_ik", "aim", "foot_placement", "foot_lock", "spring", "slot", "name"},
              "a node"))
        check_.error(v.pos,
                     "a node needs one of the keys clip, blend, select, layered, blend_space, additive, "
                     "state_machine, morph, two_bone_ik, aim, foot_placement, foot_lock, spring, slot, use");
      return -1;
    }
    // Every node but a use (which stands for the node it copies) becomes one output node.
    if (kind->key != "use" && ++visits_ > kMaxGraphNodes) {
      too_many_ = true;
      if (!checking_unused_)
        check_.error(v.pos, "the graph has more than " + std::to_string(kMaxGraphNodes) +
                                " nodes (each {\"use\"} of a named node is a copy of it)");
      return -1;
    }
    if (depth_ >= kMaxNodeDepth) {
      check_.error(v.pos, "nodes nested deeper than " + std::to_string(kMaxNodeDepth) + " levels");
      return -1;
    }
    // The loader's limit counts the nodes written (a use is the node it copies): a path of more
    // than kMaxGraphDepth + 1 of them.
    const bool output = kind->key != "use";
    if (output && output_depth_ > kMaxGraphDepth) {
      check_.error(v.pos,
                   "nodes nested deeper than " + std::to_string(kMaxGraphDepth) +
                       " levels below the root (the runtime's limit; each {\"use\"} counts as the node it copies)");
      return -1;
    }
    std::string name = default_name;
    if (const Value* n = v.find("name")) {
      if (!check_.expect(*n, Type::String, "a node's \"name\"")) return -1;
      name = n->string;
    }
    ++depth_;
    output_depth_ += output ? 1 : 0;
    int index = -1;
    const std::string& k = kind->key;
    if (k == "clip") index = clip_node(v, name);
    else if (k == "blend") index = blend_node(v, name);
    else if (k == "select") index = select_node(v, name);
    else if (k == "layered") index = layered_node(v, name);
    else if (k == "blend_space") index = blend_space_node(v, name);
    else if (k == "additive") index = additive_node(v, name);
    else if (k == "state_machine") index = machine_node(v, name);
    else if (k == "morph") index = morph_node(v, name);
    else if (k == "two_bone_ik") index = two_bone_node(v, name);
    else if (k == "aim") index = aim_node(v, name);
    else if (k == "foot_placement") index = foot_node(v, name, false);
    else if (k == "foot_lock") index = foot_node(v, name, true);
    else if (k == "spring") index = spring_node(v, name);
    else if (k == "slot") index = montage_.slot_node(v, name);
    else index = use_node(v, name, v.find("name") != nullptr);
    --depth_;
    output_depth_ -= output ? 1 : 0;
    return index;
  }

  int use_node(const Value& v, const std::string& name, bool named_here) {
    check_.expect_keys(v, {"use", "name"}, "a use");
    const Value& target = *v.find("use");
    if (!check_.expect(target, Type::String, "\"use\" (a named node)")) return -1;
    const auto at = named_index_.find(target.string);
    Named* found = at == named_index_.end() ? nullptr : &named_[at->second];
    if (!found) {
      if (check_.full()) return check_.error(target.pos, "unknown named node '" + target.string + "'"), -1;
      std::vector<std::string> names;
      for (const Named& n : named_) names.push_back(n.member->key);
      const std::string hint = json::closest_name(target.string, names);
      return check_.error(target.pos,
                          "unknown named node '" + target.string + "'" +
                              (hint.empty() ? "" : " (did you mean '" + hint + "'?)") +
                              (names.empty() ? "; the graph has no \"nodes\"" : "; named nodes: " + quoted(names))),
             -1;
    }
    if (std::find(use_stack_.begin(), use_stack_.end(), target.string) != use_stack_.end()) {
      std::string chain;
      for (auto it = std::find(use_stack_.begin(), use_stack_.end(), target.string); it != use_stack_.end(); ++it)
        chain += *it + " -> ";
      check_.error(target.pos, "named nodes use each other in a cycle: " + chain + target.string);
      return -1;
    }
    ++found->uses;
    // While unused nodes are checked, a named node compiled once is not expanded again: its
    // problems are known, and re-expanding every use made a chain of them quadratic. (The output
    // of that pass is thrown away; any valid index does.)
    if (checking_unused_ && found->checked) return 0;
    use_stack_.push_back(target.string);
    const bool enters = !too_many_ && depth_ < kMaxNodeDepth;  // node() compiles its body
    const int index = node(found->member->value, named_here ? name : target.string);
    use_stack_.pop_back();
    if (enters && !too_many_) found->checked = true;
    return index;
  }

  int clip_node(const Value& v, const std::string& name) {
    check_.expect_keys(v, {"clip", "rate", "rate_parameter", "loop", "start", "name"}, "a clip node");
    ClipNodeDef c;
    bool ok = true;
    const int index = clip(*v.find("clip"), "a clip node");
    ok &= index >= 0;
    if (const Value* r = v.find("rate")) ok &= read_float(*r, "\"rate\"", &c.rate, -kMaxRate, kMaxRate);
    if (const Value* p = v.find("rate_parameter")) {
      const int param = parameter(*p, {ParamType::Float}, "\"rate_parameter\"");
      ok &= param >= 0;
      c.rate_parameter = static_cast<int16_t>(param);
    }
    if (const Value* l = v.find("loop")) ok &= read_bool(*l, "\"loop\"", &c.loop);
    if (const Value* s = v.find("start"); s && index >= 0) {
      const double duration = clip_duration_[static_cast<size_t>(index)];
      double t = 0.0;
      if (!check_.expect_number(*s, "\"start\" (seconds)", &t)) {
        ok = false;
      } else if (t < 0.0 || t > duration + kEventTimeSlack) {
        ok = check_.error(s->pos, "\"start\" " + number_text(t) + " s is outside clip '" +
                                      g_.clips[static_cast<size_t>(index)] + "' [0, " + number_text(duration) + " s]");
      } else {
        c.start_offset = static_cast<float>(std::min(t, duration));
      }
    }
    if (!ok) return -1;
    c.clip = static_cast<uint16_t>(index);
    return emit(name, c);
  }

  int blend_node(const Value& v, const std::string& name) {
    check_.expect_keys(v, {"blend", "alpha", "name"}, "a blend node");
    BlendAlphaDef b;
    const Value& inputs = *v.find("blend");
    bool ok = true;
    int alpha = -1;
    if (const Value* a = required(v, "alpha", "a blend node"))
      alpha = parameter(*a, {ParamType::Float}, "a blend's \"alpha\"");
    ok &= alpha >= 0;
    if (!check_.expect(inputs, Type::Array, "\"blend\" ([A, B])")) return -1;
    if (inputs.items.size() != 2) {
      check_.error(inputs.pos, "\"blend\" takes exactly 2 nodes [A, B], not " + std::to_string(inputs.items.size()));
      ok = false;
    }
    std::vector<int> children;
    for (const Value& child : inputs.items) children.push_back(node(child, ""));
    for (int c : children) ok &= c >= 0;
    if (!ok) return -1;
    b.a = static_cast<uint16_t>(children[0]);
    b.b = static_cast<uint16_t>(children[1]);
    b.alpha_parameter = static_cast<uint16_t>(alpha);
    return emit(name, b);
  }

  int select_node(const Value& v, const std::string& name) {
    check_.expect_keys(v, {"select", "children", "blend_time", "name"}, "a select node");
    SelectDef s;
    bool ok = true;
    const int param = parameter(*v.find("select"), {ParamType::Bool, ParamType::Int, ParamType::Enum}, "a select node");
    ok &= param >= 0;
    if (const Value* t = v.find("blend_time")) ok &= read_float(*t, "\"blend_time\"", &s.blend_time, 0.0, kMaxSeconds);
    const Value* children = required(v, "children", "a select node");
    if (!children) return -1;
    if (!children->is(Type::Array) && !children->is(Type::Object)) {
      check_.expect(*children, Type::Array, "\"children\"");
      return -1;
    }
    if (param < 0) {  // still report the children's problems
      for (const Value& c : children->items) node(c, "");
      for (const Member& m : children->members) node(m.value, "");
      return -1;
    }
    const GraphParameter& p = g_.parameters[static_cast<size_t>(param)];
    std::vector<std::string> labels;  // the value names, when the parameter has them
    if (p.type == ParamType::Bool) labels = {"false", "true"};
    if (p.type == ParamType::Enum) labels = p.enum_values;

    std::vector<int> out;
    if (children->is(Type::Array)) {
      for (const Value& c : children->items) out.push_back(node(c, ""));
      const size_t n = children->items.size();
      if (p.type == ParamType::Int && n == 0) {
        ok = check_.error(children->pos, "a select on int '" + p.name + "' needs at least one child");
      } else if (p.type != ParamType::Int && n != labels.size()) {
        ok = check_.error(children->pos, "a select on " + std::string(type_word(p.type)) + " '" + p.name +
                                             "' needs exactly " + std::to_string(labels.size()) +
                                             " children, one per value in the order " + quoted(labels) + ", not " +
                                             std::to_string(n));
      }
    } else {
      if (p.type == ParamType::Int) {
        for (const Member& m : children->members) node(m.value, "");
        check_.error(children->pos, "a select on int '" + p.name + "' takes its children as an array");
        return -1;
      }
      out.assign(labels.size(), -1);
      std::vector<bool> given(labels.size(), false);
      for (const Member& m : children->members) {
        const auto at = std::find(labels.begin(), labels.end(), m.key);
        const int child = node(m.value, "");
        if (at == labels.end()) {
          ok = check_.error(m.key_pos, "'" + m.key + "' is not a value of " + std::string(type_word(p.type)) + " '" +
                                           p.name + "' (values: " + quoted(labels) + ")");
          continue;
        }
        const size_t slot = static_cast<size_t>(at - labels.begin());
        given[slot] = true;
        out[slot] = child;
      }
      for (size_t i = 0; i < labels.size(); ++i)
        if (!given[i])
          ok = check_.error(children->pos, "a select on '" + p.name + "' has no child for '" + labels[i] + "'");
    }
    for (int c : out) ok &= c >= 0;
    if (!ok) return -1;
    s.parameter = static_cast<uint16_t>(param);
    for (int c : out) s.children.push_back(static_cast<uint16_t>(c));
    return emit(name, std::move(s));
  }

  int joint(const Value& v, const std::string& role = "a mask") {
    if (!check_.expect(v, Type::String, role + "'s \"joint\"")) return -1;
    if (!ctx_.skeleton) return -1;
    const auto& joints = ctx_.skeleton->joints;
    if (joint_index_.empty())
      for (size_t j = joints.size(); j-- > 0;)
        joint_index_[joints[j].name] = static_cast<int>(j);  // the first of a name
    if (const auto found = joint_index_.find(v.string); found != joint_index_.end()) return found->second;
    if (check_.full()) return check_.error(v.pos, "unknown joint '" + v.string + "' in " + role), -1;
    std::vector<std::string> names;
    for (const SourceJoint& j : joints) names.push_back(j.name);
    const std::string hint = json::closest_name(v.string, names);
    return check_.error(v.pos,
                        "unknown joint '" + v.string + "' in " + role +
                            (hint.empty() ? " (joint names are case-sensitive)" : " (did you mean '" + hint + "'?)")),
           -1;
  }

  int layered_node(const Value& v, const std::string& name) {
    check_.expect_keys(v, {"layered", "layers", "name"}, "a layered node");
    LayeredDef l;
    const int base = node(*v.find("layered"), "");
    bool ok = base >= 0;
    const Value* layers = required(v, "layers", "a layered node");
    if (!layers || !check_.expect(*layers, Type::Array, "\"layers\"")) return -1;
    if (layers->items.empty())
      ok = check_.error(layers->pos, "\"layers\" is empty: a layered node needs at least one layer");
    for (const Value& lv : layers->items) {
      if (!check_.expect(lv, Type::Object, "a layer")) {
        ok = false;
        continue;
      }
      check_.expect_keys(lv, {"node", "mask", "weight", "weight_parameter", "blend_time", "mesh_space_rotation",
                              "morph_targets"},
                         "a layer");
      LayerDef layer;
      const Value* n = required(lv, "node", "a layer");
      const int child = n ? node(*n, "") : -1;
      ok &= child >= 0;
      layer.node = static_cast<uint16_t>(std::max(child, 0));
      const Value* mask = required(lv, "mask", "a layer");
      if (!mask || !check_.expect(*mask, Type::Array, "\"mask\" ([{\"joint\": ...}, ...])")) {
        ok = false;
      } else {
        if (mask->items.empty()) ok = check_.error(mask->pos, "\"mask\" is empty: a layer needs at least one joint");
        for (const Value& e : mask->items) {
          if (!check_.expect(e, Type::Object, "a mask entry ({\"joint\": ..., \"depth\": ...})")) {
            ok = false;
            continue;
          }
          check_.expect_keys(e, {"joint", "depth"}, "a mask entry");
          MaskEntryDef entry;
          const Value* jv = required(e, "joint", "a mask entry");
          const int j = jv ? joint(*jv) : -1;
          ok &= j >= 0;
          entry.joint = static_cast<uint16_t>(std::max(j, 0));
          if (const Value* d = e.find("depth")) {
            long long depth = -1;
            ok &= check_.expect_integer(*d, "a mask's \"depth\" (-1: all descendants)", -1, 32767, &depth);
            entry.depth = static_cast<int16_t>(depth);
          }
          layer.mask.push_back(entry);
        }
      }
      if (const Value* w = lv.find("weight")) ok &= read_float(*w, "a layer's \"weight\"", &layer.weight, 0.0, 1.0);
      if (const Value* p = lv.find("weight_parameter")) {
        const int param = parameter(*p, {ParamType::Float, ParamType::Bool}, "a layer's \"weight_parameter\"");
        ok &= param >= 0;
        layer.weight_parameter = static_cast<int16_t>(param);
      }
      if (const Value* t = lv.find("blend_time"))
        ok &= read_float(*t, "a layer's \"blend_time\"", &layer.blend_time, 0.0, kMaxSeconds);
      if (const Value* m = lv.find("mesh_space_rotation"))
        ok &= read_bool(*m, "\"mesh_space_rotation\"", &layer.mesh_space_rotation);
      if (const Value* mt = lv.find("morph_targets")) {
        if (!check_.expect(*mt, Type::Array, "a layer's \"morph_targets\" (morph target names)")) {
          ok = false;
        } else {
          layer.morph_targets.emplace();
          for (const Value& target : mt->items) {
            if (!check_.expect(target, Type::String, "a morph target name")) {
              ok = false;
            } else if (target.string.empty()) {
              ok = check_.error(target.pos, "a morph target name is empty");
            } else {
              layer.morph_targets->push_back(target.string);
            }
          }
        }
      }
      l.layers.push_back(std::move(layer));
    }
    if (!ok) return -1;
    l.base = static_cast<uint16_t>(base);
    return emit(name, std::move(l));
  }

  int blend_space_node(const Value& v, const std::string& name) {
    check_.expect_keys(v, {"blend_space", "y", "samples", "rate", "loop", "name"}, "a blend space");
    BlendSpaceDef b;
    const int x = parameter(*v.find("blend_space"), {ParamType::Float}, "a blend space's x (\"blend_space\")");
    bool ok = x >= 0;
    const Value* yv = v.find("y");
    if (yv) {
      const int y = parameter(*yv, {ParamType::Float}, "a blend space's \"y\"");
      ok &= y >= 0;
      b.y_parameter = static_cast<int16_t>(y);
    }
    if (const Value* r = v.find("rate")) ok &= read_float(*r, "\"rate\"", &b.rate, -kMaxRate, kMaxRate);
    if (const Value* l = v.find("loop")) ok &= read_bool(*l, "\"loop\"", &b.loop);
    const Value* samples = required(v, "samples", "a blend space");
    if (!samples || !check_.expect(*samples, Type::Array, "\"samples\"")) return -1;
    if (samples->items.size() > kMaxBlendSamples)
      return check_.error(samples->pos, "a blend space has " + std::to_string(samples->items.size()) +
                                            " samples; at most " + std::to_string(kMaxBlendSamples)),
             -1;
    const bool two_d = yv != nullptr;
    std::vector<Pos> where;  // each sample's position, for the checks across samples
    for (const Value& s : samples->items) {
      if (!check_.expect(s, Type::Object, "a sample ({\"clip\": ..., \"x\": ...})")) {
        ok = false;
        continue;
      }
      check_.expect_keys(s, {"clip", "x", "y"}, "a blend-space sample");
      BlendSampleDef sample;
      const Value* c = required(s, "clip", "a sample");
      const int ci = c ? clip(*c, "a sample") : -1;
      ok &= ci >= 0;
      sample.clip = static_cast<uint16_t>(std::max(ci, 0));
      const Value* sx = required(s, "x", "a sample");
      ok &= sx && read_float(*sx, "a sample's \"x\"", &sample.x, -kMaxCoordinate, kMaxCoordinate);
      const Value* sy = s.find("y");
      if (two_d && !sy) ok = check_.error(s.pos, "a sample of a 2D blend space needs \"y\"");
      if (!two_d && sy) ok = check_.error(sy->pos, "\"y\" given but the blend space has no \"y\" parameter (1D)");
      if (two_d && sy) ok &= read_float(*sy, "a sample's \"y\"", &sample.y, -kMaxCoordinate, kMaxCoordinate);
      b.samples.push_back(sample);
      where.push_back(s.pos);
    }
    if (!ok) return -1;
    const auto label = [&](size_t i) { return "'" + g_.clips[b.samples[i].clip] + "'"; };
    if (!two_d) {
      if (b.samples.size() < 2)
        return check_.error(samples->pos, "a 1D blend space needs at least 2 samples (one clip is a clip node)"), -1;
      std::vector<size_t> order(b.samples.size());
      for (size_t i = 0; i < order.size(); ++i) order[i] = i;
      std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t c) { return b.samples[a].x < b.samples[c].x; });
      for (size_t i = 1; i < order.size(); ++i) {
        if (b.samples[order[i]].x == b.samples[order[i - 1]].x) {
          const size_t later = std::max(order[i], order[i - 1]), earlier = std::min(order[i], order[i - 1]);
          ok = check_.error(where[later], "samples " + label(earlier) + " and " + label(later) + " have the same x (" +
                                              number_text(b.samples[later].x) + ")");
        }
      }
      std::vector<BlendSampleDef> sorted;
      for (size_t i : order) sorted.push_back(b.samples[i]);
      b.samples = std::move(sorted);
    } else {
      if (b.samples.size() < 3)
        return check_.error(samples->pos, "a 2D blend space needs at least 3 samples, not all on one line"), -1;
      for (size_t i = 0; i < b.samples.size(); ++i)
        for (size_t j = 0; j < i; ++j)
          if (b.samples[i].x == b.samples[j].x && b.samples[i].y == b.samples[j].y)
            ok = check_.error(where[i], "samples " + label(j) + " and " + label(i) + " are at the same point (" +
                                            number_text(b.samples[i].x) + ", " + number_text(b.samples[i].y) + ")");
      if (ok) {
        // The runtime's own triangulation decides what it can use (collinear, near-duplicates).
        std::vector<glm::vec2> points;
        for (const BlendSampleDef& s : b.samples) points.emplace_back(s.x, s.y);
        if (auto space = make_blend_space_2d(points); !space) ok = check_.error(samples->pos, space.error().message);
      }
    }
    if (!ok) return -1;
    b.x_parameter = static_cast<uint16_t>(x);
    return emit(name, std::move(b));
  }

  int additive_node(const Value& v, const std::string& name) {
    check_.expect_keys(v, {"additive", "add", "weight", "weight_parameter", "name"}, "an additive node");
    AdditiveDef a;
    const int base = node(*v.find("additive"), "");
    bool ok = base >= 0;
    const Value* add = required(v, "add", "an additive node");
    const int added = add ? node(*add, "") : -1;
    ok &= added >= 0;
    if (const Value* w = v.find("weight")) ok &= read_float(*w, "\"weight\"", &a.weight, -kMaxWeight, kMaxWeight);
    if (const Value* p = v.find("weight_parameter")) {
      const int param = parameter(*p, {ParamType::Float, ParamType::Bool}, "\"weight_parameter\"");
      ok &= param >= 0;
      a.weight_parameter = static_cast<int16_t>(param);
    }
    if (!ok) return -1;
    a.base = static_cast<uint16_t>(base);
    a.additive = static_cast<uint16_t>(added);
    return emit(name, a);
  }

  /// {"morph": INPUT, "drives": [{"target": "smile", "parameter": "happy", "scale": 1}, ...]}
  int morph_node(const Value& v, const std::string& name) {
    check_.expect_keys(v, {"morph", "drives", "name"}, "a morph node");
    MorphWeightsDef m;
    const int input = node(*v.find("morph"), "");
    bool ok = input >= 0;
    const Value* drives = required(v, "drives", "a morph node");
    if (!drives || !check_.expect(*drives, Type::Array, "\"drives\" ([{\"target\": ..., \"parameter\": ...}, ...])"))
      return -1;
    if (drives->items.empty()) ok = check_.error(drives->pos, "\"drives\" is empty: a morph node sets at least one target");
    for (const Value& d : drives->items) {
      if (!check_.expect(d, Type::Object, "a drive ({\"target\": ..., \"parameter\": ...})")) {
        ok = false;
        continue;
      }
      check_.expect_keys(d, {"target", "parameter", "scale"}, "a drive");
      MorphDriveDef drive;
      const Value* t = required(d, "target", "a drive");
      if (!t || !check_.expect(*t, Type::String, "a drive's \"target\" (a morph target name)")) {
        ok = false;
      } else if (t->string.empty()) {
        ok = check_.error(t->pos, "a drive's \"target\" is empty");
      } else {
        drive.target = t->string;
      }
      const Value* p = required(d, "parameter", "a drive");
      const int param = p ? parameter(*p, {ParamType::Float, ParamType::Bool}, "a drive's \"parameter\"") : -1;
      ok &= param >= 0;
      drive.parameter = static_cast<uint16_t>(std::max(param, 0));
      if (const Value* sc = d.find("scale"))
        ok &= read_float(*sc, "a drive's \"scale\"", &drive.scale, -kMaxWeight, kMaxWeight);
      m.drives.push_back(std::move(drive));
    }
    if (!ok) return -1;
    m.input = static_cast<uint16_t>(input);
    return emit(name, std::move(m));
  }

  // ---- procedural nodes (format v6) ----------------------------------------------------------
  // Lengths in the graph file are metres (converted to the rig's units), angles degrees.

  /// Rig units per metre (the rig's unit unknown: 1).
  double units() const {
    const double mpu = ctx_.skeleton ? ctx_.skeleton->metres_per_unit : 0.0;
    return mpu > 0.0 ? 1.0 / mpu : 1.0;
  }

  bool read_vec3(const Value& v, const std::string& what, double scale, Vec3Def* out) {
    if (!check_.expect(v, Type::Array, what + " ([x, y, z])")) return false;
    if (v.items.size() != 3) return check_.error(v.pos, what + " needs 3 numbers, not " + std::to_string(v.items.size()));
    bool ok = true;
    for (size_t i = 0; i < 3; ++i) {
      double d = 0.0;
      if (!check_.expect_number(v.items[i], what, &d)) {
        ok = false;
      } else if (std::abs(d * scale) > 1e6) {
        ok = check_.error(v.items[i].pos, what + " must be within +-1e6 units");
      } else {
        (*out)[i] = static_cast<float>(d * scale);
      }
    }
    return ok;
  }
  /// A length in metres, >= lo, stored in rig units.
  bool read_length(const Value& v, const std::string& what, float* out, double lo = 0.0) {
    float metres = 0.0f;
    if (!read_float(v, what + " (metres)", &metres, lo, 1e6)) return false;
    *out = static_cast<float>(metres * units());
    return true;
  }
  bool read_degrees(const Value& v, const std::string& what, float* out, double lo, double hi) {
    float deg = 0.0f;
    if (!read_float(v, what + " (degrees)", &deg, lo, hi)) return false;
    *out = static_cast<float>(deg * kDegrees);
    return true;
  }
  /// "weight" in [0, 1] and "weight_parameter" (float or bool).
  bool read_weight(const Value& v, float* weight, int16_t* weight_parameter) {
    bool ok = true;
    if (const Value* w = v.find("weight")) ok &= read_float(*w, "\"weight\"", weight, 0.0, 1.0);
    if (const Value* p = v.find("weight_parameter")) {
      const int param = parameter(*p, {ParamType::Float, ParamType::Bool}, "\"weight_parameter\"");
      ok &= param >= 0;
      *weight_parameter = static_cast<int16_t>(param);
    }
    return ok;
  }
  /// A required joint member; -1 reported.
  int joint_member(const Value& v, std::string_view key, const std::string& what) {
    const Value* j = required(v, key, what);
    return j ? joint(*j, what + " \"" + std::string(key) + "\"") : -1;
  }
  /// Joint j's model-space rotation at the bind pose.
  glm::quat bind_rotation(uint32_t j) const {
    glm::quat r(1.0f, 0.0f, 0.0f, 0.0f);
    for (int k = static_cast<int>(j); k >= 0; k = ctx_.skeleton->joints[static_cast<size_t>(k)].parent)
      r = ctx_.skeleton->joints[static_cast<size_t>(k)].rotation * r;
    return r;
  }
  /// Whether joint a is a strict ancestor of b.
  bool ancestor(int a, int b) const {
    if (!ctx_.skeleton || a < 0 || b < 0) return true;  // reported elsewhere
    for (int j = ctx_.skeleton->joints[static_cast<size_t>(b)].parent; j >= 0; j = ctx_.skeleton->joints[static_cast<size_t>(j)].parent)
      if (j == a) return true;
    return false;
  }
  bool check_chain(const Value& at, std::initializer_list<int> joints, const std::string& what) {
    const int* prev = nullptr;
    for (const int& j : joints) {
      if (prev && *prev >= 0 && j >= 0 && !ancestor(*prev, j))
        return check_.error(at.pos, what + ": joint '" + ctx_.skeleton->joints[static_cast<size_t>(*prev)].name +
                                        "' is not an ancestor of '" + ctx_.skeleton->joints[static_cast<size_t>(j)].name + "'");
      prev = &j;
    }
    return true;
  }

  /// {"two_bone_ik": INPUT, "start": J, "mid": J, "end": J, "target": VECTOR, "pole": VECTOR | [x, y, z],
  ///  "mid_axis": [x, y, z], "twist": degrees, "soften": (0, 1], "weight", "weight_parameter"}
  int two_bone_node(const Value& v, const std::string& name) {
    const std::string what = "a two_bone_ik node";
    check_.expect_keys(v, {"two_bone_ik", "start", "mid", "end", "target", "pole", "mid_axis", "twist", "soften", "weight",
                           "weight_parameter", "name"},
                       what);
    TwoBoneIkDef t;
    const int input = node(*v.find("two_bone_ik"), "");
    bool ok = input >= 0;
    const int start = joint_member(v, "start", what), mid = joint_member(v, "mid", what), end = joint_member(v, "end", what);
    ok &= start >= 0 && mid >= 0 && end >= 0 && check_chain(v, {start, mid, end}, what);
    const Value* target = required(v, "target", what);
    const int tp = target ? parameter(*target, {ParamType::Vector}, "\"target\"") : -1;
    ok &= tp >= 0;
    if (const Value* pole = v.find("pole")) {
      if (pole->is(Type::String)) {
        const int pp = parameter(*pole, {ParamType::Vector}, "\"pole\"");
        ok &= pp >= 0;
        t.pole_parameter = static_cast<int16_t>(pp);
      } else {
        ok &= read_vec3(*pole, "\"pole\" (a direction, or a vector parameter's name)", 1.0, &t.pole);
      }
    }
    if (const Value* a = v.find("mid_axis")) ok &= read_vec3(*a, "\"mid_axis\"", 1.0, &t.mid_axis);
    if (const Value* tw = v.find("twist")) ok &= read_degrees(*tw, "\"twist\"", &t.twist, -360.0, 360.0);
    if (const Value* so = v.find("soften")) {
      ok &= read_float(*so, "\"soften\"", &t.soften, 0.0, 1.0);
      if (t.soften <= 0.0f) ok = check_.error(so->pos, "\"soften\" must be above 0 (1: no softening)");
    }
    ok &= read_weight(v, &t.weight, &t.weight_parameter);
    if (!ok) return -1;
    t.input = static_cast<uint16_t>(input);
    t.start = static_cast<uint16_t>(start);
    t.mid = static_cast<uint16_t>(mid);
    t.end = static_cast<uint16_t>(end);
    t.target_parameter = static_cast<uint16_t>(tp);
    return emit(name, t);
  }

  /// {"aim": INPUT, "chain": [{"joint": J, "weight": w, "max_angle": degrees}, ...] (base first),
  ///  "target": VECTOR, "forward": [x, y, z], "up": [x, y, z], "pole": [x, y, z], "weight", "weight_parameter"}
  int aim_node(const Value& v, const std::string& name) {
    const std::string what = "an aim node";
    check_.expect_keys(v, {"aim", "chain", "target", "forward", "up", "pole", "weight", "weight_parameter", "name"}, what);
    AimDef a;
    const int input = node(*v.find("aim"), "");
    bool ok = input >= 0;
    const Value* chain = required(v, "chain", what);
    if (!chain || !check_.expect(*chain, Type::Array, "\"chain\" ([{\"joint\": ...}, ...], base first)")) return -1;
    if (chain->items.empty() || chain->items.size() > kMaxSpringJoints)
      ok = check_.error(chain->pos, "\"chain\" needs 1 to " + std::to_string(kMaxSpringJoints) + " joints");
    int previous = -1;
    for (const Value& e : chain->items) {
      if (!check_.expect(e, Type::Object, "an aim joint ({\"joint\": ..., \"weight\": ..., \"max_angle\": ...})")) {
        ok = false;
        continue;
      }
      check_.expect_keys(e, {"joint", "weight", "max_angle"}, "an aim joint");
      AimJointDef j;
      const int index = joint_member(e, "joint", "an aim joint");
      ok &= index >= 0 && check_chain(e, {previous, index}, what + "'s chain (base first)");
      previous = index;
      j.joint = static_cast<uint16_t>(std::max(index, 0));
      if (const Value* w = e.find("weight")) ok &= read_float(*w, "an aim joint's \"weight\"", &j.weight, 0.0, 1.0);
      if (const Value* m = e.find("max_angle")) ok &= read_degrees(*m, "an aim joint's \"max_angle\"", &j.max_angle, 0.0, 180.0);
      a.chain.push_back(j);
    }
    const Value* target = required(v, "target", what);
    const int tp = target ? parameter(*target, {ParamType::Vector}, "\"target\"") : -1;
    ok &= tp >= 0;
    // "forward" and "up" are model-space directions at the bind pose (where the character faces,
    // its up), stored as the last joint's local axes, so a graph names them the same for any rig.
    Vec3Def forward{0.0f, 0.0f, 1.0f}, up{0.0f, 1.0f, 0.0f};
    if (const Value* f = v.find("forward")) ok &= read_vec3(*f, "\"forward\"", 1.0, &forward);
    if (const Value* u = v.find("up")) ok &= read_vec3(*u, "\"up\"", 1.0, &up);
    if (ok && !a.chain.empty()) {
      const glm::quat to_local = glm::conjugate(bind_rotation(a.chain.back().joint));
      const glm::vec3 f = to_local * glm::vec3(forward[0], forward[1], forward[2]);
      const glm::vec3 u = to_local * glm::vec3(up[0], up[1], up[2]);
      a.forward = {f.x, f.y, f.z};
      a.up = {u.x, u.y, u.z};
    }
    if (const Value* p = v.find("pole")) ok &= read_vec3(*p, "\"pole\"", 1.0, &a.pole);
    ok &= read_weight(v, &a.weight, &a.weight_parameter);
    if (!ok) return -1;
    a.input = static_cast<uint16_t>(input);
    a.target_parameter = static_cast<uint16_t>(tp);
    return emit(name, std::move(a));
  }

  bool read_legs(const Value& v, bool lock, std::vector<FootLegDef>* out) {
    const Value* legs = required(v, "legs", lock ? "a foot_lock node" : "a foot_placement node");
    if (!legs || !check_.expect(*legs, Type::Array, "\"legs\" ([{\"hip\": ..., \"knee\": ..., \"ankle\": ...}, ...])"))
      return false;
    bool ok = true;
    if (legs->items.empty() || legs->items.size() > kMaxFootLegs)
      ok = check_.error(legs->pos, "\"legs\" needs 1 to " + std::to_string(kMaxFootLegs) + " legs");
    for (const Value& e : legs->items) {
      if (!check_.expect(e, Type::Object, "a leg ({\"hip\": ..., \"knee\": ..., \"ankle\": ...})")) {
        ok = false;
        continue;
      }
      if (lock) check_.expect_keys(e, {"hip", "knee", "ankle", "planted", "plant_event", "lift_event"}, "a foot_lock leg");
      else check_.expect_keys(e, {"hip", "knee", "ankle", "ground", "normal"}, "a foot_placement leg");
      FootLegDef leg;
      const int hip = joint_member(e, "hip", "a leg"), knee = joint_member(e, "knee", "a leg"),
                ankle = joint_member(e, "ankle", "a leg");
      ok &= hip >= 0 && knee >= 0 && ankle >= 0 && check_chain(e, {hip, knee, ankle}, "a leg");
      leg.hip = static_cast<uint16_t>(std::max(hip, 0));
      leg.knee = static_cast<uint16_t>(std::max(knee, 0));
      leg.ankle = static_cast<uint16_t>(std::max(ankle, 0));
      const auto param = [&](const char* key, std::initializer_list<ParamType> types, int16_t* slot) {
        if (const Value* p = e.find(key)) {
          const int index = parameter(*p, types, std::string("a leg's \"") + key + "\"");
          ok &= index >= 0;
          *slot = static_cast<int16_t>(index);
        }
      };
      param("ground", {ParamType::Float}, &leg.ground_parameter);
      param("normal", {ParamType::Vector}, &leg.normal_parameter);
      param("planted", {ParamType::Float, ParamType::Bool}, &leg.planted_parameter);
      for (const char* key : {"plant_event", "lift_event"}) {
        const Value* ev = e.find(key);
        if (!ev) continue;
        if (!check_.expect(*ev, Type::String, std::string("a leg's \"") + key + "\" (an event name)") || ev->string.empty()) {
          ok = ok && ev->is(Type::String) ? check_.error(ev->pos, std::string("a leg's \"") + key + "\" is empty") : false;
          continue;
        }
        (std::string_view(key) == "plant_event" ? leg.plant_event : leg.lift_event) = ev->string;
      }
      if (lock && leg.planted_parameter < 0 && (leg.plant_event.empty() || leg.lift_event.empty()))
        ok = check_.error(e.pos, "a foot_lock leg needs \"planted\" (a parameter) or both \"plant_event\" and \"lift_event\"");
      out->push_back(std::move(leg));
    }
    return ok;
  }

  /// {"foot_placement": INPUT, "pelvis": J, "legs": [{"hip", "knee", "ankle", "ground": FLOAT, "normal": VECTOR}],
  ///  "up": [x, y, z], "max_pelvis_drop": metres, "align": [0, 1], "soften", "weight", "weight_parameter"}
  /// {"foot_lock": INPUT, "legs": [{"hip", "knee", "ankle", "planted": FLOAT|BOOL, "plant_event", "lift_event"}],
  ///  "release_radius": metres, "blend_time": seconds, "weight", "weight_parameter"}
  int foot_node(const Value& v, const std::string& name, bool lock) {
    const std::string what = lock ? "a foot_lock node" : "a foot_placement node";
    if (lock)
      check_.expect_keys(v, {"foot_lock", "legs", "release_radius", "blend_time", "weight", "weight_parameter", "name"}, what);
    else
      check_.expect_keys(v, {"foot_placement", "pelvis", "legs", "up", "max_pelvis_drop", "align", "soften", "weight",
                             "weight_parameter", "name"},
                         what);
    const int input = node(*v.find(lock ? "foot_lock" : "foot_placement"), "");
    bool ok = input >= 0;
    std::vector<FootLegDef> legs;
    ok &= read_legs(v, lock, &legs);
    if (lock) {
      FootLockDef f;
      f.legs = std::move(legs);
      f.release_radius = static_cast<float>(0.15 * units());
      f.blend_time = 0.2f;
      if (const Value* r = v.find("release_radius")) {
        ok &= read_length(*r, "\"release_radius\"", &f.release_radius);
        if (ok && !(f.release_radius > 0.0f)) ok = check_.error(r->pos, "\"release_radius\" must be above 0");
      }
      if (const Value* b = v.find("blend_time")) ok &= read_float(*b, "\"blend_time\" (seconds)", &f.blend_time, 0.0, 1e6);
      ok &= read_weight(v, &f.weight, &f.weight_parameter);
      if (!ok) return -1;
      f.input = static_cast<uint16_t>(input);
      return emit(name, std::move(f));
    }
    FootPlacementDef f;
    f.legs = std::move(legs);
    const int pelvis = joint_member(v, "pelvis", what);
    ok &= pelvis >= 0;
    f.max_pelvis_drop = static_cast<float>(0.3 * units());
    if (const Value* u = v.find("up")) ok &= read_vec3(*u, "\"up\"", 1.0, &f.up);
    if (const Value* d = v.find("max_pelvis_drop")) ok &= read_length(*d, "\"max_pelvis_drop\"", &f.max_pelvis_drop);
    if (const Value* a = v.find("align")) ok &= read_float(*a, "\"align\"", &f.align, 0.0, 1.0);
    if (const Value* so = v.find("soften")) {
      ok &= read_float(*so, "\"soften\"", &f.soften, 0.0, 1.0);
      if (f.soften <= 0.0f) ok = check_.error(so->pos, "\"soften\" must be above 0 (1: no softening)");
    }
    ok &= read_weight(v, &f.weight, &f.weight_parameter);
    if (!ok) return -1;
    f.input = static_cast<uint16_t>(input);
    f.pelvis = static_cast<uint16_t>(pelvis);
    return emit(name, std::move(f));
  }

  /// {"spring": INPUT, "chains": [{"joints": [J, ...] (parent first), "stiffness", "drag", "gravity": [x, y, z] m/s^2,
  ///  "radius": metres, "tail_length": metres}], "colliders": [{"joint": J, "offset": [..] m, "tail": [..] m,
  ///  "radius": m}], "step": seconds, "teleport_distance": metres, "weight", "weight_parameter"}
  int spring_node(const Value& v, const std::string& name) {
    const std::string what = "a spring node";
    check_.expect_keys(v, {"spring", "chains", "colliders", "step", "teleport_distance", "weight", "weight_parameter", "name"},
                       what);
    SpringDef sp;
    const int input = node(*v.find("spring"), "");
    bool ok = input >= 0;
    const Value* chains = required(v, "chains", what);
    if (!chains || !check_.expect(*chains, Type::Array, "\"chains\" ([{\"joints\": [...]}, ...])")) return -1;
    if (chains->items.empty()) ok = check_.error(chains->pos, "\"chains\" is empty: a spring node needs a chain");
    for (const Value& c : chains->items) {
      if (!check_.expect(c, Type::Object, "a spring chain ({\"joints\": [...], ...})")) {
        ok = false;
        continue;
      }
      check_.expect_keys(c, {"joints", "stiffness", "drag", "gravity", "radius", "tail_length"}, "a spring chain");
      SpringChainDef chain;
      chain.gravity = {0.0f, static_cast<float>(-9.81 * units()), 0.0f};
      const Value* joints = required(c, "joints", "a spring chain");
      if (!joints || !check_.expect(*joints, Type::Array, "a spring chain's \"joints\" (parent first)")) {
        ok = false;
        continue;
      }
      if (joints->items.empty() || joints->items.size() > kMaxSpringJoints)
        ok = check_.error(joints->pos, "a spring chain needs 1 to " + std::to_string(kMaxSpringJoints) + " joints");
      int previous = -1;
      for (const Value& jv : joints->items) {
        const int j = joint(jv, "a spring chain");
        if (j < 0) {
          ok = false;
          continue;
        }
        if (previous >= 0 && ctx_.skeleton->joints[static_cast<size_t>(j)].parent != previous)
          ok = check_.error(jv.pos, "spring chain joint '" + jv.string + "' is not a child of '" +
                                        ctx_.skeleton->joints[static_cast<size_t>(previous)].name +
                                        "' (a chain lists each joint's child next)");
        previous = j;
        chain.joints.push_back(static_cast<uint16_t>(j));
      }
      // The last joint's bone: by default as long as the one before it (or 5 cm alone).
      if (previous >= 0) {
        const glm::vec3 t = ctx_.skeleton->joints[static_cast<size_t>(previous)].translation;
        chain.tail_length = chain.joints.size() > 1 ? glm::length(t) : static_cast<float>(0.05 * units());
      }
      if (const Value* x = c.find("stiffness")) ok &= read_float(*x, "\"stiffness\" (per second)", &chain.stiffness, 0.0, 1e4);
      if (const Value* x = c.find("drag")) ok &= read_float(*x, "\"drag\"", &chain.drag, 0.0, 1.0);
      if (const Value* x = c.find("gravity")) ok &= read_vec3(*x, "\"gravity\" (m/s^2)", units(), &chain.gravity);
      if (const Value* x = c.find("radius")) ok &= read_length(*x, "\"radius\"", &chain.radius);
      if (const Value* x = c.find("tail_length")) ok &= read_length(*x, "\"tail_length\"", &chain.tail_length);
      sp.chains.push_back(std::move(chain));
    }
    if (const Value* colliders = v.find("colliders")) {
      if (!check_.expect(*colliders, Type::Array, "\"colliders\" ([{\"joint\": ..., \"radius\": ...}, ...])")) return -1;
      for (const Value& c : colliders->items) {
        if (!check_.expect(c, Type::Object, "a collider ({\"joint\": ..., \"offset\": ..., \"radius\": ...})")) {
          ok = false;
          continue;
        }
        check_.expect_keys(c, {"joint", "offset", "tail", "radius"}, "a collider");
        SpringColliderDef col;
        const int j = joint_member(c, "joint", "a collider");
        ok &= j >= 0;
        col.joint = static_cast<uint16_t>(std::max(j, 0));
        if (const Value* x = c.find("offset")) ok &= read_vec3(*x, "a collider's \"offset\" (metres)", units(), &col.offset);
        col.tail = col.offset;
        if (const Value* x = c.find("tail")) ok &= read_vec3(*x, "a collider's \"tail\" (metres)", units(), &col.tail);
        if (const Value* r = required(c, "radius", "a collider")) ok &= read_length(*r, "a collider's \"radius\"", &col.radius);
        else ok = false;
        sp.colliders.push_back(col);
      }
    }
    if (const Value* x = v.find("step")) ok &= read_float(*x, "\"step\" (seconds)", &sp.step, 1e-4, 1.0);
    if (const Value* x = v.find("teleport_distance")) ok &= read_length(*x, "\"teleport_distance\"", &sp.teleport_distance);
    ok &= read_weight(v, &sp.weight, &sp.weight_parameter);
    if (!ok) return -1;
    sp.input = static_cast<uint16_t>(input);
    return emit(name, std::move(sp));
  }

  // ---- state machines ------------------------------------------------------------------------

  int machine_node(const Value& v, const std::string& name) {
    check_.expect_keys(v, {"state_machine", "name"}, "a state machine node");
    const Value& m = *v.find("state_machine");
    if (!check_.expect(m, Type::Object, "\"state_machine\"")) return -1;
    check_.expect_keys(m, {"name", "entry", "states", "transitions"}, "a state machine");
    if (g_.machines.size() >= 65535) return check_.error(m.pos, "more than 65535 state machines"), -1;
    const size_t machine_index = g_.machines.size();
    g_.machines.emplace_back();  // reserved now: machines are numbered in the order they are met
    StateMachineDef sm;
    bool ok = true;
    if (const Value* n = required(m, "name", "a state machine"))
      ok &= check_.expect_name(*n, "a state machine's \"name\"", &sm.name);
    else ok = false;
    const std::string label = sm.name.empty() ? std::string("the state machine") : "state machine '" + sm.name + "'";

    std::vector<Pos> state_pos;
    const Value* states = required(m, "states", "a state machine");
    if (states && check_.expect(*states, Type::Object, "\"states\" ({\"<state>\": {\"node\": ...}, ...})")) {
      if (states->members.empty()) ok = check_.error(states->pos, label + " has no states");
      // Transition.from is int16. Past that nothing in the machine can be compiled: say so alone.
      if (states->members.size() > 32767) return check_.error(states->pos, label + " has more than 32767 states"), -1;
      for (const Member& s : states->members) {
        StateDef st;
        st.name = s.key;
        if (s.key == "any")
          ok = check_.error(s.key_pos, "'any' is reserved for transitions from any state; rename the state");
        if (s.key.empty()) ok = check_.error(s.key_pos, "a state name must not be empty");
        if (check_.expect(s.value, Type::Object, "state '" + s.key + "' ({\"node\": ..., \"restart\": ...})")) {
          check_.expect_keys(s.value, {"node", "restart"}, "a state");
          const Value* n = required(s.value, "node", "state '" + s.key + "'");
          const int child = n ? node(*n, "") : -1;
          ok &= child >= 0;
          st.node = static_cast<uint16_t>(std::max(child, 0));
          if (const Value* r = s.value.find("restart")) ok &= read_bool(*r, "\"restart\"", &st.restart);
        } else {
          ok = false;
        }
        sm.states.push_back(std::move(st));
        state_pos.push_back(s.key_pos);
      }
    } else {
      ok = false;
    }
    std::unordered_map<std::string_view, int> states_by_name;
    for (size_t i = 0; i < sm.states.size(); ++i) states_by_name.emplace(sm.states[i].name, static_cast<int>(i));
    const auto state_index = [&](const std::string& s) {
      const auto found = states_by_name.find(s);
      return found == states_by_name.end() ? -1 : found->second;
    };
    const auto unknown_state = [&](const Value& at, const std::string& what) {
      if (check_.full()) return check_.error(at.pos, what + " '" + at.string + "' is not a state of " + label);
      std::vector<std::string> names;
      for (const StateDef& s : sm.states) names.push_back(s.name);
      const std::string hint = json::closest_name(at.string, names);
      return check_.error(at.pos, what + " '" + at.string + "' is not a state of " + label +
                                      (hint.empty() ? "" : " (did you mean '" + hint + "'?)") +
                                      "; states: " + quoted(names));
    };

    bool entry_ok = false;
    if (const Value* e = m.find("entry")) {
      if (check_.expect(*e, Type::String, "\"entry\" (a state name)")) {
        const int entry = state_index(e->string);
        if (entry < 0) ok = unknown_state(*e, "the entry state");
        else sm.entry = static_cast<uint16_t>(entry), entry_ok = true;
      } else {
        ok = false;
      }
    } else {
      ok = check_.error(m.pos, label + " needs an \"entry\" state");
    }

    std::vector<long long> priorities;
    bool transitions_ok = true;
    if (const Value* ts = m.find("transitions"); ts && check_.expect(*ts, Type::Array, "\"transitions\"")) {
      for (const Value& t : ts->items) {
        TransitionDef tr;
        long long priority = 0;
        if (transition(t, state_index, unknown_state, tr, priority)) {
          sm.transitions.push_back(std::move(tr));
          priorities.push_back(priority);
        } else {
          transitions_ok = false;
        }
      }
    } else if (ts) {
      transitions_ok = false;
    }
    ok &= transitions_ok;

    // Stable sort by priority: lower first, file order among equals.
    std::vector<size_t> order(sm.transitions.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return priorities[a] < priorities[b]; });
    std::vector<TransitionDef> sorted;
    for (size_t i : order) sorted.push_back(std::move(sm.transitions[i]));
    sm.transitions = std::move(sorted);

    // Every state must be reachable from the entry (only meaningful once every transition read).
    if (entry_ok && transitions_ok) {
      std::vector<bool> reached(sm.states.size(), false);
      std::vector<size_t> stack = {sm.entry};
      reached[sm.entry] = true;
      std::vector<std::vector<uint16_t>> leads_to(sm.states.size());  // per state, where its transitions go
      for (const TransitionDef& t : sm.transitions) {
        if (t.from < 0 && !reached[t.to]) reached[t.to] = true, stack.push_back(t.to);  // "any" leaves every state
        if (t.from >= 0) leads_to[static_cast<size_t>(t.from)].push_back(t.to);
      }
      while (!stack.empty()) {
        const size_t s = stack.back();
        stack.pop_back();
        for (const uint16_t to : leads_to[s])
          if (!reached[to]) reached[to] = true, stack.push_back(to);
      }
      for (size_t s = 0; s < sm.states.size(); ++s)
        if (!reached[s])
          ok = check_.error(state_pos[s], "state '" + sm.states[s].name + "' of " + label +
                                              " cannot be reached: no transition leads to it from the entry state '" +
                                              sm.states[sm.entry].name + "'");
    }
    if (!ok) return -1;
    g_.machines[machine_index] = std::move(sm);
    return emit(name, StateMachineRefDef{static_cast<uint16_t>(machine_index)});
  }

  template <class StateIndex, class UnknownState>
  bool transition(const Value& t, const StateIndex& state_index, const UnknownState& unknown_state, TransitionDef& out,
                  long long& priority) {
    if (!check_.expect(t, Type::Object, "a transition")) return false;
    check_.expect_keys(t, {"from", "to", "when", "exit_time", "duration", "mode", "priority"}, "a transition");
    bool ok = true;
    if (const Value* from = required(t, "from", "a transition (a state name or \"any\")")) {
      if (!check_.expect(*from, Type::String, "\"from\"")) {
        ok = false;
      } else if (from->string == "any") {
        out.from = -1;
      } else {
        const int s = state_index(from->string);
        if (s < 0) ok = unknown_state(*from, "\"from\"");
        out.from = static_cast<int16_t>(s);
      }
    } else {
      ok = false;
    }
    if (const Value* to = required(t, "to", "a transition")) {
      if (!check_.expect(*to, Type::String, "\"to\"")) {
        ok = false;
      } else {
        const int s = state_index(to->string);
        if (s < 0) ok = unknown_state(*to, "\"to\"");
        out.to = static_cast<uint16_t>(std::max(s, 0));
      }
    } else {
      ok = false;
    }
    if (ok && out.from >= 0 && out.from == static_cast<int>(out.to))
      ok = check_.error(t.find("to")->pos, "a transition from state '" + t.find("to")->string +
                                               "' to itself: a state cannot transition to itself (\"restart\" on the "
                                               "state replays it when it is entered again)");
    if (const Value* when = t.find("when")) {
      if (check_.expect(*when, Type::String, "\"when\" (a condition)")) {
        ConditionResult c = compile_condition(when->string, g_.parameters, &param_index_, !check_.full());
        if (!c.ok) {
          ok = check_.error_in_string(*when, c.error_offset, c.error);
        } else {
          for (const CondInstr& instr : c.code)  // a parameter already reported wrong is not re-checked
            if (instr.op != CondOp::True && instr.op < CondOp::Not && param_bad_[instr.parameter]) ok = false;
          out.condition = std::move(c.code);
        }
      } else {
        ok = false;
      }
    }
    if (const Value* e = t.find("exit_time")) {
      ok &= read_float(*e, "\"exit_time\" (normalized time of the source state; leave it out for none)", &out.exit_time,
                       0.0, kMaxSeconds);
    }
    if (const Value* d = t.find("duration"))
      ok &= read_float(*d, "\"duration\" (seconds)", &out.duration, 0.0, kMaxSeconds);
    if (const Value* mode = t.find("mode")) {
      static const std::vector<std::string_view> kModes = {"crossfade", "sync_crossfade", "inertialize"};
      if (!check_.expect(*mode, Type::String, "\"mode\"")) {
        ok = false;
      } else if (const auto at = std::find(kModes.begin(), kModes.end(), mode->string); at != kModes.end()) {
        out.mode = static_cast<TransitionModeDef>(at - kModes.begin());
      } else {
        const std::string hint = json::closest_name(mode->string, kModes);
        ok = check_.error(mode->pos, "unknown transition mode '" + mode->string + "'" +
                                         (hint.empty() ? "" : " (did you mean '" + hint + "'?)") +
                                         "; modes: crossfade, sync_crossfade, inertialize");
      }
    }
    if (const Value* p = t.find("priority"))
      ok &= check_.expect_integer(*p, "\"priority\" (lower is checked first)", -1000000000, 1000000000, &priority);
    return ok;
  }
};

}  // namespace

Result<GraphManifest> read_graph_manifest(const json::Document& doc) {
  Checker check(doc);
  GraphManifest out;
  read_manifest(check, doc.root, out);
  if (!check.ok()) return Error{check.message()};
  return out;
}

Result<CompiledGraph> compile_graph(const json::Document& doc, const GraphContext& context) {
  return GraphCompiler(doc, context).run();
}

Result<CompiledGraph> compile_graph(std::string_view text, std::string file, const GraphContext& context) {
  auto doc = json::parse(text, std::move(file));
  if (!doc) return doc.error();
  return compile_graph(*doc, context);
}

}  // namespace ossa::cook
