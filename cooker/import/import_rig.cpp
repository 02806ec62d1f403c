// import_rig.cpp — which nodes are joints, in what order, and where each joint's local comes from.
//
// Assimp has no notion of a skeleton: it gives a node tree, bones that name nodes, and channels that
// name nodes. The skeleton is rebuilt from those names:
//   seeds   = nodes named by a bone of a kept mesh + nodes carrying keys (an `$AssimpFbx$` helper's
//             keys count for the node it belongs to); cameras and lights never;
//   rig     = the top-level subtrees (children of the scene root) holding the bones, or, in a file
//             without bones, a mesh-free one holding most of the animated nodes (else all that
//             hold any). This is the seed blog's "top-level node whose subtree holds no mesh" idea
//             made robust to what real files carry next to the rig: animated cameras and their
//             targets (Pab/walk.fbx), rigid parts hung under bones (Quaternius), several animated
//             objects (interpolation_test);
//   joints  = the seeds, their ancestors up to the seeds' lowest common ancestor (so there is one
//             root; raised to the top-level node when that one's subtree holds no mesh, the blog's
//             root), and the descendants of seeds whose subtrees hold no mesh (end sites, leaf
//             bones: clips and attachments may address them even when no vertex does).
// Ancestry here skips helpers: a joint's parent is the joint Assimp split it from, and the helpers
// in between are multiplied into the joint's local ("chain"), as is everything above the root, so a
// joint's model matrix equals Assimp's global transform of the node.
//
// With ImportOptions::reference the skeleton is the reference's; file nodes are matched to it by
// name and each matched joint's chain runs from the nearest matched ancestor down, so anything in
// between (helpers, nodes the reference lacks) is folded into the keys of the joint below it: that
// half is import_rig_reference.cpp.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <set>

#include <assimp/scene.h>

#include "cooker/import/import_internal.h"
#include "cooker/import/rig_internal.h"

