// diff_skeleton.cpp — the skeleton section of ossa-diff: joints added, removed, renamed or moved
// in the order, parents changed, and bind poses compared joint by joint.
//
// The bind pose is judged on each joint's LOCAL transform, with the same probe measure the clips
// use (<ossa/anim/pose_error.h>): the six points at 10 cm around the joint, placed by the old and by
// the new local transform. Judging model space instead would name a moved joint and every joint
// below it; the local measure names the joint whose data changed, in millimetres a player would
// see at that joint, and folds translation, rotation and scale into one figure the tolerance can
// apply to. The separate translation / rotation / scale figures are reported alongside.
#include <algorithm>
#include <cmath>
#include <string>

#include <glm/gtc/quaternion.hpp>

#include <ossa/anim/pose_error.h>
#include "common/message.h"
#include "tools/diff/diff_internal.h"

namespace ossa::diff::internal {
namespace {

constexpr const char* kSection = "skeleton";

std::vector<std::string> joint_names(const SkeletonView& s) {
  std::vector<std::string> names;
  names.reserve(s.joint_count());
  for (size_t i = 0; i < s.joint_count(); ++i) names.emplace_back(s.joint_name(i));
  return names;
}

struct LocalBind {
  glm::vec3 t, s;
  glm::quat r;
};

LocalBind local_bind(const SkeletonView& s, size_t j, double to_old_units) {
  const fb::Vec3& t = s.bind_translations()[j];
  const fb::Quat& r = s.bind_rotations()[j];
  const fb::Vec3& sc = s.bind_scales()[j];
  const auto k = static_cast<float>(to_old_units);
  return {glm::vec3(t.x(), t.y(), t.z()) * k, glm::vec3(sc.x(), sc.y(), sc.z()), glm::quat(r.w(), r.x(), r.y(), r.z())};
}

/// Angle of the rotation taking a to b, in degrees (double, shortest arc). From the chord between
/// the unit quaternions (4 asin(|a - b| / 2)) rather than acos(dot): exact 0 for equal rotations
/// and accurate for small angles, where acos loses half the digits.
double rotation_angle_deg(const glm::quat& a, const glm::quat& b) {
  glm::dquat qa(a), qb(b);
  const double la = glm::length(qa), lb = glm::length(qb);
  if (la == 0.0 || lb == 0.0) return la == lb ? 0.0 : 180.0;
  qa = qa / la;
  qb = qb / lb;
  if (glm::dot(qa, qb) < 0.0) qb = -qb;
  const glm::dvec4 chord(qa.x - qb.x, qa.y - qb.y, qa.z - qb.z, qa.w - qb.w);
  return glm::degrees(4.0 * std::asin(std::min(1.0, glm::length(chord) / 2.0)));
}

JointBind compare_bind(const Context& c, const SkeletonView& a, size_t i, const SkeletonView& b, size_t k) {
  const LocalBind x = local_bind(a, i, 1.0), y = local_bind(b, k, c.new_to_old());
  JointBind jb;
  jb.name = std::string(a.joint_name(i));
  jb.translation_mm = glm::length(glm::dvec3(x.t) - glm::dvec3(y.t)) * c.old_mm();
  jb.rotation_deg = rotation_angle_deg(x.r, y.r);
  const glm::dvec3 ds = glm::abs(glm::dvec3(x.s) - glm::dvec3(y.s));
  jb.scale_delta = std::max({ds.x, ds.y, ds.z});
  jb.probe_mm =
      probe_error(affine_from_trs(x.t, x.r, x.s), affine_from_trs(y.t, y.r, y.s), c.probe_old_units()) * c.old_mm();
  return jb;
}

std::string parent_name(const SkeletonView& s, int parent) {
  return parent < 0 ? std::string() : std::string(s.joint_name(static_cast<size_t>(parent)));
}

}  // namespace

void compare_skeletons(Context& c) {
  SkeletonSection& out = c.report.skeleton;
  const SkeletonView a = c.old_asset.skeleton(), b = c.new_asset.skeleton();
  out.old_present = !a.empty();
  out.new_present = !b.empty();
  if (!a.empty()) out.old_joints = a.joint_count(), out.old_hash = a.hash();
  if (!b.empty()) out.new_joints = b.joint_count(), out.new_hash = b.hash();
  if (a.empty() || b.empty()) {
    if (a.empty() != b.empty())
      c.add_text(kSection, "", a.empty() ? "added" : "removed",
                 std::to_string(a.empty() ? out.new_joints : out.old_joints) + " joints",
                 a.empty() ? "only the new file has a skeleton" : "only the old file has a skeleton");
    return;
  }
  if (out.old_hash != out.new_hash)
    c.add_text(kSection, "", "hash",
               detail::format("%016llx -> %016llx", static_cast<unsigned long long>(out.old_hash),
                              static_cast<unsigned long long>(out.new_hash)),
               "clips cooked for one rig do not bind to the other");

  const JointMapping m = map_joints(a, b);
  const std::vector<std::string> old_names = joint_names(a), new_names = joint_names(b);
  for (const auto& [i, k] : m.renamed) {
    out.renamed.emplace_back(old_names[static_cast<size_t>(i)], new_names[static_cast<size_t>(k)]);
    c.add_text(kSection, item_label(old_names, static_cast<size_t>(i)), "renamed",
               quote_name(old_names[static_cast<size_t>(i)]) + " -> " + quote_name(new_names[static_cast<size_t>(k)]),
               "joint " + std::to_string(i));
  }
  std::vector<bool> new_taken(b.joint_count(), false);
  for (size_t i = 0; i < m.old_to_new.size(); ++i) {
    if (m.old_to_new[i] >= 0) {
      new_taken[static_cast<size_t>(m.old_to_new[i])] = true;
      continue;
    }
    out.removed.push_back(item_label(old_names, i));
    c.add_text(kSection, out.removed.back(), "removed", "only in the old skeleton", "joint " + std::to_string(i));
  }
  for (size_t k = 0; k < new_taken.size(); ++k) {
    if (new_taken[k]) continue;
    out.added.push_back(item_label(new_names, k));
    c.add_text(kSection, out.added.back(), "added", "only in the new skeleton", "joint " + std::to_string(k));
  }

  // Order: a paired joint that comes before a joint it used to follow has moved.
  int highest = -1;
  for (size_t i = 0; i < m.old_to_new.size(); ++i) {
    const int k = m.old_to_new[i];
    if (k < 0) continue;
    if (k < highest) out.reordered.push_back(item_label(old_names, i));
    highest = std::max(highest, k);
  }
  if (!out.reordered.empty()) {
    std::string list;
    for (size_t n = 0; n < out.reordered.size() && n < 5; ++n) list += (n ? ", " : "") + quote_name(out.reordered[n]);
    if (out.reordered.size() > 5) list += ", ...";
    c.add_text(kSection, "", "joint order", std::to_string(out.reordered.size()) + " joints moved", list);
  }

  const auto old_parents = a.parents(), new_parents = b.parents();
  for (size_t i = 0; i < m.old_to_new.size(); ++i) {
    const int k = m.old_to_new[i];
    if (k < 0) continue;
    const int p_old = old_parents[i], p_new = new_parents[static_cast<size_t>(k)];
    const int expected = p_old < 0 ? -1 : m.old_to_new[static_cast<size_t>(p_old)];
    if (expected == p_new && (p_old < 0) == (p_new < 0)) continue;
    SkeletonSection::ParentChange pc{old_names[i], parent_name(a, p_old), parent_name(b, p_new)};
    c.add_text(kSection, item_label(old_names, i), "parent",
               (pc.old_parent.empty() ? "(root)" : quote_name(pc.old_parent)) + " -> " +
                   (pc.new_parent.empty() ? "(root)" : quote_name(pc.new_parent)));
    out.parent_changed.push_back(std::move(pc));
  }

  for (size_t i = 0; i < m.old_to_new.size(); ++i) {
    const int k = m.old_to_new[i];
    if (k < 0) continue;
    JointBind jb = compare_bind(c, a, i, b, static_cast<size_t>(k));
    if (out.bind.empty() || jb.probe_mm > out.max_bind_mm) {
      out.max_bind_mm = jb.probe_mm;
      out.worst_joint = jb.name;
    }
    if (jb.probe_mm > c.tolerance_mm)
      c.add_figure(kSection, item_label(old_names, i), "bind pose", jb.probe_mm, "mm", c.tolerance_mm,
                   "translation " + num(jb.translation_mm) + " mm, rotation " + num(jb.rotation_deg) + " deg, scale " +
                       num(jb.scale_delta));
    out.bind.push_back(std::move(jb));
  }
}

}  // namespace ossa::diff::internal
