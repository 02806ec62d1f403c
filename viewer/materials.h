// materials.h — a file's materials on the GPU: colours and the diffuse / normal / specular maps.
//
// Textures are either embedded in the .ossa (the encoded PNG / JPEG bytes the source had) or a
// path relative to the .ossa file; both are decoded with stb_image. A texture that cannot be found
// or decoded is not fatal — the material falls back to its colour and a warning names the file —
// because a character without its maps is still worth looking at.
#pragma once
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include <ossa/loader/asset.h>
#include "viewer/gl.h"

namespace ossa::view {

struct GpuMaterial {
  glm::vec3 diffuse{0.8f};
  float opacity = 1.0f;
  GLuint diffuse_map = 0, normal_map = 0, specular_map = 0;  // 0: none
};

/// One GpuMaterial per file material (plus a grey default when the file has none). Warnings for
/// textures left out are appended to `warnings`. `asset_path` is the .ossa file's path.
std::vector<GpuMaterial> create_materials(const Asset& asset, const std::string& asset_path,
                                          std::vector<std::string>& warnings);
void destroy_materials(std::vector<GpuMaterial>& materials);

}  // namespace ossa::view
