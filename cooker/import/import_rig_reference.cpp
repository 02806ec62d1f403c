// import_rig_reference.cpp — clip-only cooking: a source's nodes mapped onto a reference rig
// (ImportOptions::reference, --skeleton) instead of a skeleton of its own.
//
// File nodes are matched to the reference's joints by name (exactly, then loosely: exporters
// rewrite names), each matched joint's chain runs from the nearest matched ancestor down, so
// anything in between (helpers, nodes the reference lacks) is folded into the keys of the joint
// below it; what the file animates or skins that the reference lacks is an error naming it. The
// file's own rig (import_rig.cpp) is built the same way otherwise; both share rig_internal.h.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>
#include <string>
#include <vector>

#include <assimp/scene.h>

#include "cooker/import/import_internal.h"
#include "cooker/import/rig_internal.h"

namespace ossa::cook::detail {
namespace {

/// Letters and digits of the name after any "namespace:", lower-cased. Exporters rewrite names:
/// 3ds Max's "Bip01 L Finger0Nub" becomes "Bip01LFinger0Nub" in Pab's clip files, three.js drops
/// the '.' of Blender's "Foot.L". Used only when the exact name fails and only when it picks
/// exactly one node.
std::string loose_name(const std::string& name) {
  const size_t colon = name.rfind(':');
  std::string out;
  for (size_t i = colon == std::string::npos ? 0 : colon + 1; i < name.size(); ++i) {
    const unsigned char ch = static_cast<unsigned char>(name[i]);
    if (std::isalnum(ch)) out += static_cast<char>(std::tolower(ch));
  }
  return out;
}

bool joinable(const Node& node) { return !node.helper && !node.camera_or_light; }

/// File node per reference joint (-1 when absent): exact names first, then loose ones.
std::vector<int> match_reference(const Context& ctx, const NodeGraph& graph, const SourceSkeleton& ref) {
  const size_t count = ref.joints.size();
  std::vector<int> node(count, -1);
  std::vector<bool> taken(graph.nodes.size(), false);
  for (size_t r = 0; r < count; ++r) {
    const int n = graph.resolve(ref.joints[r].name);
    if (n >= 0 && joinable(graph.nodes[n]) && !taken[n]) {
      node[r] = n;
      taken[n] = true;
    }
  }
  std::map<std::string, std::vector<int>> loose;
  for (size_t n = 0; n < graph.nodes.size(); ++n) {
    if (joinable(graph.nodes[n]) && !taken[n]) loose[loose_name(graph.nodes[n].name)].push_back(n);
  }
  std::vector<std::string> matched;
  for (size_t r = 0; r < count; ++r) {
    if (node[r] >= 0) continue;
    const auto it = loose.find(loose_name(ref.joints[r].name));
    if (it == loose.end()) continue;
    std::vector<int> free;
    for (int n : it->second) {
      if (!taken[n]) free.push_back(n);
    }
    if (free.size() != 1) continue;  // ambiguous: better unmatched than matched wrongly
    node[r] = free.front();
    taken[free.front()] = true;
    matched.push_back(graph.nodes[free.front()].name + " -> " + ref.joints[r].name);
  }
  if (!matched.empty()) {
    ctx.warn("joints matched to the reference by letters and digits only: " + name_list(matched));
  }
  return node;
}

Status check_reference(const Context& ctx, const SourceSkeleton& ref) {
  if (ref.joints.empty()) return ctx.error("the reference skeleton has no joints");
  if (ref.joints.size() > kMaxJoints) return ctx.error("the reference skeleton has too many joints");
  for (size_t j = 0; j < ref.joints.size(); ++j) {
    const int p = ref.joints[j].parent;
    if (p >= static_cast<int>(j) || p < -1 || (j > 0 && p < 0) || (j == 0 && p != -1)) {
      return ctx.error("the reference skeleton is not parents-first with one root (joint '" + ref.joints[j].name +
                       "')");
    }
  }
  return {};
}

/// Chains from each matched joint's nearest matched ancestor. A joint whose file node is not below
/// that ancestor's node (the hierarchies differ there) is unmatched, with a warning.
void reference_chains(const Context& ctx, const NodeGraph& graph, Rig* rig) {
  const auto& joints = rig->skeleton.joints;
  std::vector<glm::dmat4> ref_model(joints.size());
  for (size_t r = 0; r < joints.size(); ++r) {
    const glm::dmat4 local =
        compose({glm::dvec3(joints[r].translation), glm::dquat(joints[r].rotation), glm::dvec3(joints[r].scale)});
    ref_model[r] = joints[r].parent < 0 ? local : ref_model[joints[r].parent] * local;
  }
  std::vector<std::string> moved;
  for (size_t r = 0; r < joints.size(); ++r) {
    const int n = rig->joint_node[r];
    if (n < 0) continue;
    int above = joints[r].parent;
    while (above >= 0 && rig->joint_node[above] < 0) above = joints[above].parent;
    const int stop = above < 0 ? -1 : rig->joint_node[above];
    bool ok = stop < 0 || (stop != n && graph.is_ancestor_or_self(stop, n));
    std::vector<int> chain = ok ? chain_to(graph, n, stop) : std::vector<int>{};
    for (size_t i = 0; ok && i + 1 < chain.size(); ++i) {
      // A matched node inside the chain would be a joint the reference puts elsewhere.
      if (rig->node_joint[chain[i]] >= 0) ok = false;
    }
    if (!ok) {
      moved.push_back(joints[r].name);
      rig->node_joint[n] = -1;
      rig->joint_node[r] = -1;
      continue;
    }
    rig->chain[r] = std::move(chain);
    const int parent = joints[r].parent;
    if (parent != above) {  // reference joints the file lacks sit in between, at their bind
      glm::dmat4 inverse;
      if (try_inverse(ref_model[parent], &inverse)) {
        rig->prefix[r] = above < 0 ? inverse : inverse * ref_model[above];
      }
    }
  }
  if (!moved.empty()) {
    ctx.warn("joints whose parent in the file differs from the reference are not matched: " + name_list(moved));
  }
}

/// Skinned or animated nodes the reference cannot carry. Skinned ones, and animated ones other
/// animated or skinned nodes hang below, are errors (their motion would be lost or misplaced);
/// an animated leaf the reference lacks (3ds Max's "Bip01 Footsteps") moves nothing it has, so it
/// is dropped with a warning.
Status check_unmatched(const Context& ctx, const NodeGraph& graph, const Seeds& seeds,
                       const std::vector<int>& rig_nodes, const Rig& rig) {
  std::vector<bool> on_chain(graph.nodes.size(), false);
  for (const auto& chain : rig.chain) {
    for (int c : chain) on_chain[c] = true;
  }
  std::vector<bool> carries_seed(graph.nodes.size(), false);  // a seed strictly below
  for (int s : rig_nodes) {
    for (int a = graph.nodes[s].effective_parent; a >= 0; a = graph.nodes[a].effective_parent) {
      if (carries_seed[a]) break;
      carries_seed[a] = true;
    }
  }
  std::vector<std::string> missing, dropped;
  for (int s : rig_nodes) {
    if (rig.node_joint[s] >= 0 || on_chain[s]) continue;
    if (seeds.bone[s] || carries_seed[s]) {
      missing.push_back(graph.nodes[s].name);
    } else {
      dropped.push_back(graph.nodes[s].name);
    }
  }
  if (!missing.empty()) {
    return ctx.error("joints the file skins or animates are missing from the reference skeleton: " +
                     name_list(missing, 1000));
  }
  if (!dropped.empty()) {
    ctx.warn("animated leaf nodes the reference skeleton lacks are dropped: " + name_list(dropped));
  }
  return {};
}

/// Keys are folded into the file's space; joints the file does not animate keep the reference's
/// bind. Both must be in the same units (a Collada file, scaled to metres by Assimp, against an
/// FBX reference in centimetres would mix them), so a different root scale is said out loud.
void check_root_scale(const Context& ctx, const NodeGraph& graph, const Rig& rig) {
  if (rig.joint_node.empty() || rig.joint_node[0] < 0) return;
  const double file = glm::length(decompose(chain_local(graph, rig.chain[0])).s);
  const double ref = glm::length(glm::dvec3(rig.skeleton.joints[0].scale));
  if (ref > 0.0 && std::abs(file / ref - 1.0) > 0.01) {
    ctx.warn("the root's scale in the file (" + std::to_string(file / std::sqrt(3.0)) +
             ") differs from the reference's (" + std::to_string(ref / std::sqrt(3.0)) +
             "): are both in the same units?");
  }
}

}  // namespace

Result<Rig> reference_rig(const Context& ctx, const NodeGraph& graph, const Seeds& seeds, const SourceSkeleton& ref) {
  if (Status s = check_reference(ctx, ref); !s) return s.error();
  Rig rig;
  rig.skeleton = ref;
  rig.joint_node = match_reference(ctx, graph, ref);
  rig.chain.assign(ref.joints.size(), {});
  rig.prefix.assign(ref.joints.size(), glm::dmat4(1.0));
  rig.node_joint.assign(graph.nodes.size(), -1);
  for (size_t r = 0; r < ref.joints.size(); ++r) {
    if (rig.joint_node[r] >= 0) rig.node_joint[rig.joint_node[r]] = static_cast<int>(r);
  }
  reference_chains(ctx, graph, &rig);
  check_root_scale(ctx, graph, rig);
  // The rig is the top-level subtrees holding matched seeds; animated cameras etc. elsewhere are
  // dropped like in the file's own rig.
  std::vector<bool> tops(graph.nodes.size(), false);
  bool any = false;
  for (size_t n = 0; n < graph.nodes.size(); ++n) {
    if (rig.node_joint[n] >= 0 && (seeds.bone[n] || seeds.animated[n])) {
      tops[graph.nodes[n].top] = true;
      any = true;
    }
  }
  if (!any) {
    bool has_seed = false;
    for (size_t n = 0; n < graph.nodes.size(); ++n) has_seed |= seeds.bone[n] || seeds.animated[n];
    if (has_seed) {
      // Name what the file wanted, so the user sees at once which rig the clip was made for.
      std::vector<std::string> wanted;
      for (size_t n = 0; n < graph.nodes.size(); ++n) {
        if (!(seeds.bone[n] || seeds.animated[n])) continue;
        const int owner = graph.helper_owner(static_cast<int>(n));
        if (owner < 0) continue;
        const std::string& name = graph.nodes[static_cast<size_t>(owner)].name;
        if (std::find(wanted.begin(), wanted.end(), name) == wanted.end()) wanted.push_back(name);
      }
      std::string list;
      for (size_t i = 0; i < wanted.size() && i < 12; ++i) list += (i ? ", " : "") + wanted[i];
      if (wanted.size() > 12) list += ", ... (" + std::to_string(wanted.size() - 12) + " more)";
      return ctx.error("no skinned or animated joint of the file matches the reference skeleton; missing from it: " +
                       list);
    }
    return rig;
  }
  const std::vector<int> rig_nodes = rig_seeds(ctx, graph, seeds, tops);
  if (Status s = check_unmatched(ctx, graph, seeds, rig_nodes, rig); !s) return s.error();
  return rig;
}

}  // namespace ossa::cook::detail
