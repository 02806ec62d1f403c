// texture_mips.h — a decoded image and its full mip chain, filtered the way its role needs.
//
// Mips are made at cook time so a loader never runs glGenerateMipmap (60–100 ms for a 1024²
// texture under Mesa) and so they are made right, which a GPU's mipmap generator does not do:
//   - colour maps are averaged in linear light (sRGB decoded, averaged, re-encoded), so a
//     black-and-white checker's next level is sRGB 188, the grey it looks like, not 128;
//   - colour is weighted by alpha, so a cut-out's transparent texels do not bleed their (often
//     black) colour into the edge of the opaque part;
//   - normal maps are averaged as vectors and renormalised, so a level's normals stay unit;
//   - other data maps (specular) are averaged as they are.
// Each level is a separable area ("box") resample of the one above: every destination texel
// averages the source area it covers, with fractional weights where an odd side does not halve
// evenly, so a 5 x 3 level's next is 2 x 1 with nothing dropped. Kaiser or Lanczos filters are
// sharper; the area filter is the one that never rings, and this is the one place it matters
// that a mip is exactly the mean of what it covers (normal-map lengths, alpha coverage).
//
// Level 0 comes from decode_rgba (image_check.h), bottom-up as the format stores rows. Written here rather than taken
// from stb_image_resize because that one filters in sRGB only with a fixed alpha treatment and has no vector
// renormalisation; the filter is 60 lines.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "cooker/import/image_check.h"

namespace ossa::cook {

/// How a texture's texels are filtered between levels.
enum class TexelKind : uint8_t {
  Colour,  // RGB in sRGB, A linear (alpha-weighted colour)
  Normal,  // RGB is a unit vector * 0.5 + 0.5; A ignored
  Data,    // every channel linear (specular, masks)
};

/// An RGBA8 image, rows bottom to top (decode_rgba in image_check.h makes level 0).
using Image = DecodedImage;

/// Levels 1.. of the chain below `level0` down to 1 x 1 (level 0 itself is not repeated).
/// O(pixels), about 1/3 of level 0's texels in total.
std::vector<Image> build_mips(const Image& level0, TexelKind kind);

/// True when every texel's alpha is 255.
bool opaque(const Image& image);
/// True when every texel has R == G == B.
bool greyscale(const Image& image);

}  // namespace ossa::cook