namespace ossa::cook::detail {
namespace {

constexpr double kBindTolerance = 1e-4;

}  // namespace

/// "a, b, c" with at most `limit` names, then "and N more": warnings stay readable on big rigs.
std::string name_list(const std::vector<std::string>& names, size_t limit) {
  std::string out;
  for (size_t i = 0; i < names.size() && i < limit; ++i) out += (i ? ", " : "") + names[i];
  if (names.size() > limit) out += ", and " + std::to_string(names.size() - limit) + " more";
  return out;
}

namespace {

/// Appends name once, keeping first-seen order (deterministic, and the order the file has).
void add_unique(std::vector<std::string>* names, std::set<std::string>* seen, const std::string& n) {
  if (seen->insert(n).second) names->push_back(n);
}

Seeds find_seeds(const Context& ctx, const NodeGraph& graph) {
  const aiScene& scene = *ctx.scene;
  const size_t count = graph.nodes.size();
  Seeds seeds{std::vector<bool>(count, false), std::vector<bool>(count, false)};
  std::vector<std::string> missing_bones, missing_channels, cameras;
  std::set<std::string> seen_bones, seen_channels, seen_cameras;
  std::vector<int> holder(scene.mNumMeshes, -1);  // the first node holding each mesh
  for (size_t n = graph.nodes.size(); n-- > 0;) {
    const aiNode& node = *graph.nodes[n].ai;
    for (unsigned i = 0; i < node.mNumMeshes; ++i)
      if (node.mMeshes[i] < scene.mNumMeshes) holder[node.mMeshes[i]] = static_cast<int>(n);
  }
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    const aiMesh* mesh = scene.mMeshes[m];
    if (!ctx.mesh_kept[m]) continue;
    const std::vector<int> nodes = bone_nodes(graph, *mesh, holder[m]);
    for (unsigned b = 0; b < mesh->mNumBones; ++b) {
      const aiBone* bone = mesh->mBones[b];
      if (!bone) continue;
      const int n = nodes[b];
      if (n < 0) {
        add_unique(&missing_bones, &seen_bones, bone->mName.C_Str());
      } else {
        seeds.bone[n] = true;
      }
    }
  }
  for (unsigned a = 0; a < scene.mNumAnimations; ++a) {
    const aiAnimation* anim = scene.mAnimations[a];
    const std::vector<int> nodes = anim ? channel_nodes(graph, *anim) : std::vector<int>{};
    for (unsigned c = 0; anim && c < anim->mNumChannels; ++c) {
      const aiNodeAnim* channel = anim->mChannels[c];
      if (!channel) continue;
      const int n = graph.helper_owner(nodes[c]);
      if (n < 0) {
        add_unique(&missing_channels, &seen_channels, channel->mNodeName.C_Str());
      } else if (graph.nodes[n].camera_or_light) {
        add_unique(&cameras, &seen_cameras, graph.nodes[n].name);
      } else {
        seeds.animated[n] = true;
      }
    }
  }
  if (!missing_bones.empty()) {
    ctx.warn("bones name nodes the file does not have, their weights are dropped: " + name_list(missing_bones));
  }
  if (!missing_channels.empty()) {
    ctx.warn("animation channels name nodes the file does not have, their keys are dropped: " +
             name_list(missing_channels));
  }
  if (!cameras.empty()) {
    ctx.warn("keys of cameras and lights are dropped: " + name_list(cameras));
  }
  return seeds;
}

/// Per top-level subtree: whether it belongs to the rig. Index 0 (the scene root) stands for
/// "every subtree", used when the root itself is a seed.
std::vector<bool> choose_rig_tops(const NodeGraph& graph, const Seeds& seeds) {
  const size_t count = graph.nodes.size();
  std::vector<bool> tops(count, false);
  bool any_bone = false;
  for (size_t n = 0; n < count; ++n) {
    if (seeds.bone[n]) {
      tops[graph.nodes[n].top] = true;
      any_bone = true;
    }
  }
  if (any_bone) return tops;
  if (seeds.animated[0]) {  // the scene root itself moves (BVH): everything is under it
    tops[0] = true;
    return tops;
  }
  std::vector<size_t> per_top(count, 0);
  size_t total = 0;
  for (size_t n = 0; n < count; ++n) {
    if (seeds.animated[n]) {
      ++per_top[graph.nodes[n].top];
      ++total;
    }
  }
  for (size_t t = 1; t < count; ++t) {
    // One mesh-free subtree holds most animated nodes: that is the rig, the rest is scenery
    // (camera targets, lights). Animated objects with meshes are all kept (interpolation_test).
    if (per_top[t] * 2 > total && !graph.nodes[t].subtree_has_mesh) {
      tops[t] = true;
      return tops;
    }
  }
  for (size_t t = 0; t < count; ++t) tops[t] = per_top[t] > 0;
  return tops;
}

bool in_rig(const NodeGraph& graph, const std::vector<bool>& tops, int n) {
  return tops[0] || tops[graph.nodes[n].top];
}

}  // namespace

/// Seeds outside the rig are dropped; says which.
std::vector<int> rig_seeds(const Context& ctx, const NodeGraph& graph, const Seeds& seeds,
                           const std::vector<bool>& tops) {
  std::vector<int> kept;
  std::vector<std::string> outside;
  for (size_t n = 0; n < graph.nodes.size(); ++n) {
    if (!seeds.bone[n] && !seeds.animated[n]) continue;
    if (in_rig(graph, tops, static_cast<int>(n))) {
      kept.push_back(static_cast<int>(n));
    } else {
      outside.push_back(graph.nodes[n].name);
    }
  }
  if (!outside.empty()) {
    ctx.warn("animated nodes outside the skeleton are not joints, their keys are dropped: " + name_list(outside));
  }
  return kept;
}

namespace {

int effective_lca(const NodeGraph& graph, int a, int b) {
  std::set<int> above_a;
  for (int n = a; n >= 0; n = graph.nodes[n].effective_parent) above_a.insert(n);
  for (int n = b; n >= 0; n = graph.nodes[n].effective_parent) {
    if (above_a.count(n)) return n;
  }
  return 0;
}

}  // namespace

/// Raw nodes from just below `stop` (or from the scene root when stop is -1) down to n.
std::vector<int> chain_to(const NodeGraph& graph, int n, int stop) {
  std::vector<int> chain;
  for (int c = n; c >= 0 && c != stop; c = graph.nodes[c].parent) chain.push_back(c);
  std::reverse(chain.begin(), chain.end());
  return chain;
}

