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

#include "cooker/graph/graph_compiler.h"
#include <ossa/anim/blend_space.h>
#include <ossa/loader/validate.h>

namespace ossa::cook {
namespace graph_detail {

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
  check.expect_keys(root,
                    {"ossa_graph", "name", "skeleton", "meshes", "clips", "parameters", "nodes", "root", "montages"},
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
      else check.error(skeleton->pos, "\"skeleton\" needs a \"source\": the rig's source file");
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

void GraphCompiler::warn(Pos pos, const std::string& what) {
  warnings_.push_back(json::where(check_.doc().file, pos) + what);
}

// ---- small readers -----------------------------------------------------------------------
bool GraphCompiler::read_float(const Value& v, const std::string& what, float* out, double lo, double hi) {
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

bool GraphCompiler::read_bool(const Value& v, const std::string& what, bool* out) {
  if (!check_.expect(v, Type::Bool, what)) return false;
  *out = v.boolean;
  return true;
}

int GraphCompiler::parameter(const Value& v, std::initializer_list<ParamType> allowed, const std::string& role) {
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

int GraphCompiler::clip(const Value& v, const std::string& role) {
  if (!check_.expect(v, Type::String, role + " (a clip name)")) return -1;
  if (const auto found = clip_index_.find(v.string); found != clip_index_.end()) {
    clip_used_[static_cast<size_t>(found->second)] = true;
    return found->second;
  }
  if (retarget_clip_index_.count(v.string) != 0)
    return check_.error(v.pos, "clip '" + v.string +
                                   "' is a retarget node's clip of another rig; only retarget nodes "
                                   "play it"),
           -1;
  if (check_.full()) return check_.error(v.pos, "unknown clip '" + v.string + "'"), -1;
  const std::string hint = json::closest_name(v.string, g_.clips);
  check_.error(v.pos, "unknown clip '" + v.string + "'" + (hint.empty() ? "" : " (did you mean '" + hint + "'?)") +
                          (g_.clips.empty() ? "; \"clips\" declares none" : "; clips: " + quoted(g_.clips)));
  return -1;
}

const Value* GraphCompiler::required(const Value& object, std::string_view key, const std::string& what) {
  const Value* v = object.find(key);
  if (!v) check_.error(object.pos, what + " needs \"" + std::string(key) + "\"");
  return v;
}

// ---- top level ---------------------------------------------------------------------------
void GraphCompiler::read_skeleton() {
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

void GraphCompiler::read_clips(const Value& root, const GraphManifest& manifest) {
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
      if (list && list->is(Type::Array)) read_event_list(check_, *list, duration, "clip '" + entry.name + "'", events);
      sort_events(events);
    }
    clip_events_.push_back(std::move(events));
    clip_duration_.push_back(duration);
  }
  for (size_t c = 0; c < g_.clips.size(); ++c) clip_index_.emplace(g_.clips[c], static_cast<int>(c));
}

void GraphCompiler::read_parameters(const Value* params) {
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

bool GraphCompiler::read_parameter(const Member& m, GraphParameter& p) {
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
      if (def)
        ok &= read_vec3(*def, what + (direction ? " \"default\"" : " \"default\" (metres)"), direction ? 1.0 : units(),
                        &d);
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

void GraphCompiler::read_named_nodes(const Value* nodes) {
  if (!nodes || !check_.expect(*nodes, Type::Object, "\"nodes\" (named nodes)")) return;
  for (const Member& m : nodes->members) {
    if (m.key.empty()) check_.error(m.key_pos, "a named node's name must not be empty");
    named_index_.emplace(m.key, named_.size());
    named_.push_back({&m, 0});
  }
}

void GraphCompiler::check_unused() {
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

}  // namespace graph_detail

using graph_detail::Checker;
using graph_detail::GraphCompiler;
using graph_detail::read_manifest;

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
