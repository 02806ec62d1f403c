// bounds.cpp — see bounds.h.
#include "viewer/bounds.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <ossa/skinning/skinning.h>

namespace ossa::view {

Box joint_bounds(std::span<const glm::mat4> model) {
  Box b;
  for (const glm::mat4& m : model) b.add(glm::vec3(m[3]));
  return b;
}

Box posed_bounds(const Asset& asset, std::span<const glm::mat4> model) {
  Box box = joint_bounds(model);
  std::vector<glm::mat4> palette;
  std::vector<float> positions;
  for (size_t i = 0; i < asset.mesh_count(); ++i) {
    const MeshView mesh = asset.mesh(i);
    if (mesh.vertex_count() == 0) continue;
    palette.assign(std::max<size_t>(mesh.joints().size(), 1), glm::mat4(1.0f));
    skinning_matrices(mesh, model, palette);
    positions.assign(static_cast<size_t>(mesh.vertex_count()) * 3, 0.0f);
    skin_cpu(mesh, palette, SkinningMethod::Linear, SkinnedStreams{positions, {}, {}});
    for (size_t v = 0; v < positions.size(); v += 3) {
      const glm::vec3 p(positions[v], positions[v + 1], positions[v + 2]);
      if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) box.add(p);
    }
  }
  return box;
}

}  // namespace ossa::view
