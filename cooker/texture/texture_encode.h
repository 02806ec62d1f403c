// texture_encode.h — mip levels into the block formats GPUs sample, and back (to measure them).
//
// Encoding is stb_dxt (Debian's libstb): BC1 and BC3 in its high-quality mode (two refinement
// passes), BC4 and BC5 with its exhaustive single-channel search. It is the encoder the issue
// named; its BC1 never uses the 3-colour + transparent mode, so colour with any alpha below 255
// goes to BC3. A level whose sides are not multiples of 4 is padded by repeating its last row and
// column (what a GPU samples there is clamped away by the level's real size).
//
// Decoding follows the S3TC / RGTC specifications exactly (both BC1 modes, both BC4 modes). The
// cooker only uses it to measure what it wrote (PSNR, normal angles, texture_cook.h); tests use it
// to check the bytes the viewer uploads.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include <ossa/format/ossa_generated.h>
#include "cooker/texture/texture_mips.h"

namespace ossa::cook {

/// `image` in `encoding` (Rgba8 copies; Bc1 ignores alpha; Bc4 keeps R; Bc5 keeps R and G),
/// appended to `out`. O(texels); about 1 µs per 4 x 4 block for BC1 / BC3 in high quality.
void encode_level(const Image& image, fb::TextureEncoding encoding, std::vector<uint8_t>& out);

/// The RGBA8 texels a GPU returns for `bytes`, one level of `width` x `height` in `encoding`
/// (Bc4: R, 0, 0, 255; Bc5: R, G, 0, 255; Bc1: alpha 255, or 0 for the 3-colour mode's
/// transparent index). `bytes` must hold the level (texture_level_bytes). O(texels).
Image decode_level(std::span<const uint8_t> bytes, fb::TextureEncoding encoding, uint32_t width, uint32_t height);

}  // namespace ossa::cook
