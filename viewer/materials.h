// materials.h — a file's materials on the GPU: colours and the diffuse / normal / specular maps,
// and of a PBR source what Phong shading can use: occlusion (scales the ambient term) and the
// emissive colour and map (added). Metallic-roughness maps and factors are not shown: a warning
// names the materials that have them.
//
// A cooked texture (ossa/loader/texture.h) is uploaded level by level from the file's bytes with
// glCompressedTexImage2D (BC1 / BC3 / BC4 / BC5) or glTexImage2D (RGBA8): no decode and no mipmap
// generation at load, colour maps through sRGB formats so the shader lights linear values. A
// texture cooked with --texture-format source (PNG / JPEG bytes) or referenced by a path relative
// to the .ossa file is decoded with stb_image and its mips generated, as before. Materials that
// share a Texture table share one GL texture. A texture that cannot be found
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
  glm::vec3 emissive{0.0f};
  GLuint diffuse_map = 0, normal_map = 0, specular_map = 0, occlusion_map = 0, emissive_map = 0;  // 0: none
  uint64_t texture_bytes = 0;  // GPU memory of the textures this material uploaded (shared ones count once)
};

/// One GpuMaterial per file material (plus a grey default when the file has none). Warnings for
/// textures left out are appended to `warnings`. `asset_path` is the .ossa file's path.
std::vector<GpuMaterial> create_materials(const Asset& asset, const std::string& asset_path,
                                          std::vector<std::string>& warnings);
void destroy_materials(std::vector<GpuMaterial>& materials);

/// GPU memory the materials' textures take: every mip level as uploaded (a decoded image counts
/// its RGBA8 chain). O(materials).
uint64_t texture_bytes(const std::vector<GpuMaterial>& materials);

}  // namespace ossa::view
