// morphs.h — morph targets in the viewer: the character's weight channels, the vertex-major entry
// lists the GPU reads, and the CPU reference (decode, apply_morphs, skin).
//
// The file stores targets target-major and sparse (each target lists the vertices it moves), which
// is what a CPU accumulate wants (ossa/anim/morph.h apply_morphs) but not what a vertex shader
// wants: one shader invocation is one vertex, and it must find that vertex's deltas without
// walking every target. build_morph_entries transposes the lists once per mesh, at load, into a
// CSR keyed by vertex: ranges[v] = (first entry, entry count), and per entry the channel index
// and the decoded float deltas (position, normal, tangent; mesh units, mesh space). The shader
// then does one loop over the few entries of its own vertex, reading the weight of each entry's
// channel for its instance: cost O(listed vertices) per draw, nothing for meshes without targets.
//
// The CPU path (--cpu-skinning) is the reference the shader is tested against. skin_cpu decodes
// and skins in one pass from the file's bytes and has no hook between the two, so a mesh with
// targets is decoded here once (decode_morph_base: positions as stored, normals, tangents, joint
// slots, weights; the same GL fetch rules skin_cpu follows), and each frame its positions and
// directions in mesh units get apply_morphs and are skinned by linear blending with the same
// palette (D folded in, directions divided by position_scale) as skin_cpu would. With all weights
// zero that reproduces skin_cpu (tested), so the two paths still differ only in who morphs and
// skins. Everything here is GL-free.
#pragma once
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include <ossa/format/result.h>
#include <ossa/loader/asset.h>
#include <ossa/skinning/skinning.h>

namespace ossa::view {

/// Vertex-major morph data of one mesh, ready for two texture buffers.
struct MorphEntries {
  std::vector<int32_t> ranges;  // 2 per vertex: first entry, entry count (RG32I)
  std::vector<float> texels;    // texels_per_entry RGBA texels per entry (RGBA32F)
  /// 1: (position delta xyz, channel); 2: + (normal delta xyz, 0); 3: + (tangent delta xyz, 0).
  int texels_per_entry = 1;
  size_t entry_count = 0;
  bool empty() const { return entry_count == 0; }
};

/// Transposes the mesh's targets into per-vertex entry lists. target_channel[t] is the channel of
/// target t (bind_morph_targets); targets bound to no channel (-1) are left out. Deltas are
/// decoded to floats (int16 * step): positions in mesh units, directions in mesh space. Within a
/// vertex, entries keep the targets' order. Empty for a mesh without targets. O(vertices +
/// listed vertices).
MorphEntries build_morph_entries(const MeshView& mesh, std::span<const int32_t> target_channel);

/// A mesh's vertices decoded for the CPU morph: positions in mesh units, unit normals, tangents
/// (xyz + bitangent sign), joint slots and weights as OpenGL would fetch them.
struct MorphBase {
  std::vector<glm::vec3> positions, normals;  // normals empty without a Normal attribute
  std::vector<glm::vec4> tangents;            // empty without a Tangent attribute
  std::vector<glm::uvec4> slots;
  std::vector<glm::vec4> weights;
  bool dequantize = false;              // positions are stored normalized (D in the palette)
  glm::vec3 offset{0.0f}, scale{1.0f};  // D = translate(offset) * scale(scale)
  glm::vec3 direction_prescale{1.0f};   // 1 / scale (0 on a zero axis)
};

/// Decodes `mesh` for morph_and_skin_cpu. Errors name the mesh for a layout it cannot read.
Result<MorphBase> decode_morph_base(const MeshView& mesh);

/// Scratch for morph_and_skin_cpu, reused from frame to frame.
struct MorphScratch {
  std::vector<glm::vec3> positions, normals, tangents;
};

/// skin_cpu(mesh, palette, Linear, out) of the mesh with its targets applied at `weights`
/// (indexed by channel, through target_channel): base positions / normals / tangents in mesh
/// units + apply_morphs, then linear blend skinning with the palette (from skinning_matrices,
/// D folded in). Output sizes as skin_cpu's; false (nothing written) when a span is too small.
bool morph_and_skin_cpu(const MeshView& mesh, const MorphBase& base, std::span<const int32_t> target_channel,
                        std::span<const float> weights, std::span<const glm::mat4> palette, MorphScratch& scratch,
                        SkinnedStreams out);

}  // namespace ossa::view
