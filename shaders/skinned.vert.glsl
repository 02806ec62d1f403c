// skinned.vert.glsl — linear blend skinning on the GPU (4 influences), reading the cooked vertex
// layout exactly as it is stored in the .ossa file.
//
// The viewer binds the file's vertex bytes with glVertexAttribPointer straight from the layout
// table (ossa/format/vertex_format.h), so GL itself does the unorm / snorm / half-float decoding and
// attribute locations equal fb::VertexSemantic values (Position 0 ... Weights 6):
//  - position: Unorm16x4 (normalized into [0, 1] inside the mesh bounds) or Float32x3. The
//    de-quantizing affine D = translate(position_offset) * scale(position_scale) is folded into
//    every palette matrix on the CPU (ossa/skinning/skinning.h), so both cases are palette * (p.xyz, 1).
//  - normal: Snorm16x2 octahedral (decoded here, as ossa/format/vertex_codec.h) or Float32x3 xyz.
//    Directions must not see D's per-axis scale, so they are multiplied by u_direction_prescale
//    (1 / position_scale; 1 for float layouts) before the palette, exactly as skin_cpu does:
//    palette3x3 * (n / s) = (model * inverse_bind)3x3 * n.
//  - tangent: Snorm16x4 (octahedral xy, bitangent sign in z) or Float32x4 (xyz, sign in w).
//  - joints: integer slots (glVertexAttribIPointer), weights unorm8 / float summing to 1.
// A static mesh has no joint / weight arrays: the constant attribute values the viewer sets
// (slot 0, weight (1, 0, 0, 0)) select palette[0] = D.
//
// The palette is a texture buffer (RGBA32F, four texels per column-major matrix) that holds the
// palettes of every instance back to back: rigs with more joints than the uniform limits allow,
// and crowds drawn with one instanced call, need no shader change. The CPU-skinning reference
// path feeds already skinned float streams through this same shader with an identity palette.
//
// Morph targets (viewer/morphs.h) are added before skinning, as glTF specifies. The file stores
// them per target; the viewer transposed them per vertex at load: u_morph_ranges[gl_VertexID] =
// (first entry, entry count), and each entry is u_morph_texels texels of u_morph_entries: (position
// delta xyz in mesh units, channel), then the normal delta, then the tangent delta (mesh space).
// Weights are per instance: u_morph_weights[gl_InstanceID * u_morph_channels + channel], so a
// crowd's members each show their own. A position delta is in mesh units while a quantized
// position is in [0, 1] of the mesh bounds: it is multiplied by u_direction_prescale (1 /
// position_scale) to be added to a_position. Direction deltas are added to the decoded direction
// before the prescale, exactly as the CPU reference (apply_morphs, then skinning) does. A mesh
// without targets sets u_morph_channels = 0 and skips all of it.
//
// Simulated cloth (viewer/cloth_view.h): a mesh with cloth is skinned here like any other, and
// each of its cloth vertices then takes its particle's output instead. u_cloth_slots[gl_VertexID]
// is -1 for a skinned vertex, else particle * 2 + 1 where its normal is flipped (gpu_mesh.h);
// u_cloth_vertices holds two texels per particle and instance, from u_cloth_first and
// u_cloth_texels apart: the position and the normal where they are drawn, computed on the CPU
// exactly as the CPU-skinning path writes them, so both paths draw the same cloth. A mesh without
// live cloth sets u_cloth_texels = 0.
#version 330 core

layout(location = 0) in vec4 a_position;
layout(location = 1) in vec4 a_normal;
layout(location = 2) in vec4 a_tangent;
layout(location = 3) in vec2 a_uv;
layout(location = 4) in vec4 a_color;
layout(location = 5) in uvec4 a_joints;
layout(location = 6) in vec4 a_weights;