glm::dmat4 chain_local(const NodeGraph& graph, const std::vector<int>& chain) {
  glm::dmat4 m(1.0);
  for (int c : chain) m = m * graph.nodes[c].local;
  return m;
}

namespace {

/// The seeds' lowest common ancestor, raised to the top-level node above it when that node's
/// subtree holds no mesh (the seed blog's root rule). A rig whose root bone carries no weight and
/// no keys in one file (Pab/skeleton.fbx's Hips) then gets the same root as the clip files that do
/// animate it, instead of a root one level lower.
int skeleton_root(const NodeGraph& graph, const std::vector<int>& seeds) {
  int lca = seeds.front();
  for (int s : seeds) lca = effective_lca(graph, lca, s);
  if (lca == 0) return lca;
  int highest = lca;  // the top-level node, or the joint its `$AssimpFbx$` helpers belong to
  while (graph.nodes[highest].effective_parent > 0) highest = graph.nodes[highest].effective_parent;
  if (highest != lca && !graph.nodes[highest].camera_or_light && !graph.nodes[graph.nodes[lca].top].subtree_has_mesh) {
    return highest;
  }
  return lca;
}

/// Seeds + ancestors up to the root + non-mesh descendants of seeds.
std::vector<bool> select_joints(const NodeGraph& graph, const std::vector<int>& seeds, int* root) {
  const size_t count = graph.nodes.size();
  const int lca = skeleton_root(graph, seeds);
  std::vector<bool> joint(count, false);
  for (int s : seeds) {
    for (int n = s; n >= 0; n = graph.nodes[n].effective_parent) {
      if (joint[n]) break;
      joint[n] = true;
      if (n == lca) break;
    }
  }
  joint[lca] = true;
  std::vector<int> grow(seeds.begin(), seeds.end());
  while (!grow.empty()) {
    const int j = grow.back();
    grow.pop_back();
    for (int c : graph.nodes[j].effective_children) {
      const Node& child = graph.nodes[c];
      // Only mesh-free subtrees: an empty that merely holds meshes (glTF exports of rigid parts)
      // is not a bone; its meshes ride on the joint above it.
      if (joint[c] || child.subtree_has_mesh || child.camera_or_light) continue;
      joint[c] = true;
      grow.push_back(c);
    }
  }
  *root = lca;
  return joint;
}

/// Depth-first, parents first, children in the source's order.
std::vector<int> flatten(const NodeGraph& graph, const std::vector<bool>& joint, int root) {
  std::vector<int> order;
  std::vector<int> stack{root};
  while (!stack.empty()) {
    const int n = stack.back();
    stack.pop_back();
    order.push_back(n);
    const auto& children = graph.nodes[n].effective_children;
    for (size_t i = children.size(); i-- > 0;) {
      if (joint[children[i]]) stack.push_back(children[i]);
    }
  }
  return order;
}

/// Bind pose from the chains; checks the flattened TRS reproduces Assimp's node globals.
void fill_bind_pose(const Context& ctx, const NodeGraph& graph, Rig* rig) {
  std::vector<glm::dmat4> model(rig->skeleton.joints.size());
  std::vector<std::string> sheared, singular;
  for (size_t j = 0; j < rig->skeleton.joints.size(); ++j) {
    SourceJoint& joint = rig->skeleton.joints[j];
    const Trs trs = decompose(chain_local(graph, rig->chain[j]));
    joint.translation = glm::vec3(trs.t);
    joint.rotation = glm::normalize(glm::quat(trs.r));
    joint.scale = glm::vec3(trs.s);
    const glm::dmat4 local = compose(trs);
    model[j] = joint.parent < 0 ? local : model[joint.parent] * local;
    if (relative_difference(model[j], graph.nodes[rig->joint_node[j]].global) > kBindTolerance) {
      sheared.push_back(joint.name);
    }
    glm::dmat4 inverse;
    if (try_inverse(model[j], &inverse)) {
      joint.inverse_bind = to_float(inverse);
    } else {
      joint.inverse_bind = glm::mat4(1.0f);
      singular.push_back(joint.name);
    }
  }
  if (!sheared.empty()) {
    ctx.warn(
        "bind transforms with shear cannot be held as translation/rotation/scale, these "
        "joints' model matrices differ from the source: " +
        name_list(sheared));
  }
  if (!singular.empty()) {
    ctx.warn("joints with a singular bind matrix get an identity inverse bind: " + name_list(singular));
  }
}

/// The bind pose is the pose the mesh was bound in. A source exported mid-animation has its nodes
/// in some frame's pose while its skins' inverse bind matrices (aiBone::mOffsetMatrix) still say
/// the T-pose; the skeleton's bind pose (the viewer's bind pose, additive references, the rest a
/// game resets to) must be the latter. Bone j of a mesh held by node n was bound at model matrix
/// global(n) x inverse(offset); the first mesh naming a joint decides (glTF keeps its node pose,
/// see below). Joints no skin names keep their node-pose local under their (possibly moved) parent. Nothing changes
/// when every bound matrix agrees with the node pose to kBindTolerance (most files), so those cook as before.
void adopt_mesh_bind_pose(const Context& ctx, const NodeGraph& graph, Rig* rig) {
  const size_t count = rig->skeleton.joints.size();
  // glTF: the node pose is the rest pose by the specification, and its inverse bind matrices need
  // not describe one consistent pose of the whole rig (RobotExpressive's hand skins name all 43
  // joints in a pose that would scatter its rigid parts), so glTF keeps the node pose.
  if (count == 0 || ctx.format == SourceFormat::Gltf) return;
  std::vector<glm::dmat4> bound(count);
  std::vector<bool> has(count, false);
  for (size_t n = 0; n < graph.nodes.size(); ++n) {
    const aiNode& node = *graph.nodes[n].ai;
    for (unsigned i = 0; i < node.mNumMeshes; ++i) {
      const unsigned m = node.mMeshes[i];
      if (m >= ctx.mesh_kept.size() || !ctx.mesh_kept[m]) continue;
      const aiMesh* mesh = ctx.scene->mMeshes[m];
      if (!mesh) continue;
      const std::vector<int> nodes = bone_nodes(graph, *mesh, static_cast<int>(n));
      for (unsigned b = 0; b < mesh->mNumBones; ++b) {
        const aiBone* bone = mesh->mBones[b];
        if (!bone) continue;
        const int bn = nodes[b];
        if (bn < 0 || rig->node_joint[static_cast<size_t>(bn)] < 0) continue;
        const auto j = static_cast<size_t>(rig->node_joint[static_cast<size_t>(bn)]);
        glm::dmat4 inverse_offset;
        if (has[j] || !try_inverse(to_dmat4(bone->mOffsetMatrix), &inverse_offset)) continue;
        // FBX and Collada through Assimp: the offset maps from the mesh node's space.
        const glm::dmat4 model = graph.nodes[n].global * inverse_offset;
        if (!is_finite(model)) continue;
        bound[j] = model;
        has[j] = true;
      }
    }
  }
  // The node pose's model matrices, and how far the skins' bind is from them.
  std::vector<Trs> node_pose(count);
  std::vector<glm::dmat4> node_model(count), local(count);
  size_t moved = 0;
  double worst = 0.0;
  std::string worst_joint;
  for (size_t j = 0; j < count; ++j) {
    const SourceJoint& joint = rig->skeleton.joints[j];
    node_pose[j] = Trs{glm::dvec3(joint.translation), glm::dquat(joint.rotation), glm::dvec3(joint.scale)};
    local[j] = compose(node_pose[j]);
    node_model[j] = joint.parent < 0 ? local[j] : node_model[static_cast<size_t>(joint.parent)] * local[j];
    if (!has[j]) continue;
    const double d = relative_difference(bound[j], node_model[j]);
    if (d > kBindTolerance) {
      ++moved;
      if (d > worst) {
        worst = d;
        worst_joint = joint.name;
      }
    }
  }
  if (moved == 0) return;
  rig->rest = std::move(node_pose);
  std::vector<glm::dmat4> model(count);
  std::vector<std::string> sheared;
  for (size_t j = 0; j < count; ++j) {
    SourceJoint& joint = rig->skeleton.joints[j];
    const int parent = joint.parent;
    model[j] = has[j] ? bound[j] : (parent < 0 ? local[j] : model[static_cast<size_t>(parent)] * local[j]);
    glm::dmat4 parent_inverse(1.0);
    if (parent >= 0 && !try_inverse(model[static_cast<size_t>(parent)], &parent_inverse)) return;  // keep the node pose
    const glm::dmat4 wanted = parent_inverse * model[j];
    const Trs trs = decompose(wanted);
    joint.translation = glm::vec3(trs.t);
    joint.rotation = glm::normalize(glm::quat(trs.r));
    joint.scale = glm::vec3(trs.s);
    // What the TRS holds is what the runtime will compose: carry that, not the wish, downwards.
    model[j] = (parent < 0 ? glm::dmat4(1.0) : model[static_cast<size_t>(parent)]) * compose(trs);
    if (has[j] && relative_difference(model[j], bound[j]) > kBindTolerance) sheared.push_back(joint.name);
    glm::dmat4 inverse;
    joint.inverse_bind = try_inverse(model[j], &inverse) ? to_float(inverse) : glm::mat4(1.0f);
  }
  char largest[64];
  std::snprintf(largest, sizeof largest, "%.3g", worst);
  ctx.warn("the skins were bound in another pose than the nodes stand in (" + std::to_string(moved) +
           " joints differ, most '" + worst_joint + "', by " + largest +
           " relative): the bind pose is the skins' pose; the file's clips keep the node pose for what they do "
           "not animate");
  if (!sheared.empty())
    ctx.warn("bind matrices with shear cannot be held as translation/rotation/scale: " + name_list(sheared));
}

/// Joints the source left unnamed (some FBX exporters write empty model names, and Assimp keeps
/// them) get a stable name from their place in the skeleton: "joint<index>", or "joint<index>_<n>"
/// when the file already uses that name. The format requires a name per joint (masks, retargeting
/// and clip binding go by name), so without this the cook failed its own verification.
void name_unnamed_joints(const Context& ctx, SourceSkeleton* skeleton) {
  std::set<std::string> used;
  for (const SourceJoint& j : skeleton->joints) used.insert(j.name);
  std::vector<std::string> named;
  for (size_t j = 0; j < skeleton->joints.size(); ++j) {
    SourceJoint& joint = skeleton->joints[j];
    if (!joint.name.empty()) continue;
    std::string name = "joint" + std::to_string(j);
    for (int n = 2; used.count(name); ++n) name = "joint" + std::to_string(j) + "_" + std::to_string(n);
    used.insert(name);
    joint.name = name;
    named.push_back(name);
  }
  if (!named.empty()) {
    ctx.warn(std::to_string(named.size()) +
             " joints have no name in the source and are named by their index: " + name_list(named));
  }
}

/// Joints are nodes, and two armatures may each have a "Bone": the format binds clips, masks and
/// retargeting by joint name, so a repeated name is made unique. The first joint keeps it; a later
/// one becomes "<its top-level node>/<name>" (which NodeGraph::resolve understands, so clip files
/// cooked against this rig find the joint), or "<name>.<n>" when that is taken too. Said in a warning.
void make_names_unique(const Context& ctx, const NodeGraph& graph, Rig* rig) {
  std::set<std::string> used;
  std::vector<std::string> renamed;
  for (size_t j = 0; j < rig->skeleton.joints.size(); ++j) {
    SourceJoint& joint = rig->skeleton.joints[j];
    if (used.insert(joint.name).second) continue;
    const Node& node = graph.nodes[static_cast<size_t>(rig->joint_node[j])];
    std::string name = graph.nodes[static_cast<size_t>(node.top)].name + "/" + joint.name;
    if (node.top == 0 || used.count(name)) {
      for (int n = 1; used.count(name = joint.name + "." + std::to_string(n)); ++n) {
      }
    }
    used.insert(name);
    renamed.push_back("'" + joint.name + "' -> '" + name + "'");
    joint.name = name;
  }
  if (!renamed.empty()) {
    ctx.warn(std::to_string(renamed.size()) +
             " joints share a name with another joint (several armatures) "
             "and are renamed: " +
             name_list(renamed));
  }
}

Result<Rig> own_rig(const Context& ctx, const NodeGraph& graph, const std::vector<int>& seeds) {
  Rig rig;
  rig.node_joint.assign(graph.nodes.size(), -1);
  if (seeds.empty()) return rig;
  int root = 0;
  const std::vector<bool> joint = select_joints(graph, seeds, &root);
  const std::vector<int> order = flatten(graph, joint, root);
  if (order.size() > kMaxJoints) {
    return ctx.error("the skeleton has " + std::to_string(order.size()) + " joints, more than " +
                     std::to_string(kMaxJoints));
  }
  for (size_t j = 0; j < order.size(); ++j) {
    const int n = order[j];
    rig.node_joint[n] = static_cast<int>(j);
    const int parent_node = j == 0 ? -1 : graph.nodes[n].effective_parent;
    SourceJoint sj;
    sj.name = graph.nodes[n].name;
    sj.parent = parent_node < 0 ? -1 : rig.node_joint[parent_node];
    rig.skeleton.joints.push_back(std::move(sj));
    rig.joint_node.push_back(n);
    rig.chain.push_back(chain_to(graph, n, parent_node));
    rig.prefix.emplace_back(1.0);
  }
  name_unnamed_joints(ctx, &rig.skeleton);
  make_names_unique(ctx, graph, &rig);
  for (size_t j = 0; j < order.size(); ++j) {
    if (!is_finite(chain_local(graph, rig.chain[j]))) {
      return ctx.error("joint '" + rig.skeleton.joints[j].name + "' has a non-finite transform");
    }
  }
  fill_bind_pose(ctx, graph, &rig);
  adopt_mesh_bind_pose(ctx, graph, &rig);
  return rig;
}

/// A rig-only file (a Collada or FBX skeleton exported without its body or any animation) has no
/// bones and no keys to seed the skeleton: its node tree is the skeleton. The top-level subtree
/// with the most nodes is taken (scenery beside it, cameras and lights, is left out); every node
/// in it but cameras, lights and `$AssimpFbx$` helpers is a joint. Only for files that hold no
/// mesh at all (Assimp's generated bone display mesh aside): nodes that hold point or line meshes
/// are not a rig.
std::vector<int> rig_only_seeds(const Context& ctx, const NodeGraph& graph) {
  if (ctx.scene->mNumAnimations != 0 || graph.nodes.size() < 2) return {};
  for (unsigned m = 0; m < ctx.scene->mNumMeshes; ++m)
    if (!is_generated_skeleton_mesh(*ctx.scene, m)) return {};
  std::vector<size_t> per_top(graph.nodes.size(), 0);
  for (size_t n = 1; n < graph.nodes.size(); ++n)
    if (!graph.nodes[n].helper && !graph.nodes[n].camera_or_light) ++per_top[graph.nodes[n].top];
  const size_t top = static_cast<size_t>(std::max_element(per_top.begin() + 1, per_top.end()) - per_top.begin());
  if (per_top[top] == 0) return {};
  std::vector<int> seeds;
  for (size_t n = 1; n < graph.nodes.size(); ++n)
    if (graph.nodes[n].top == static_cast<int>(top) && !graph.nodes[n].helper && !graph.nodes[n].camera_or_light)
      seeds.push_back(static_cast<int>(n));
  ctx.warn("the file holds no mesh and no animation: its node tree under '" + graph.nodes[top].name + "' (" +
           std::to_string(seeds.size()) + " nodes) is cooked as a skeleton");
  return seeds;
}

}  // namespace

Result<Rig> build_rig(const Context& ctx, const NodeGraph& graph) {
  const Seeds seeds = find_seeds(ctx, graph);
  if (ctx.options->reference) return reference_rig(ctx, graph, seeds, *ctx.options->reference);
  const std::vector<bool> tops = choose_rig_tops(graph, seeds);
  std::vector<int> kept = rig_seeds(ctx, graph, seeds, tops);
  if (kept.empty()) kept = rig_only_seeds(ctx, graph);
  return own_rig(ctx, graph, kept);
}

}  // namespace ossa::cook::detail
