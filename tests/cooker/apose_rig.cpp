// apose_rig.cpp — ossa-test-apose: makes an A-pose character from a T-pose one, for the retarget
// tests and screenshots (no sample character is bound in an A-pose).
//
//   ossa-test-apose SOURCE OUT.ossa [--degrees 45]
//
// The source is imported with the cooker (import_scene), its clips dropped, and its bind pose
// changed: both upper arms turn `degrees` down about the body's forward axis (the body frame the
// retarget finds, ossa/retarget/retarget.h). Every skinned vertex is posed into the new bind with
// linear blend skinning and each skin's bind matrices are remade (inverse of the joint's new model
// matrix times the mesh's placement), so the new file draws the same character with its arms
// lowered, bound that way: what an artist's A-pose export of the rig would be. Then meshes,
// textures and the file are cooked as ossa-cook would. Test tooling: not installed.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include "cooker/cook.h"
#include "cooker/import/import_scene.h"
#include "cooker/model/input_log.h"
#include "cooker/mesh/mesh_build.h"
#include "cooker/texture/texture_cook.h"
#include "cooker/write/write_ossa.h"
#include <ossa/loader/asset.h>
#include <ossa/retarget/retarget.h>

namespace {

using namespace ossa;
using namespace ossa::cook;

glm::mat4 trs(const SourceJoint& j) {
  glm::mat4 m = glm::mat4_cast(j.rotation);
  m[0] *= j.scale.x;
  m[1] *= j.scale.y;
  m[2] *= j.scale.z;
  m[3] = glm::vec4(j.translation, 1.0f);
  return m;
}

std::vector<glm::mat4> model_of(const SourceSkeleton& s) {
  std::vector<glm::mat4> m(s.joints.size());
  for (size_t j = 0; j < m.size(); ++j) {
    const int p = s.joints[j].parent;
    m[j] = p >= 0 ? m[static_cast<size_t>(p)] * trs(s.joints[j]) : trs(s.joints[j]);
  }
  return m;
}

int fail(const std::string& message) {
  std::fprintf(stderr, "ossa-test-apose: %s\n", message.c_str());
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) return fail("usage: ossa-test-apose SOURCE OUT.ossa [--degrees 45]");
  const std::string source = argv[1], output = argv[2];
  float degrees = 45.0f;
  if (argc >= 5 && std::string(argv[3]) == "--degrees") degrees = std::strtof(argv[4], nullptr);
  InputLog log;
  InputLogScope scope(&log);
  auto scene = import_scene(source);
  if (!scene) return fail(scene.error().message);
  SourceScene& s = *scene;
  s.clips.clear();

  // The body frame and arms, as the retarget sees them.
  std::vector<std::string_view> names;
  std::vector<int16_t> parents;
  std::vector<Transform> bind;
  for (const SourceJoint& j : s.skeleton.joints) {
    names.emplace_back(j.name);
    parents.push_back(static_cast<int16_t>(j.parent));
    bind.push_back(Transform{j.translation, j.rotation, j.scale});
  }
  RetargetRig rig;
  rig.name = source;
  rig.parents = parents;
  rig.bind = bind;
  rig.names = names;
  rig.humanoid = map_humanoid(names, parents);
  rig.rest = RestPose::Bind;
  auto pose = make_retarget_pose(rig);
  if (!pose) return fail(pose.error().message);
  const glm::vec3 forward = glm::inverse(pose->frame) * glm::vec3(0.0f, 0.0f, 1.0f);

  const std::vector<glm::mat4> before = model_of(s.skeleton);
  for (int side = 0; side < 2; ++side) {
    const int arm = rig.humanoid[side == 0 ? HumanoidBone::LeftUpperArm : HumanoidBone::RightUpperArm];
    // Down is a turn about forward: negative for the left arm (+x), positive for the right.
    const glm::quat down = glm::angleAxis(glm::radians(side == 0 ? -degrees : degrees), forward);
    SourceJoint& j = s.skeleton.joints[static_cast<size_t>(arm)];
    const int p = j.parent;
    glm::quat parent(1.0f, 0.0f, 0.0f, 0.0f);
    for (int k = p; k >= 0; k = s.skeleton.joints[static_cast<size_t>(k)].parent)
      parent = s.skeleton.joints[static_cast<size_t>(k)].rotation * parent;
    j.rotation = glm::normalize(glm::inverse(parent) * down * parent * j.rotation);
  }
  const std::vector<glm::mat4> after = model_of(s.skeleton);
  for (size_t j = 0; j < after.size(); ++j) s.skeleton.joints[j].inverse_bind = glm::inverse(after[j]);

  for (SourceMesh& mesh : s.meshes) {
    if (mesh.joints.empty()) continue;
    // Per skin joint: the skinning matrix from the old bind to the new pose, and the new bind.
    std::vector<glm::mat4> skin(s.skeleton.joints.size(), glm::mat4(1.0f));
    glm::mat4 placement(1.0f);
    for (auto& [joint, inverse_bind] : mesh.bind) {
      skin[joint] = after[joint] * inverse_bind;
      placement = before[joint] * inverse_bind;  // the mesh's placement in model space
    }
    for (auto& [joint, inverse_bind] : mesh.bind) inverse_bind = glm::inverse(after[joint]) * placement;
    const glm::mat4 to_mesh = glm::inverse(placement);
    for (size_t v = 0; v < mesh.positions.size(); ++v) {
      glm::mat4 m(0.0f);
      for (int k = 0; k < 4; ++k) m += mesh.weights[v][k] * skin[mesh.joints[v][k]];
      mesh.positions[v] = glm::vec3(to_mesh * m * glm::vec4(mesh.positions[v], 1.0f));
      const glm::mat3 linear = glm::mat3(to_mesh * m);
      if (!mesh.normals.empty()) mesh.normals[v] = glm::normalize(linear * mesh.normals[v]);
      if (!mesh.tangents.empty())
        mesh.tangents[v] = glm::vec4(glm::normalize(linear * glm::vec3(mesh.tangents[v])), mesh.tangents[v].w);
    }
    mesh.morph_targets.clear();
  }

  MeshBuildStats stats;
  std::vector<std::string> warnings;
  auto meshes = build_meshes(s, MeshOptions{}, &stats, &warnings);
  if (!meshes) return fail(meshes.error().message);
  std::vector<TextureRecord> textures;
  if (Status st = cook_textures(s, TextureOutput::Compressed, source, textures); !st) return fail(st.message());
  WriteProvenance provenance;
  provenance.source_name = "apose";
  provenance.options = "apose=" + std::to_string(degrees);
  const std::vector<uint8_t> bytes = write_ossa(s, *meshes, {}, provenance, WriteOptions{});
  if (Status st = verify_buffer(bytes, output); !st) return fail(st.message());
  if (Status st = write_file_atomic(output, bytes); !st) return fail(st.message());
  return 0;
}
