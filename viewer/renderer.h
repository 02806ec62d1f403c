// renderer.h — draws a scene: skinned meshes (GPU or CPU skinning), skeleton overlay, grid.
//
// Per frame the CPU work is per joint, never per vertex (on the GPU path): each instance's model
// matrices become palettes (ossa/skinning/skinning.h, with the bind matrices prepared once per mesh),
// the palettes of every instance and mesh go into one texture buffer, and each submesh is drawn
// once for all instances with glDrawElementsInstanced. The --cpu-skinning path instead runs
// skin_cpu per instance and streams the skinned floats into the mesh's CPU vertex array; it draws
// through the same shader with an identity palette, so the two paths differ only in who skins.
//
// Morph targets: every instance's channel weights (animation.h) go into one R32F texture buffer
// per frame, beside the palettes, and meshes with targets read them in the vertex shader through
// their entry lists (gpu_mesh.h, morphs.h). The CPU path morphs and skins those meshes with
// morph_and_skin_cpu (apply_morphs, then the same linear blend), from vertices decoded once here.
//
// Simulated cloth (cloth_view.h) on the GPU path: every instance's particle output, placed where it
// is drawn, goes into one RGBA32F texture buffer per frame (two texels a particle), and the cloth
// mesh is drawn instanced like the others, its cloth vertices read from there by gl_VertexID
// (gpu_mesh.h's map). The CPU work per frame is per particle, never per vertex of the mesh. A mesh
// whose cloth has no output yet for some instance, and the --cpu-skinning path, skin it with
// skin_cpu and write the particles over the streams (write_cloth_vertices), as before.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include <ossa/format/result.h>
#include "viewer/animation.h"
#include "viewer/bounds.h"
#include "viewer/camera.h"
#include "viewer/gpu_mesh.h"
#include "viewer/materials.h"
#include "viewer/morphs.h"
#include "viewer/scene.h"

namespace ossa::view {

struct ViewerCloth;

struct ViewToggles {
  bool wireframe = false;
  bool skeleton = false;
  bool grid = true;
  bool cpu_skinning = false;
  bool procedural = false;  // the procedural nodes' overlays (procedural_draw.h)
  bool mapping = false;     // the retarget mode's joint mapping (retarget_view.h)
  bool keep_frame = false;  // draw over what the viewport holds (no clear): a second character's pass
};

/// Milliseconds spent in each stage of a frame (CPU time; gpu_ms from a timer query, a frame
/// late, 0 until available).
struct FrameTimings {
  double sample_ms = 0, blend_ms = 0, graph_ms = 0, skin_ms = 0, draw_ms = 0, gpu_ms = 0;
  // Counts added per frame: cloth particles the vertex shader read, meshes skinned by skin_cpu
  // (instances x meshes).
  double shader_cloth_particles = 0, cpu_skinned_meshes = 0;
};

struct LineVertex {
  glm::vec3 position;
  glm::vec4 color;
};

/// Overlay geometry rebuilt on the CPU each frame (procedural_draw.h fills it; empty: nothing
/// drawn). The vectors keep their capacity, so a steady overlay allocates nothing per frame.
struct OverlayGeometry {
  std::vector<LineVertex> ground_fill;   // GL_TRIANGLES, translucent, depth-tested
  std::vector<LineVertex> ground_lines;  // GL_LINES, depth-tested
  std::vector<LineVertex> on_top;        // GL_LINES over everything: targets, springs, colliders
  void clear() {
    ground_fill.clear();
    ground_lines.clear();
    on_top.clear();
  }
  bool empty() const { return ground_fill.empty() && ground_lines.empty() && on_top.empty(); }
};

struct Renderer {
  GLuint mesh_program = 0, line_program = 0;
  struct {
    GLint palette, palette_base, instance_texels, normal_encoding, tangent_encoding, direction_prescale,
        view_projection, camera_position, light_direction, diffuse_color, opacity, diffuse_map, normal_map,
        specular_map, has_diffuse_map, has_normal_map, has_specular_map, flat_color, morph_ranges, morph_entries,
        morph_weights, morph_channels, morph_texels, occlusion_map, emissive_map, has_occlusion_map, has_emissive_map,
        emissive_color, cloth_slots, cloth_vertices, cloth_first, cloth_texels, cloth_normals;
  } mesh_uniforms{};
  struct {
    GLint view_projection, point_size;
  } line_uniforms{};