uniform samplerBuffer u_palette;
uniform int u_palette_base;      // first texel of this mesh's palette for instance 0
uniform int u_instance_texels;   // texels from one instance's palettes to the next
uniform int u_normal_encoding;   // 0: xyz, 1: octahedral xy
uniform int u_tangent_encoding;  // 0: none, 1: octahedral xy + sign z, 2: xyz + sign w
uniform vec3 u_direction_prescale;
uniform mat4 u_view_projection;
uniform isamplerBuffer u_morph_ranges;  // RG32I, per vertex: first entry, entry count
uniform samplerBuffer u_morph_entries;  // RGBA32F, u_morph_texels per entry
uniform samplerBuffer u_morph_weights;  // R32F, per instance and channel
uniform int u_morph_channels;           // channels per instance; 0: no morphs for this mesh
uniform int u_morph_texels;             // 1: positions, 2: + normals, 3: + tangents
uniform isamplerBuffer u_cloth_slots;   // R32I, per vertex: -1, or particle * 2 + (normal flipped)
uniform samplerBuffer u_cloth_vertices; // RGBA32F, per instance and particle: position, normal
uniform int u_cloth_first;              // first texel of this mesh's cloth for instance 0
uniform int u_cloth_texels;             // texels from one instance's cloth to the next; 0: no cloth
uniform int u_cloth_normals;            // 1: the cloth's normals replace the skinned ones

out vec3 v_position;
out vec3 v_normal;
out vec4 v_tangent;
out vec2 v_uv;
out vec4 v_color;

vec3 octahedral_decode(vec2 e) {
  vec3 n = vec3(e, 1.0 - abs(e.x) - abs(e.y));
  float t = max(-n.z, 0.0);
  n.x += n.x >= 0.0 ? -t : t;
  n.y += n.y >= 0.0 ? -t : t;
  return normalize(n);
}

mat4 palette(uint slot) {
  int t = u_palette_base + gl_InstanceID * u_instance_texels + 4 * int(slot);
  return mat4(texelFetch(u_palette, t), texelFetch(u_palette, t + 1), texelFetch(u_palette, t + 2),
              texelFetch(u_palette, t + 3));
}

void main() {
  vec3 position = a_position.xyz;
  vec3 n = u_normal_encoding == 1 ? octahedral_decode(a_normal.xy) : a_normal.xyz;
  vec3 t = u_tangent_encoding == 1 ? octahedral_decode(a_tangent.xy) : a_tangent.xyz;
  float t_sign = (u_tangent_encoding == 1 ? a_tangent.z : a_tangent.w) < 0.0 ? -1.0 : 1.0;

  if (u_morph_channels > 0) {
    ivec2 range = texelFetch(u_morph_ranges, gl_VertexID).xy;
    int weights = gl_InstanceID * u_morph_channels;
    vec3 dp = vec3(0.0), dn = vec3(0.0), dt = vec3(0.0);
    for (int e = range.x; e < range.x + range.y; ++e) {
      int texel = e * u_morph_texels;
      vec4 entry = texelFetch(u_morph_entries, texel);
      float w = texelFetch(u_morph_weights, weights + int(entry.w)).r;
      dp += w * entry.xyz;
      if (u_morph_texels > 1) dn += w * texelFetch(u_morph_entries, texel + 1).xyz;
      if (u_morph_texels > 2) dt += w * texelFetch(u_morph_entries, texel + 2).xyz;
    }
    position += dp * u_direction_prescale;
    n += dn;
    t += dt;
  }

  mat4 skin = a_weights.x * palette(a_joints.x) + a_weights.y * palette(a_joints.y) +
              a_weights.z * palette(a_joints.z) + a_weights.w * palette(a_joints.w);
  vec4 world = skin * vec4(position, 1.0);
  mat3 linear = mat3(skin);

  v_normal = linear * (n * u_direction_prescale);
  v_tangent = u_tangent_encoding == 0 ? vec4(0.0) : vec4(linear * (t * u_direction_prescale), t_sign);

  if (u_cloth_texels > 0) {
    int slot = texelFetch(u_cloth_slots, gl_VertexID).r;
    if (slot >= 0) {
      int texel = u_cloth_first + gl_InstanceID * u_cloth_texels + 2 * (slot >> 1);
      world = vec4(texelFetch(u_cloth_vertices, texel).xyz, 1.0);
      vec3 cloth_normal = texelFetch(u_cloth_vertices, texel + 1).xyz;
      if (u_cloth_normals != 0) v_normal = (slot & 1) != 0 ? -cloth_normal : cloth_normal;
    }
  }

  v_position = world.xyz;
  v_uv = a_uv;
  v_color = a_color;
  gl_Position = u_view_projection * world;
}
