// graph_compile_nodes.cpp — the graph compiler's node dispatch (node, use) and the blend-tree nodes:
// clip, blend, select, layered, blend space, additive, morph (the class is in graph_compiler.h). A file
// of its own because these nodes read only parameters, clips and other nodes.
#include "cooker/graph/graph_compiler.h"
#include <ossa/anim/blend_space.h>
#include <ossa/loader/validate.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>
#include <unordered_set>

namespace ossa::cook::graph_detail {

// ---- nodes ---------------------------------------------------------------------------------
int GraphCompiler::emit(std::string name, NodeKind kind) {
  g_.nodes.push_back({std::move(name), std::move(kind)});
  return static_cast<int>(g_.nodes.size() - 1);
}

int GraphCompiler::node(const Value& v, const std::string& default_name) {
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
            v,
            {"clip", "blend", "select", "layered", "blend_space", "additive", "state_machine", "morph", "use",
             "two_bone_ik", "aim", "foot_placement", "foot_lock", "spring", "slot", "retarget", "name"},
            "a node"))
      check_.error(v.pos,
                   "a node needs one of the keys clip, blend, select, layered, blend_space, additive, "
                   "state_machine, morph, two_bone_ik, aim, foot_placement, foot_lock, spring, slot, retarget, use");
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
  else if (k == "retarget") index = retarget_node(v, name);
  else index = use_node(v, name, v.find("name") != nullptr);
  --depth_;
  output_depth_ -= output ? 1 : 0;
  return index;
}

int GraphCompiler::retarget_node(const Value& v, const std::string& name) {
  check_.expect_keys(v, {"retarget", "rig", "map", "rate", "rate_parameter", "loop", "start", "contacts", "name"},
                     "a retarget node");
  RetargetNodeDef r;
  bool ok = true;
  const Value& clip_name = *v.find("retarget");
  if (!check_.expect(clip_name, Type::String, "\"retarget\" (the name of a clip of the source rig)")) ok = false;
  else if (clip_name.string.empty()) ok = check_.error(clip_name.pos, "\"retarget\" names no clip");
  else if (clip_index_.count(clip_name.string) != 0)
    ok = check_.error(clip_name.pos, "clip '" + clip_name.string +
                                         "' is one of the graph's own clips (\"clips\"), made for its rig; a retarget "
                                         "node plays a clip of another rig, by a name of its own");
  const Value* rig = required(v, "rig", "a retarget node");
  std::string map;
  if (const Value* m = v.find("map")) {
    if (check_.expect(*m, Type::String, "\"map\" (a humanoid map file)")) map = m->string;
    else ok = false;
  }
  if (const Value* x = v.find("rate")) ok &= read_float(*x, "\"rate\"", &r.rate, -kMaxRate, kMaxRate);
  if (const Value* p = v.find("rate_parameter")) {
    const int param = parameter(*p, {ParamType::Float, ParamType::Int}, "\"rate_parameter\"");
    ok &= param >= 0;
    r.rate_parameter = static_cast<int16_t>(param);
  }
  if (const Value* l = v.find("loop")) ok &= read_bool(*l, "\"loop\"", &r.loop);
  if (const Value* c = v.find("contacts")) ok &= read_bool(*c, "\"contacts\"", &r.contacts);
  if (const Value* s = v.find("start")) ok &= read_float(*s, "\"start\" (seconds)", &r.start_offset, 0.0, kMaxSeconds);
  if (!rig || !check_.expect(*rig, Type::String, "\"rig\" (the source rig: its cooked .ossa or a source file)"))
    return -1;
  if (!ctx_.retarget_rigs) return check_.error(v.pos, "retarget nodes need the cooker to load their rigs"), -1;
  // Each rig and map pair is loaded once (a named node is compiled again when checked unused).
  auto key = std::make_pair(rig->string, map);
  auto cached = retarget_rigs_.find(key);
  if (cached == retarget_rigs_.end()) cached = retarget_rigs_.emplace(key, ctx_.retarget_rigs(rig->string, map)).first;
  const Result<GraphRetargetRigs>& rigs = cached->second;
  if (!rigs) return check_.error(rig->pos, "retarget node: " + rigs.error().message), -1;
  if (!ok) return -1;
  r.source_skeleton_hash = rigs->source_skeleton_hash;
  r.source_joint_count = rigs->source_joint_count;
  r.source_bones = rigs->source_bones;
  r.target_bones = rigs->target_bones;
  r.source_rest = rigs->source_rest;
  r.target_rest = rigs->target_rest;
  r.source_rest_rotations = rigs->source_rest_rotations;
  r.target_rest_rotations = rigs->target_rest_rotations;
  // The clip: a graph clip of its own, after the graph's own clips, resolved at run time among the
  // clip files given. An unused node's check (thrown away) adds none.
  if (checking_unused_) return emit(name, std::move(r));
  auto found = retarget_clip_index_.find(clip_name.string);
  if (found == retarget_clip_index_.end()) {
    if (g_.clips.size() >= kMaxGraphClips) return check_.error(clip_name.pos, "too many clips"), -1;
    found = retarget_clip_index_.emplace(clip_name.string, static_cast<int>(g_.clips.size())).first;
    g_.clips.push_back(clip_name.string);
    clip_events_.emplace_back();
    clip_duration_.push_back(0.0f);
    clip_used_.push_back(true);
    clip_pos_.push_back(clip_name.pos);
  }
  r.clip = static_cast<uint16_t>(found->second);
  return emit(name, std::move(r));
}

int GraphCompiler::use_node(const Value& v, const std::string& name, bool named_here) {
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

int GraphCompiler::clip_node(const Value& v, const std::string& name) {
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

int GraphCompiler::blend_node(const Value& v, const std::string& name) {
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

int GraphCompiler::select_node(const Value& v, const std::string& name) {
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

int GraphCompiler::joint(const Value& v, const std::string& role) {
  if (!check_.expect(v, Type::String, role + "'s \"joint\"")) return -1;
  if (!ctx_.skeleton) return -1;
  const auto& joints = ctx_.skeleton->joints;
  if (joint_index_.empty())
    for (size_t j = joints.size(); j-- > 0;) joint_index_[joints[j].name] = static_cast<int>(j);  // the first of a name
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

int GraphCompiler::layered_node(const Value& v, const std::string& name) {
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
    check_.expect_keys(
        lv, {"node", "mask", "weight", "weight_parameter", "blend_time", "mesh_space_rotation", "morph_targets"},
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

int GraphCompiler::blend_space_node(const Value& v, const std::string& name) {
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

int GraphCompiler::additive_node(const Value& v, const std::string& name) {
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

int GraphCompiler::morph_node(const Value& v, const std::string& name) {
  check_.expect_keys(v, {"morph", "drives", "name"}, "a morph node");
  MorphWeightsDef m;
  const int input = node(*v.find("morph"), "");
  bool ok = input >= 0;
  const Value* drives = required(v, "drives", "a morph node");
  if (!drives || !check_.expect(*drives, Type::Array, "\"drives\" ([{\"target\": ..., \"parameter\": ...}, ...])"))
    return -1;
  if (drives->items.empty())
    ok = check_.error(drives->pos, "\"drives\" is empty: a morph node sets at least one target");
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

}  // namespace ossa::cook::graph_detail