  // Palette texture buffer: RGBA32F, 4 texels per matrix; one identity matrix at the end serves
  // the CPU-skinning path.
  GLuint palette_buffer = 0, palette_texture = 0;
  // Morph weights texture buffer: R32F, instance * channels + channel.
  GLuint morph_weight_buffer = 0, morph_weight_texture = 0;
  // Cloth output texture buffer: RGBA32F, per mesh from cloth_first[m], instance-major, two texels
  // (position, normal) per particle; cloth_first[m] < 0: the mesh's cloth is not read by the shader.
  GLuint cloth_buffer = 0, cloth_texture = 0;
  GLint max_texels = 0;
  GLuint lines_vao = 0, lines_buffer = 0, grid_vao = 0, grid_buffer = 0;
  GLsizei grid_vertices = 0;
  GLuint timer_queries[2] = {0, 0};
  bool timer_pending[2] = {false, false};
  unsigned frame_index = 0;
  // Where render_frame's width x height viewport starts in the bound framebuffer: the window's
  // scene region beside the panel (layout.h); (0, 0) offscreen. The clear is scissored to it.
  int viewport_x = 0, viewport_y = 0;

  // The scene on the GPU.
  std::vector<GpuMesh> meshes;
  std::vector<GpuMaterial> materials;
  std::vector<std::vector<glm::mat4>> bind;  // prepare_bind_matrices, per mesh
  std::vector<uint32_t> palette_base;        // first matrix of each mesh's palette in an instance
  uint32_t instance_matrices = 0;            // matrices per instance (all meshes)
  std::vector<MorphBase> morph_base;         // per mesh: decoded for the CPU path (empty without targets)

  // Per-frame scratch, sized once.
  std::vector<glm::mat4> palette;
  std::vector<float> skinned_positions, skinned_normals, skinned_tangents;
  std::vector<float> morph_weights;
  std::vector<glm::vec4> cloth_texels;
  std::vector<int64_t> cloth_first;
  MorphScratch morph_scratch;
  std::vector<LineVertex> lines;
  OverlayGeometry overlay;  // drawn last by render_frame when not empty
};

/// Programs, the palette texture buffer, line buffers, timer queries. Errors carry the shader log.
Result<Renderer> create_renderer();
void destroy_renderer(Renderer& r);

/// Uploads the character's meshes (their file bytes as they are) and materials, prepares bind
/// matrices. `warnings` receives textures left out. Replaces any previous scene.
Status upload_scene(Renderer& r, const Scene& scene, std::vector<std::string>& warnings);
void release_scene(Renderer& r);

/// A ground grid under `area` at height `ground`, cells sized to the character.
void set_grid(Renderer& r, const Box& area, float ground, float character_radius);

/// Draws one frame into the bound framebuffer (viewport width x height). `offsets` places each
/// instance (crowd); the animator's model matrices must be current. Adds skin/draw timings.
/// Meshes with live cloth (`cloth`, cloth_view.h) are drawn with their simulated particles.
/// Errors: too many instances x joints for the palette buffer (or x morph channels).
Status render_frame(Renderer& r, const Scene& scene, const Animator& animator, std::span<const glm::vec3> offsets,
                    const OrbitCamera& camera, const ViewToggles& toggles, int width, int height, FrameTimings& timings,
                    const ViewerCloth* cloth = nullptr);

}  // namespace ossa::view
