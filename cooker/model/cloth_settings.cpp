// cloth_settings.cpp — the "cloth" cook setting (see cloth_settings.h for the shape).
#include "cooker/model/cloth_settings.h"

#include <cmath>
#include <cstdio>

namespace ossa::cook {
namespace {

bool number_in(json::Checker& check, const json::Value& v, const std::string& what, double lo, double hi, float* out) {
  double x = 0.0;
  if (!check.expect_number(v, what, &x)) return false;
  if (!(x >= lo && x <= hi)) {
    char range[96];
    std::snprintf(range, sizeof range, " must be within [%g, %g]", lo, hi);
    return check.error(v.pos, what + range);
  }
  *out = static_cast<float>(x);
  return true;
}

bool vec3_in(json::Checker& check, const json::Value& v, const std::string& what, glm::vec3* out) {
  if (!check.expect(v, json::Type::Array, what)) return false;
  if (v.items.size() != 3) return check.error(v.pos, what + " must be [x, y, z]");
  for (size_t k = 0; k < 3; ++k)
    if (!number_in(check, v.items[k], what, -100.0, 100.0, &(*out)[static_cast<int>(k)])) return false;
  return true;
}

void read_region(json::Checker& check, const json::Value& v, ClothRegion& r) {
  if (!check.expect(v, json::Type::Object, "a \"regions\" entry")) return;
  check.expect_keys(v, {"mesh", "material", "pin_joints", "pin_within", "ramp"}, "a \"regions\" entry");
  const json::Value* mesh = v.find("mesh");
  const json::Value* material = v.find("material");
  if ((mesh != nullptr) == (material != nullptr)) {
    check.error(v.pos, "a \"regions\" entry names exactly one of \"mesh\" and \"material\"");
    return;
  }
  if (mesh) check.expect_name(*mesh, "\"mesh\"", &r.mesh);
  if (material) check.expect_name(*material, "\"material\"", &r.material);
  if (const json::Value* pins = v.find("pin_joints"); pins && check.expect(*pins, json::Type::Array, "\"pin_joints\""))
    for (const json::Value& p : pins->items) {
      std::string name;
      if (check.expect_name(p, "a pin joint", &name)) r.pin_joints.push_back(name);
    }
  if (const json::Value* w = v.find("pin_within")) number_in(check, *w, "\"pin_within\"", 0.0, 10.0, &r.pin_within_m);
  if (const json::Value* w = v.find("ramp")) number_in(check, *w, "\"ramp\"", 1e-6, 100.0, &r.ramp_m);
}

void read_collider(json::Checker& check, const json::Value& v, ClothColliderSetting& c) {
  if (!check.expect(v, json::Type::Object, "a \"colliders\" entry")) return;
  check.expect_keys(v, {"joint", "to", "offset", "tail", "radius"}, "a \"colliders\" entry");
  const json::Value* joint = v.find("joint");
  if (!joint) {
    check.error(v.pos, "a \"colliders\" entry needs \"joint\"");
    return;
  }
  check.expect_name(*joint, "\"joint\"", &c.joint);
  if (const json::Value* to = v.find("to")) check.expect_name(*to, "\"to\"", &c.to);
  if (const json::Value* o = v.find("offset")) vec3_in(check, *o, "\"offset\"", &c.offset_m);
  if (const json::Value* t = v.find("tail")) c.has_tail = vec3_in(check, *t, "\"tail\"", &c.tail_m);
  if (v.find("to") && v.find("tail")) check.error(v.pos, "a \"colliders\" entry has \"to\" or \"tail\", not both");
  const json::Value* radius = v.find("radius");
  if (!radius) check.error(v.pos, "a \"colliders\" entry needs \"radius\" (metres)");
  else number_in(check, *radius, "\"radius\"", 0.0, 100.0, &c.radius_m);
}

}  // namespace

bool read_cloth_settings(json::Checker& check, const json::Value& value, ClothOptions& out) {
  if (!check.expect(value, json::Type::Object, "\"cloth\"")) return false;
  const size_t errors = check.errors().size();
  check.expect_keys(value,
                    {"paint", "regions", "max_distance", "backstop", "thickness", "stretch_compliance",
                     "bend_compliance", "tether_scale", "damping", "drag", "gravity", "linear_inertia",
                     "angular_inertia", "teleport_distance", "max_speed", "colliders", "max_colliders"},
                    "\"cloth\"");
  ClothOptions o;
  o.up_axis = out.up_axis;
  o.from_settings = true;
  for (const json::Member& m : value.members) {
    const std::string what = "\"" + m.key + "\"";
    const json::Value& v = m.value;
    const struct {
      const char* key;
      float* field;
      double lo, hi;
    } numbers[] = {{"max_distance", &o.max_distance_m, 0.0, 100.0},
                   {"backstop", &o.backstop_m, 0.0, 100.0},
                   {"thickness", &o.thickness_m, 0.0, 1.0},
                   {"stretch_compliance", &o.stretch_compliance, 0.0, 1e6},
                   {"bend_compliance", &o.bend_compliance, 0.0, 1e6},
                   {"tether_scale", &o.tether_scale, 1.0, 2.0},
                   {"damping", &o.damping, 0.0, 1000.0},
                   {"drag", &o.drag, 0.0, 1000.0},
                   {"gravity", &o.gravity_ms2, -1000.0, 1000.0},
                   {"linear_inertia", &o.linear_inertia, 0.0, 1.0},
                   {"angular_inertia", &o.angular_inertia, 0.0, 1.0},
                   {"teleport_distance", &o.teleport_distance_m, 0.0, 1e6},
                   {"max_speed", &o.max_speed_ms, 0.0, 1e6}};
    bool known = false;
    for (const auto& n : numbers)
      if (m.key == n.key) {
        known = true;
        number_in(check, v, what, n.lo, n.hi, n.field);
      }
    if (known) continue;
    if (m.key == "paint") {
      if (check.expect(v, json::Type::Bool, what)) o.paint = v.boolean;
    } else if (m.key == "regions") {
      if (check.expect(v, json::Type::Array, what))
        for (const json::Value& r : v.items) read_region(check, r, o.regions.emplace_back());
    } else if (m.key == "colliders") {
      if (v.is(json::Type::String)) {
        if (v.string == "auto") o.auto_colliders = true;
        else if (v.string == "none") o.auto_colliders = false;
        else check.error(v.pos, what + " must be \"auto\", \"none\" or a list of colliders");
      } else if (check.expect(v, json::Type::Array, what)) {
        for (const json::Value& c : v.items) read_collider(check, c, o.colliders.emplace_back());
      }
    } else if (m.key == "max_colliders") {
      long long count = 0;
      if (check.expect_integer(v, what, 0, 32, &count)) o.max_colliders = static_cast<uint32_t>(count);
    }
  }
  if (check.errors().size() != errors) return false;
  out = std::move(o);
  return true;
}

std::string ClothOptions::canonical() const {
  // Settings files are inputs of the cook key already; this records the values in the output.
  if (!from_settings) return "";
  char buf[512];
  std::snprintf(buf, sizeof buf, ";cloth=%d,%zu,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%d,%zu,%u", paint ? 1 : 0,
                regions.size(), double(max_distance_m), double(backstop_m), double(thickness_m),
                double(stretch_compliance), double(bend_compliance), double(tether_scale), double(damping),
                double(drag), double(gravity_ms2), double(linear_inertia), double(angular_inertia),
                double(teleport_distance_m), double(max_speed_ms), auto_colliders ? 1 : 0, colliders.size(),
                max_colliders);
  return buf;
}

}  // namespace ossa::cook
