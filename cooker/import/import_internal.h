// import_internal.h — what the import_*.cpp files share; nothing outside the import stage includes it.
//
// import_scene.cpp reads the file with Assimp and hands the aiScene to convert_scene(), which runs
// the stages below in a fixed order: node graph -> rig (skeleton or reference mapping) -> clips ->
// meshes -> materials. The stages are split by what they own so each stays small, and
// convert_scene() takes an aiScene rather than a path so a test can feed it a scene it built or
// edited by hand (helper chains, odd hierarchies) without writing a file.
//
// All transform arithmetic here is double precision: chains of helper and above-root nodes are
// multiplied, decomposed and re-multiplied, and the result must still match Assimp's node globals
// to 1e-4 relative after the conversion to float at the very end.
#pragma once
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <assimp/matrix4x4.h>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "cooker/import/import_scene.h"
#include "cooker/model/source_scene.h"
#include <ossa/format/result.h>

struct aiScene;
struct aiNode;
struct aiMesh;
struct aiAnimation;

namespace ossa::cook::detail {

// ---------------------------------------------------------------------------------------------
// Math (import_nodes.cpp)

struct Trs {
  glm::dvec3 t{0.0};
  glm::dquat r{1.0, 0.0, 0.0, 0.0};
  glm::dvec3 s{1.0};
};

glm::dmat4 to_dmat4(const aiMatrix4x4& m);
/// Translation, rotation, scale of an affine matrix. A mirroring matrix gets all three scales
/// negated, as Assimp's own aiMatrix4x4::Decompose does, so decomposed binds agree with Assimp's
/// keys. Shear is lost (a TRS joint cannot hold it); the caller measures the residual.
Trs decompose(const glm::dmat4& m);
glm::dmat4 compose(const Trs& trs);
bool is_finite(const glm::dmat4& m);
/// max |a - b| over the 16 entries divided by max(1, max |b|).
double relative_difference(const glm::dmat4& a, const glm::dmat4& b);
/// Writes the inverse and returns true, or returns false when the matrix is (numerically) singular.
bool try_inverse(const glm::dmat4& m, glm::dmat4* out);
glm::mat4 to_float(const glm::dmat4& m);

// ---------------------------------------------------------------------------------------------
// Node graph (import_nodes.cpp)

enum class SourceFormat { Fbx, Gltf, Collada, Bvh, Other };

struct Node {
  const aiNode* ai = nullptr;
  std::string name;
  int parent = -1;                      // raw Assimp parent
  int effective_parent = -1;            // nearest ancestor that is not an `$AssimpFbx$` helper
  std::vector<int> effective_children;  // non-helper nodes whose effective parent is this, in order
  glm::dmat4 local{1.0};
  glm::dmat4 global{1.0};
  bool helper = false;            // an `$AssimpFbx$` pivot/offset node: never a joint
  bool has_mesh = false;          // holds at least one mesh that is kept
  bool subtree_has_mesh = false;  // it or a raw descendant has_mesh
  bool camera_or_light = false;   // never a joint, its keys are dropped
  int top = 0;                    // the child of the scene root this node lies under (0 for the root)
};

/// Every aiNode flattened depth-first (index 0 = the scene root), so node order, and everything
/// derived from it, follows the source's order and never a pointer's.
struct NodeGraph {
  std::vector<Node> nodes;
  std::map<std::string, std::vector<int>> by_name;

