// import_nodes.cpp — Assimp's node tree as a flat, ordered graph, and the transform math on it.
//
// The rest of the import stage reasons about nodes by index in depth-first order: that order is
// the source's own, so joints, meshes and warnings come out the same for the same bytes, and no
// container keyed by pointer is ever iterated. The graph also marks what Assimp inserted or what
// can never be a joint (`$AssimpFbx$` helpers, cameras, lights) and links each node to its nearest
// non-helper ancestor, the tree the skeleton is chosen from.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <set>

#include <assimp/scene.h>
#include <glm/gtc/matrix_transform.hpp>

#include "cooker/import/import_internal.h"

namespace ossa::cook::detail {

// ---------------------------------------------------------------------------------------------
// Math

glm::dmat4 to_dmat4(const aiMatrix4x4& m) {
  // aiMatrix4x4 is row-major (a1..a4 is the first row); glm is column-major.
  glm::dmat4 out(1.0);
  for (int row = 0; row < 4; ++row) {
    for (int col = 0; col < 4; ++col) out[col][row] = static_cast<double>(m[row][col]);
  }
  return out;
}

Trs decompose(const glm::dmat4& m) {
  Trs trs;
  trs.t = glm::dvec3(m[3]);
  glm::dmat3 a(m);
  glm::dvec3 s(glm::length(a[0]), glm::length(a[1]), glm::length(a[2]));
  if (glm::determinant(a) < 0.0) s = -s;
  glm::dmat3 rot(1.0);
  for (int c = 0; c < 3; ++c) {
    // A zero scale leaves that axis undefined; any unit axis reproduces the (degenerate) matrix.
    if (std::abs(s[c]) > 1e-300) rot[c] = a[c] / s[c];
  }
  trs.s = s;
  trs.r = glm::normalize(glm::quat_cast(rot));
  if (!std::isfinite(trs.r.w)) trs.r = glm::dquat(1.0, 0.0, 0.0, 0.0);
  return trs;
}

glm::dmat4 compose(const Trs& trs) {
  glm::dmat4 m = glm::mat4_cast(trs.r);
  m[0] *= trs.s.x;
  m[1] *= trs.s.y;
  m[2] *= trs.s.z;
  m[3] = glm::dvec4(trs.t, 1.0);
  return m;
}

bool is_finite(const glm::dmat4& m) {
  for (int c = 0; c < 4; ++c) {
    for (int r = 0; r < 4; ++r) {
      if (!std::isfinite(m[c][r])) return false;
    }
  }
  return true;
}

double relative_difference(const glm::dmat4& a, const glm::dmat4& b) {
  double diff = 0.0, scale = 1.0;
  for (int c = 0; c < 4; ++c) {
    for (int r = 0; r < 4; ++r) {
      diff = std::max(diff, std::abs(a[c][r] - b[c][r]));
      scale = std::max(scale, std::abs(b[c][r]));
    }
  }
  return diff / scale;
}

bool try_inverse(const glm::dmat4& m, glm::dmat4* out) {
  // Judge singularity relative to the matrix's own size: centimetre and metre rigs differ by 1e6
  // in determinant, a fixed threshold would misjudge one of them.
  const glm::dmat3 a(m);
  const double size = std::max({glm::length(a[0]), glm::length(a[1]), glm::length(a[2])});
  const double det = glm::determinant(a);
  if (!(size > 0.0) || !std::isfinite(det) || std::abs(det) <= 1e-12 * size * size * size) {
    return false;
  }
  *out = glm::inverse(m);
  return is_finite(*out);
}

glm::mat4 to_float(const glm::dmat4& m) { return glm::mat4(m); }

// ---------------------------------------------------------------------------------------------
// Graph

namespace {

constexpr const char* kHelperTag = "_$AssimpFbx$_";

bool is_helper_name(const std::string& name) { return name.find(kHelperTag) != std::string::npos; }

std::set<std::string> camera_and_light_names(const aiScene& scene) {
  std::set<std::string> names;
  for (unsigned i = 0; i < scene.mNumCameras; ++i) {
    if (scene.mCameras[i]) names.insert(scene.mCameras[i]->mName.C_Str());
  }
  for (unsigned i = 0; i < scene.mNumLights; ++i) {
    if (scene.mLights[i]) names.insert(scene.mLights[i]->mName.C_Str());
  }
  return names;
}

bool holds_kept_mesh(const aiNode& node, const std::vector<bool>& mesh_kept) {
  for (unsigned i = 0; i < node.mNumMeshes; ++i) {
    const unsigned m = node.mMeshes[i];
    if (m < mesh_kept.size() && mesh_kept[m]) return true;
  }
  return false;
}

}  // namespace

NodeGraph build_node_graph(const Context& ctx) {
  NodeGraph graph;
  const std::set<std::string> cameras = camera_and_light_names(*ctx.scene);
  // Explicit stack instead of recursion: a hostile file may nest nodes deeper than the call stack.
  struct Pending {
    const aiNode* node;
    int parent;
  };
  std::vector<Pending> stack{{ctx.scene->mRootNode, -1}};
  while (!stack.empty()) {
    const Pending p = stack.back();
    stack.pop_back();
    if (!p.node) continue;
    const int index = static_cast<int>(graph.nodes.size());
    Node n;
    n.ai = p.node;
    n.name = p.node->mName.C_Str();
    n.parent = p.parent;
    n.local = to_dmat4(p.node->mTransformation);
    n.global = p.parent < 0 ? n.local : graph.nodes[p.parent].global * n.local;
    n.helper = index != 0 && is_helper_name(n.name);
    n.has_mesh = holds_kept_mesh(*p.node, ctx.mesh_kept);
    n.camera_or_light = cameras.count(n.name) != 0;
    n.top = p.parent <= 0 ? (p.parent < 0 ? 0 : index) : graph.nodes[p.parent].top;
    // Effective parent: skip helpers, so a joint's parent is the joint Assimp split it from.
    int ep = p.parent;
    while (ep >= 0 && graph.nodes[ep].helper) ep = graph.nodes[ep].parent;
    n.effective_parent = ep;
    if (!n.helper && ep >= 0) graph.nodes[ep].effective_children.push_back(index);
    graph.by_name[n.name].push_back(index);
    graph.nodes.push_back(std::move(n));
    for (unsigned c = p.node->mNumChildren; c-- > 0;) stack.push_back({p.node->mChildren[c], index});
  }
  // Depth-first order puts every node after its parent: one backward pass gathers subtrees.
  for (size_t n = graph.nodes.size(); n-- > 0;) {
    Node& node = graph.nodes[n];
    node.subtree_has_mesh = node.subtree_has_mesh || node.has_mesh;
    if (node.parent >= 0 && node.subtree_has_mesh) graph.nodes[node.parent].subtree_has_mesh = true;
  }
  return graph;
}

int NodeGraph::resolve(const std::string& name) const {
  const auto it = by_name.find(name);
  if (it == by_name.end()) return resolve_path(name);
  int best = -1;
  for (int n : it->second) {
    if (nodes[n].helper) continue;
    if (!nodes[n].has_mesh) return n;
    if (best < 0) best = n;
  }
  return best >= 0 ? best : it->second.front();
}

int NodeGraph::resolve_path(const std::string& name) const {
  const size_t slash = name.find('/');
  if (slash == std::string::npos) return -1;
  const auto it = by_name.find(name.substr(slash + 1));
  if (it == by_name.end()) return -1;
  int best = -1;
  for (int n : it->second) {
    if (nodes[n].helper || nodes[nodes[n].top].name != name.substr(0, slash)) continue;
    if (!nodes[n].has_mesh) return n;
    if (best < 0) best = n;
  }
  return best;
}

namespace {

/// The nodes named `name` that resolve() would choose between (neither helpers nor holding a
/// mesh: an object named like a bone is settled by resolve()), or empty when at most one is.
std::vector<int> ambiguous(const NodeGraph& graph, const std::string& name) {
  const auto it = graph.by_name.find(name);
  if (it == graph.by_name.end()) return {};
  std::vector<int> out;
  for (int n : it->second)
    if (!graph.nodes[n].helper && !graph.nodes[n].has_mesh) out.push_back(n);
  if (out.size() < 2) out.clear();
  return out;
}

/// The top-level node most of `nodes` lie under (the first in node order on a tie), -1 if none.
int majority_top(const NodeGraph& graph, const std::vector<int>& nodes) {
  std::map<int, size_t> count;
  for (int n : nodes)
    if (n >= 0) ++count[graph.nodes[n].top];
  int best = -1;
  size_t most = 0;
  for (const auto& [top, c] : count) {
    if (c > most) {
      best = top;
      most = c;
    }
  }
  return best;
}

/// The candidates under `top`, or all of them when none is.
std::vector<int> under_top(const NodeGraph& graph, const std::vector<int>& candidates, int top) {
  std::vector<int> out;
  for (int n : candidates)
    if (graph.nodes[n].top == top) out.push_back(n);
  return out.empty() ? candidates : out;
}

}  // namespace

std::vector<int> bone_nodes(const NodeGraph& graph, const aiMesh& mesh, int mesh_node) {
  std::vector<int> out(mesh.mNumBones, -1);
  std::vector<bool> settled(mesh.mNumBones, true);
  for (unsigned b = 0; b < mesh.mNumBones; ++b) {
    if (!mesh.mBones[b]) continue;
    const std::string name = mesh.mBones[b]->mName.C_Str();
    settled[b] = ambiguous(graph, name).empty();
    if (settled[b]) out[b] = graph.helper_owner(graph.resolve(name));
  }
  const int top = majority_top(graph, out);
  for (unsigned b = 0; b < mesh.mNumBones; ++b) {
    if (settled[b]) continue;
    const aiBone& bone = *mesh.mBones[b];
    const std::vector<int> candidates = under_top(graph, ambiguous(graph, bone.mName.C_Str()), top);
    glm::dmat4 bound(1.0);
    const bool has_bind = mesh_node >= 0 && try_inverse(to_dmat4(bone.mOffsetMatrix), &bound);
    if (has_bind) bound = graph.nodes[mesh_node].global * bound;
    double closest = 0.0;
    for (int n : candidates) {  // node order breaks ties: the same bytes give the same joints
      const double d = has_bind ? relative_difference(graph.nodes[n].global, bound) : 0.0;
      if (out[b] < 0 || d < closest) {
        out[b] = n;
        closest = d;
      }
    }
  }
  return out;
}

std::vector<int> channel_nodes(const NodeGraph& graph, const aiAnimation& anim) {
  std::vector<int> out(anim.mNumChannels, -1);
  std::vector<bool> settled(anim.mNumChannels, true);
  for (unsigned c = 0; c < anim.mNumChannels; ++c) {
    if (!anim.mChannels[c]) continue;
    const std::string name = anim.mChannels[c]->mNodeName.C_Str();
    settled[c] = ambiguous(graph, name).empty();
    if (settled[c]) out[c] = graph.resolve(name);
  }
  // Blender names an action after its armature ("HatArmature|Lift"): that armature, when it is a
  // top-level node; else the one the clip's unambiguous channels lie under.
  int top = majority_top(graph, out);
  const std::string clip = anim.mName.C_Str();
  if (clip.find('|') != std::string::npos) {
    const auto named = graph.by_name.find(clip.substr(0, clip.find('|')));
    for (int n : named == graph.by_name.end() ? std::vector<int>{} : named->second)
      if (graph.nodes[n].parent == 0) top = n;
  }
  for (unsigned c = 0; c < anim.mNumChannels; ++c) {
    if (settled[c]) continue;
    const std::vector<int> candidates = under_top(graph, ambiguous(graph, anim.mChannels[c]->mNodeName.C_Str()), top);
    out[c] = candidates.front();
  }
  return out;
}

bool NodeGraph::is_ancestor_or_self(int a, int n) const {
  for (; n >= 0; n = nodes[n].parent) {
    if (n == a) return true;
  }
  return false;
}

int NodeGraph::helper_owner(int n) const {
  if (n < 0 || !nodes[n].helper) return n;
  // Assimp names the chain "<node>_$AssimpFbx$_<part>" and hangs the node itself below it;
  // the pivot-geometry helpers hang below the node instead, so the owner may be above.
  const std::string owner = nodes[n].name.substr(0, nodes[n].name.find(kHelperTag));
  for (int d = n + 1; d < static_cast<int>(nodes.size()) && is_ancestor_or_self(n, d); ++d) {
    if (!nodes[d].helper && nodes[d].name == owner) return d;
  }
  for (int a = nodes[n].parent; a >= 0; a = nodes[a].parent) {
    if (!nodes[a].helper) return nodes[a].name == owner ? a : -1;
  }
  return -1;
}

}  // namespace ossa::cook::detail
