// texture_cook.h — the texture stage: every embedded image becomes the mip chain a GPU samples.
//
// Runs between import and write, on the scene's materials. Per distinct (image bytes, role) —
// materials sharing an image share one cooked texture, and the writer one Texture table — the
// image is decoded, its full mip chain built as its role needs (texture_mips.h) and encoded
// (texture_encode.h) in the format picked by role:
//   - diffuse (colour): sRGB; BC1 when every texel is opaque, BC3 otherwise;
//   - normal: BC5 (x and y; the loader rebuilds z), renormalised per mip;
//   - specular: BC4 when the image is grey (R = G = B everywhere), BC1 (linear) otherwise.
// With TextureOutput::Rgba8 the same chains are stored uncompressed (still sRGB for colour);
// with TextureOutput::Source nothing changes: the source's PNG / JPEG bytes are embedded as read.
// A texture known only by path (its file could not be read) stays a path.
//
// Each distinct texture adds a TextureRecord: sizes before and after, what a decoded RGBA8 chain
// would take on a GPU, the format, and its error against the source at level 0 — PSNR over the
// channels kept (colour in sRGB bytes, as an artist compares them) and, for normal maps, the mean
// and largest angle between the source's normal and the one the GPU reconstructs.
//
// Deterministic: the encoders are, and the output depends only on the bytes and the role.
// O(texels) per texture; BC1 / BC3 in high quality take about 1 µs per 4 x 4 block.
#pragma once
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cooker/model/cook_options.h"
#include "cooker/model/cook_record.h"
#include "cooker/model/source_scene.h"
#include <ossa/format/result.h>

namespace ossa::cook {

/// Cooks the embedded textures of every material of `scene` in place (SourceTexture's encoding
/// fields, same_as for repeats) and appends one record per distinct texture. An image that does
/// not decode fails the cook, named with `label` (the input) and the material.
Status cook_textures(SourceScene& scene, TextureOutput output, const std::string& label,
                     std::vector<TextureRecord>& records);

}  // namespace ossa::cook