  /// The node a bone or channel name means. Names are not unique in every file (Blender exports
  /// an object and a bone of the same name, e.g. Quaternius' "Torso"): prefer a non-helper node
  /// holding no mesh, then the first in depth-first order. -1 when nothing has that name.
  int resolve(const std::string& name) const;
  /// A name that is not in the file but reads "<top>/<name>" means the node <name> under the
  /// top-level node <top>: the cooked name of a joint whose name repeats in another armature.
  int resolve_path(const std::string& name) const;
  /// true when a is n or one of n's raw ancestors.
  bool is_ancestor_or_self(int a, int n) const;
  /// The non-helper node an `$AssimpFbx$` helper belongs to (itself when not a helper), -1 if none.
  int helper_owner(int n) const;
};

struct Context {
  const aiScene* scene = nullptr;
  std::string path;  // as given, for messages and relative texture paths
  SourceFormat format = SourceFormat::Other;
  const ImportOptions* options = nullptr;
  std::vector<bool> mesh_kept;  // per aiMesh: false for dropped (lines, generated skeleton)
  std::vector<std::string>* warnings = nullptr;
  /// A problem that must fail the import after the stage that found it (a texture that is not the
  /// image it claims to be); the first one is kept.
  std::string* failure = nullptr;
  void warn(std::string message) const { warnings->push_back(std::move(message)); }
  void fail(std::string message) const {
    if (failure != nullptr && failure->empty()) *failure = std::move(message);
  }
  Error error(const std::string& what) const { return Error{path + ": " + what}; }
};

NodeGraph build_node_graph(const Context& ctx);

/// The node each of the mesh's bones means (helpers resolved to their owner, -1 when none),
/// mesh_node being a node that holds the mesh (-1 when none). A name held by several nodes (two
/// armatures each with a "Bone") is settled by the hierarchy, not by name alone: the candidate
/// under the armature (top-level node) holding most of the mesh's unambiguous bones, then the
/// one whose global transform is closest to where the skin was bound, global(mesh_node) x
/// inverse(offset). Every stage that reads bones calls this, so they all agree.
std::vector<int> bone_nodes(const NodeGraph& graph, const aiMesh& mesh, int mesh_node);

/// The node each channel of anim means (raw, helpers not resolved; -1 when none). A clip drives the
/// joints of its own armature: a repeated name means the candidate under the top-level node the
/// clip's name starts with ("HatArmature|Lift", Blender's convention), else under the one holding
/// most of the clip's unambiguous channels, else the first in node order.
std::vector<int> channel_nodes(const NodeGraph& graph, const aiAnimation& anim);

// ---------------------------------------------------------------------------------------------
// Rig (import_rig.cpp): which nodes are joints and where each joint's local transform comes from.

struct Rig {
  SourceSkeleton skeleton;
  /// File node of each joint; -1 for a reference joint the file does not have.
  std::vector<int> joint_node;
  /// Raw nodes, top-down, whose local transforms multiply to the joint's local transform: the
  /// `$AssimpFbx$` helpers above the joint (in clip-only cooking also nodes the reference lacks)
  /// and the joint node itself; for the root also every node above it up to and including the
  /// scene root. Empty where joint_node is -1.
  std::vector<std::vector<int>> chain;
  /// Static matrix multiplied before the chain; identity except in clip-only cooking where the
  /// file lacks reference joints between this joint and its nearest matched ancestor: the runtime
  /// puts those joints at their reference bind, so this undoes them (inverse of the parent's
  /// reference model times the matched ancestor's).
  std::vector<glm::dmat4> prefix;
  /// Per node: the joint it is, or -1.
  std::vector<int> node_joint;
  /// Per joint, the node pose's local transform, when the bind pose was taken from the skins and
  /// differs from it (import_rig.cpp, adopt_mesh_bind_pose); empty otherwise. A clip leaves a joint
  /// or channel it does not key where the file's nodes stand, so the file's clips carry these
  /// values for what they do not animate, instead of the bind value.
  std::vector<Trs> rest;
};

Result<Rig> build_rig(const Context& ctx, const NodeGraph& graph);

// ---------------------------------------------------------------------------------------------
// Stages that read the rig.

/// One SourceClip per aiAnimation (import_clips.cpp).
std::vector<SourceClip> import_clips(const Context& ctx, const NodeGraph& graph, const Rig& rig);

/// One SourceMesh per (kept aiMesh, node instance) (import_meshes.cpp). Adds to
/// *vertices_over_4_influences.
Result<std::vector<SourceMesh>> import_meshes(const Context& ctx, const NodeGraph& graph, const Rig& rig,
                                              uint32_t* vertices_over_4_influences);

/// Whether mesh m is the bone display mesh Assimp builds for files without meshes (BVH, rig-only
/// Collada), never part of the source (import_meshes.cpp).
bool is_generated_skeleton_mesh(const aiScene& scene, unsigned m);

/// Which meshes to keep, with warnings for those dropped (import_meshes.cpp).
std::vector<bool> select_meshes(const Context& ctx);

/// One SourceMaterial per aiMaterial (import_materials.cpp).
std::vector<SourceMaterial> import_materials(const Context& ctx);

/// Length of one source unit in metres (import_materials.cpp).
float metres_per_unit(const Context& ctx);

/// The whole conversion, after Assimp has read the file (import_scene.cpp).
Result<SourceScene> convert_scene(const aiScene& scene, const std::string& path, SourceFormat format,
                                  const ImportOptions& options);

SourceFormat format_of(const std::string& path);

/// The source's up axis (import_axes.cpp) and what says so.
struct SourceUp {
  int axis = 1;  // 0 x, 1 y, 2 z
  int sign = 1;  // +1 or -1
  const char* by = "";
};
/// True when Assimp turns this file to Y-up itself (Collada's <up_axis>, with no --up-axis).
bool assimp_applies_up_axis(const std::string& path, const ImportOptions& options);
SourceUp source_up(const aiScene& scene, const std::string& path, const ImportOptions& options);
/// Turns the scene so that `up` becomes +Y; leaves a Y-up scene untouched.
void turn_to_y_up(aiScene& scene, const SourceUp& up);

}  // namespace ossa::cook::detail
