// graph_compile_procedural.cpp — the graph compiler's procedural nodes (format v6): two-bone IK, aim,
// foot placement and foot lock, spring, with their length/angle readers and rig checks (the class is in
// graph_compiler.h). A file of its own because these nodes read joints and the rig's units.
#include "cooker/graph/graph_compiler.h"
#include <ossa/anim/blend_space.h>
#include <ossa/loader/validate.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>
#include <unordered_set>

namespace ossa::cook::graph_detail {

// ---- procedural nodes (format v6) ----------------------------------------------------------
// Lengths in the graph file are metres (converted to the rig's units), angles degrees.
double GraphCompiler::units() const {
  const double mpu = ctx_.skeleton ? ctx_.skeleton->metres_per_unit : 0.0;
  return mpu > 0.0 ? 1.0 / mpu : 1.0;
}

bool GraphCompiler::read_vec3(const Value& v, const std::string& what, double scale, Vec3Def* out) {
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

bool GraphCompiler::read_length(const Value& v, const std::string& what, float* out, double lo) {
  float metres = 0.0f;
  if (!read_float(v, what + " (metres)", &metres, lo, 1e6)) return false;
  *out = static_cast<float>(metres * units());
  return true;
}

bool GraphCompiler::read_degrees(const Value& v, const std::string& what, float* out, double lo, double hi) {
  float deg = 0.0f;
  if (!read_float(v, what + " (degrees)", &deg, lo, hi)) return false;
  *out = static_cast<float>(deg * kDegrees);
  return true;
}

bool GraphCompiler::read_weight(const Value& v, float* weight, int16_t* weight_parameter) {
  bool ok = true;
  if (const Value* w = v.find("weight")) ok &= read_float(*w, "\"weight\"", weight, 0.0, 1.0);
  if (const Value* p = v.find("weight_parameter")) {
    const int param = parameter(*p, {ParamType::Float, ParamType::Bool}, "\"weight_parameter\"");
    ok &= param >= 0;
    *weight_parameter = static_cast<int16_t>(param);
  }
  return ok;
}

int GraphCompiler::joint_member(const Value& v, std::string_view key, const std::string& what) {
  const Value* j = required(v, key, what);
  return j ? joint(*j, what + " \"" + std::string(key) + "\"") : -1;
}

glm::quat GraphCompiler::bind_rotation(uint32_t j) const {
  glm::quat r(1.0f, 0.0f, 0.0f, 0.0f);
  for (int k = static_cast<int>(j); k >= 0; k = ctx_.skeleton->joints[static_cast<size_t>(k)].parent)
    r = ctx_.skeleton->joints[static_cast<size_t>(k)].rotation * r;
  return r;
}

bool GraphCompiler::ancestor(int a, int b) const {
  if (!ctx_.skeleton || a < 0 || b < 0) return true;  // reported elsewhere
  for (int j = ctx_.skeleton->joints[static_cast<size_t>(b)].parent; j >= 0;
       j = ctx_.skeleton->joints[static_cast<size_t>(j)].parent)
    if (j == a) return true;
  return false;
}

bool GraphCompiler::check_chain(const Value& at, std::initializer_list<int> joints, const std::string& what) {
  const int* prev = nullptr;
  for (const int& j : joints) {
    if (prev && *prev >= 0 && j >= 0 && !ancestor(*prev, j))
      return check_.error(at.pos, what + ": joint '" + ctx_.skeleton->joints[static_cast<size_t>(*prev)].name +
                                      "' is not an ancestor of '" + ctx_.skeleton->joints[static_cast<size_t>(j)].name +
                                      "'");
    prev = &j;
  }
  return true;
}

int GraphCompiler::two_bone_node(const Value& v, const std::string& name) {
  const std::string what = "a two_bone_ik node";
  check_.expect_keys(v,
                     {"two_bone_ik", "start", "mid", "end", "target", "pole", "mid_axis", "twist", "soften", "weight",
                      "weight_parameter", "name"},
                     what);
  TwoBoneIkDef t;
  const int input = node(*v.find("two_bone_ik"), "");
  bool ok = input >= 0;
  const int start = joint_member(v, "start", what), mid = joint_member(v, "mid", what),
            end = joint_member(v, "end", what);
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

int GraphCompiler::aim_node(const Value& v, const std::string& name) {
  const std::string what = "an aim node";
  check_.expect_keys(v, {"aim", "chain", "target", "forward", "up", "pole", "weight", "weight_parameter", "name"},
                     what);
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
    if (const Value* m = e.find("max_angle"))
      ok &= read_degrees(*m, "an aim joint's \"max_angle\"", &j.max_angle, 0.0, 180.0);
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

bool GraphCompiler::read_legs(const Value& v, bool lock, std::vector<FootLegDef>* out) {
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
    if (lock)
      check_.expect_keys(e, {"hip", "knee", "ankle", "planted", "plant_event", "lift_event"}, "a foot_lock leg");
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
      if (!check_.expect(*ev, Type::String, std::string("a leg's \"") + key + "\" (an event name)") ||
          ev->string.empty()) {
        ok =
            ok && ev->is(Type::String) ? check_.error(ev->pos, std::string("a leg's \"") + key + "\" is empty") : false;
        continue;
      }
      (std::string_view(key) == "plant_event" ? leg.plant_event : leg.lift_event) = ev->string;
    }
    if (lock && leg.planted_parameter < 0 && (leg.plant_event.empty() || leg.lift_event.empty()))
      ok = check_.error(e.pos,
                        "a foot_lock leg needs \"planted\" (a parameter) or both \"plant_event\" and \"lift_event\"");
    out->push_back(std::move(leg));
  }
  return ok;
}

int GraphCompiler::foot_node(const Value& v, const std::string& name, bool lock) {
  const std::string what = lock ? "a foot_lock node" : "a foot_placement node";
  if (lock)
    check_.expect_keys(v, {"foot_lock", "legs", "release_radius", "blend_time", "weight", "weight_parameter", "name"},
                       what);
  else
    check_.expect_keys(v,
                       {"foot_placement", "pelvis", "legs", "up", "max_pelvis_drop", "align", "soften", "weight",
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
    if (const Value* b = v.find("blend_time"))
      ok &= read_float(*b, "\"blend_time\" (seconds)", &f.blend_time, 0.0, 1e6);
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

int GraphCompiler::spring_node(const Value& v, const std::string& name) {
  const std::string what = "a spring node";
  check_.expect_keys(
      v, {"spring", "chains", "colliders", "step", "teleport_distance", "weight", "weight_parameter", "name"}, what);
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
    if (const Value* x = c.find("stiffness"))
      ok &= read_float(*x, "\"stiffness\" (per second)", &chain.stiffness, 0.0, 1e4);
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
      if (const Value* x = c.find("offset"))
        ok &= read_vec3(*x, "a collider's \"offset\" (metres)", units(), &col.offset);
      col.tail = col.offset;
      if (const Value* x = c.find("tail")) ok &= read_vec3(*x, "a collider's \"tail\" (metres)", units(), &col.tail);
      if (const Value* r = required(c, "radius", "a collider"))
        ok &= read_length(*r, "a collider's \"radius\"", &col.radius);
      else ok = false;
      sp.colliders.push_back(col);
    }
  }
  if (const Value* x = v.find("step")) ok &= read_float(*x, "\"step\" (seconds)", &sp.step, 1e-4, 1.0);
  if (const Value* x = v.find("teleport_distance"))
    ok &= read_length(*x, "\"teleport_distance\"", &sp.teleport_distance);
  ok &= read_weight(v, &sp.weight, &sp.weight_parameter);
  if (!ok) return -1;
  sp.input = static_cast<uint16_t>(input);
  return emit(name, std::move(sp));
}

}  // namespace ossa::cook::graph_detail
