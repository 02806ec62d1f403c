// renderer.cpp — see renderer.h.
#include "viewer/renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>

#include <ossa/skinning/skinning.h>
#include "viewer/cloth_view.h"
#include "viewer/gl_util.h"
#include "viewer/shader_sources.h"

namespace ossa::view {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

const void* byte_offset(size_t offset) { return reinterpret_cast<const void*>(static_cast<uintptr_t>(offset)); }

constexpr glm::vec4 kBackground{0.17f, 0.18f, 0.20f, 1.0f};
constexpr glm::vec4 kBoneColor{1.0f, 0.85f, 0.2f, 1.0f};
constexpr glm::vec4 kJointColor{1.0f, 0.35f, 0.15f, 1.0f};
constexpr glm::vec4 kWireColor{0.05f, 0.05f, 0.08f, 1.0f};

GLuint make_line_array(GLuint& buffer) {
  GLuint vao = 0;
  glGenVertexArrays(1, &vao);
  glBindVertexArray(vao);
  glGenBuffers(1, &buffer);
  glBindBuffer(GL_ARRAY_BUFFER, buffer);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(LineVertex), byte_offset(offsetof(LineVertex, position)));
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 4, GL_FLOAT, GL_FALSE, sizeof(LineVertex), byte_offset(offsetof(LineVertex, color)));
  glBindVertexArray(0);
  return vao;
}

void upload_lines(GLuint buffer, const std::vector<LineVertex>& v) {
  glBindBuffer(GL_ARRAY_BUFFER, buffer);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(v.size() * sizeof(LineVertex)), v.data(), GL_STREAM_DRAW);
}

template <class T>
void upload_stream(GLuint buffer, const std::vector<T>& v) {
  glBindBuffer(GL_ARRAY_BUFFER, buffer);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(v.size() * sizeof(T)), v.data(), GL_STREAM_DRAW);
}

/// Binds the submesh's material to the mesh program.
void bind_material(const Renderer& r, const GpuMaterial& m) {
  const auto& u = r.mesh_uniforms;
  glUniform3f(u.diffuse_color, m.diffuse.x, m.diffuse.y, m.diffuse.z);
  glUniform1f(u.opacity, m.opacity);
  glUniform3f(u.emissive_color, m.emissive.x, m.emissive.y, m.emissive.z);
  const struct {
    GLenum unit;
    GLuint map;
    GLint flag;
  } maps[] = {{GL_TEXTURE1, m.diffuse_map, u.has_diffuse_map},
              {GL_TEXTURE2, m.normal_map, u.has_normal_map},
              {GL_TEXTURE3, m.specular_map, u.has_specular_map},
              {GL_TEXTURE7, m.occlusion_map, u.has_occlusion_map},
              {GL_TEXTURE8, m.emissive_map, u.has_emissive_map}};
  for (const auto& map : maps) {
    glActiveTexture(map.unit);
    glBindTexture(GL_TEXTURE_2D, map.map);
    glUniform1i(map.flag, map.map != 0 ? 1 : 0);
  }
  glActiveTexture(GL_TEXTURE0);
}

/// Draws every submesh of `mesh` from the currently bound vertex array.
void draw_submeshes(const Renderer& r, const MeshView& view, const GpuMesh& mesh, GLsizei instances, bool shaded) {
  for (const fb::Submesh& s : view.submeshes()) {
    if (shaded) bind_material(r, r.materials[std::min<size_t>(s.material(), r.materials.size() - 1)]);
    glDrawElementsInstanced(GL_TRIANGLES, static_cast<GLsizei>(s.index_count()), mesh.index_type,
                            byte_offset(static_cast<size_t>(s.first_index()) * mesh.index_size), instances);
  }
}

void set_mesh_encoding(const Renderer& r, const GpuMesh& m, bool cpu_skinned) {
  const auto& u = r.mesh_uniforms;
  if (cpu_skinned) {  // skin_cpu wrote unit xyz normals and xyz + sign tangents, in world space
    glUniform1i(u.normal_encoding, static_cast<int>(NormalEncoding::Xyz));
    glUniform1i(u.tangent_encoding,
                static_cast<int>(m.has_tangents ? TangentEncoding::XyzSignW : TangentEncoding::None));
    glUniform3f(u.direction_prescale, 1.0f, 1.0f, 1.0f);
  } else {
    glUniform1i(u.normal_encoding, static_cast<int>(m.normal_encoding));
    glUniform1i(u.tangent_encoding, static_cast<int>(m.tangent_encoding));
    glUniform3f(u.direction_prescale, m.direction_prescale.x, m.direction_prescale.y, m.direction_prescale.z);
  }
}

/// Morph uniforms and textures for one mesh on the GPU path (none: the shader skips the loop).
void bind_mesh_morphs(const Renderer& r, const GpuMesh& m, size_t channels) {
  const auto& u = r.mesh_uniforms;
  if (!m.has_morphs() || channels == 0) {
    glUniform1i(u.morph_channels, 0);
    return;
  }
  glUniform1i(u.morph_channels, static_cast<GLint>(channels));
  glUniform1i(u.morph_texels, m.morph_texels);
  glActiveTexture(GL_TEXTURE4);
  glBindTexture(GL_TEXTURE_BUFFER, m.morph_range_texture);
  glActiveTexture(GL_TEXTURE5);
  glBindTexture(GL_TEXTURE_BUFFER, m.morph_entry_texture);
  glActiveTexture(GL_TEXTURE0);
}

/// Where a cloth particle is drawn: the character's motion through the world `w`, then the crowd
/// placement `o`. One definition for both skinning paths, so they draw the same bits.
glm::vec3 drawn_cloth_position(const glm::mat4& w, const glm::vec3& o, const glm::vec3& p) {
  return glm::vec3(w * glm::vec4(p, 1.0f)) + o;
}

/// The GPU path's cloth texels (renderer.h): for each mesh with cloth whose every instance has an
/// output, the particles' positions and normals where they are drawn (the character's motion through
/// the world, then the crowd placement: the same operations as the CPU path's), one upload. Sets
/// r.cloth_first per mesh (-1: drawn by the CPU path). Allocation-free once the vectors have grown.
/// O(instances * particles).
void upload_cloth(Renderer& r, const ViewerCloth* cloth, size_t instances, std::span<const glm::vec3> offsets,
                  bool cpu_skinning, FrameTimings& timings) {
  r.cloth_first.assign(r.meshes.size(), -1);
  r.cloth_texels.clear();
  if (cpu_skinning || cloth == nullptr || !cloth->enabled) return;
  size_t texels = 0;
  for (size_t m = 0; m < r.meshes.size(); ++m) {
    const GpuMesh& g = r.meshes[m];
    if (!g.has_cloth()) continue;
    bool ready = instances > 0;
    for (size_t i = 0; i < instances && ready; ++i) {
      const ClothInstance* c = cloth->find(i, m);
      ready = c != nullptr && c->particle_count() == g.cloth_particles && c->positions().size() == g.cloth_particles &&
              c->normals().size() == g.cloth_particles;
    }
    const size_t need = 2 * instances * g.cloth_particles;
    if (!ready || texels + need > static_cast<size_t>(r.max_texels)) continue;
    r.cloth_first[m] = static_cast<int64_t>(texels);
    texels += need;
  }
  if (texels == 0) return;
  r.cloth_texels.resize(texels);
  const glm::mat4& w = cloth->world;
  const glm::mat3 turn(w);
  for (const ClothSim& sim : cloth->sims) {  // instance-major, as find() sees them
    if (sim.mesh >= r.meshes.size() || r.cloth_first[sim.mesh] < 0 || sim.instance >= instances) continue;
    const glm::vec3 o = sim.instance < offsets.size() ? offsets[sim.instance] : glm::vec3(0.0f);
    const std::span<const glm::vec3> p = sim.state.positions(), n = sim.state.normals();
    glm::vec4* out = r.cloth_texels.data() + r.cloth_first[sim.mesh] + 2 * sim.instance * p.size();
    for (size_t k = 0; k < p.size(); ++k) {
      out[2 * k] = glm::vec4(drawn_cloth_position(w, o, p[k]), 1.0f);
      out[2 * k + 1] = glm::vec4(turn * n[k], 0.0f);
    }
    timings.shader_cloth_particles += static_cast<double>(p.size());
  }
  glBindBuffer(GL_TEXTURE_BUFFER, r.cloth_buffer);
  glBufferData(GL_TEXTURE_BUFFER, static_cast<GLsizeiptr>(texels * sizeof(glm::vec4)), r.cloth_texels.data(),
               GL_STREAM_DRAW);
}

/// Bones (joint to parent) and joints of every instance.
void build_skeleton_lines(Renderer& r, const Scene& scene, const Animator& animator, std::span<const glm::vec3> offsets,
                          size_t& bone_vertices) {
  r.lines.clear();
  const auto parents = scene.skeleton().parents();
  for (size_t i = 0; i < animator.instances.size(); ++i) {
    const auto& model = animator.instances[i].model;
    const glm::vec3 o = i < offsets.size() ? offsets[i] : glm::vec3(0.0f);
    for (size_t j = 0; j < model.size() && j < parents.size(); ++j) {
      if (parents[j] < 0) continue;
      r.lines.push_back({glm::vec3(model[static_cast<size_t>(parents[j])][3]) + o, kBoneColor});
      r.lines.push_back({glm::vec3(model[j][3]) + o, kBoneColor});
    }
  }
  bone_vertices = r.lines.size();
  for (size_t i = 0; i < animator.instances.size(); ++i) {
    const glm::vec3 o = i < offsets.size() ? offsets[i] : glm::vec3(0.0f);
    for (const glm::mat4& m : animator.instances[i].model) r.lines.push_back({glm::vec3(m[3]) + o, kJointColor});
  }
}

/// The procedural overlays (r.overlay): the ground patches depth-tested (the feet hide them where
/// they stand on them), then targets, springs and colliders on top, as the skeleton is.
void draw_overlay(Renderer& r, const glm::mat4& view_projection) {
  const OverlayGeometry& o = r.overlay;
  glUseProgram(r.line_program);
  glUniformMatrix4fv(r.line_uniforms.view_projection, 1, GL_FALSE, &view_projection[0][0]);
  glBindVertexArray(r.lines_vao);
  if (!o.ground_fill.empty()) {
    upload_lines(r.lines_buffer, o.ground_fill);
    glDepthMask(GL_FALSE);
    glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(o.ground_fill.size()));
    glDepthMask(GL_TRUE);
  }
  if (!o.ground_lines.empty()) {
    upload_lines(r.lines_buffer, o.ground_lines);
    glDrawArrays(GL_LINES, 0, static_cast<GLsizei>(o.ground_lines.size()));
  }
  if (!o.on_top.empty()) {
    upload_lines(r.lines_buffer, o.on_top);
    glDisable(GL_DEPTH_TEST);
    glDrawArrays(GL_LINES, 0, static_cast<GLsizei>(o.on_top.size()));
    glEnable(GL_DEPTH_TEST);
  }
}

}  // namespace

Result<Renderer> create_renderer() {
  Renderer r;
  Result<GLuint> mesh =
      build_program("skinned.vert.glsl + phong.frag.glsl", shaders::kSkinnedVert, shaders::kPhongFrag);
  if (!mesh) return mesh.error();
  r.mesh_program = *mesh;
  Result<GLuint> lines = build_program("lines.vert.glsl + lines.frag.glsl", shaders::kLinesVert, shaders::kLinesFrag);
  if (!lines) {
    glDeleteProgram(r.mesh_program);
    return lines.error();
  }
  r.line_program = *lines;

  auto& u = r.mesh_uniforms;
  const GLuint p = r.mesh_program;
  u.palette = glGetUniformLocation(p, "u_palette");
  u.palette_base = glGetUniformLocation(p, "u_palette_base");
  u.instance_texels = glGetUniformLocation(p, "u_instance_texels");
  u.normal_encoding = glGetUniformLocation(p, "u_normal_encoding");
  u.tangent_encoding = glGetUniformLocation(p, "u_tangent_encoding");
  u.direction_prescale = glGetUniformLocation(p, "u_direction_prescale");
  u.view_projection = glGetUniformLocation(p, "u_view_projection");
  u.camera_position = glGetUniformLocation(p, "u_camera_position");
  u.light_direction = glGetUniformLocation(p, "u_light_direction");
  u.diffuse_color = glGetUniformLocation(p, "u_diffuse_color");
  u.opacity = glGetUniformLocation(p, "u_opacity");
  u.diffuse_map = glGetUniformLocation(p, "u_diffuse_map");
  u.normal_map = glGetUniformLocation(p, "u_normal_map");
  u.specular_map = glGetUniformLocation(p, "u_specular_map");
  u.has_diffuse_map = glGetUniformLocation(p, "u_has_diffuse_map");
  u.has_normal_map = glGetUniformLocation(p, "u_has_normal_map");
  u.has_specular_map = glGetUniformLocation(p, "u_has_specular_map");
  u.flat_color = glGetUniformLocation(p, "u_flat_color");
  u.occlusion_map = glGetUniformLocation(p, "u_occlusion_map");
  u.emissive_map = glGetUniformLocation(p, "u_emissive_map");
  u.has_occlusion_map = glGetUniformLocation(p, "u_has_occlusion_map");
  u.has_emissive_map = glGetUniformLocation(p, "u_has_emissive_map");
  u.emissive_color = glGetUniformLocation(p, "u_emissive_color");
  u.morph_ranges = glGetUniformLocation(p, "u_morph_ranges");
  u.morph_entries = glGetUniformLocation(p, "u_morph_entries");
  u.morph_weights = glGetUniformLocation(p, "u_morph_weights");
  u.morph_channels = glGetUniformLocation(p, "u_morph_channels");
  u.morph_texels = glGetUniformLocation(p, "u_morph_texels");
  u.cloth_slots = glGetUniformLocation(p, "u_cloth_slots");
  u.cloth_vertices = glGetUniformLocation(p, "u_cloth_vertices");
  u.cloth_first = glGetUniformLocation(p, "u_cloth_first");
  u.cloth_texels = glGetUniformLocation(p, "u_cloth_texels");
  u.cloth_normals = glGetUniformLocation(p, "u_cloth_normals");
  r.line_uniforms.view_projection = glGetUniformLocation(r.line_program, "u_view_projection");
  r.line_uniforms.point_size = glGetUniformLocation(r.line_program, "u_point_size");

  // Texture units: 0 palette, 1 diffuse, 2 normal, 3 specular, 4 morph ranges, 5 morph entries,
  // 6 morph weights, 7 occlusion, 8 emissive, 9 cloth slots, 10 cloth vertices (each sampler type
  // on its own unit, as GL requires).
  glUseProgram(p);
  glUniform1i(u.palette, 0);
  glUniform1i(u.diffuse_map, 1);
  glUniform1i(u.normal_map, 2);
  glUniform1i(u.specular_map, 3);
  glUniform1i(u.morph_ranges, 4);
  glUniform1i(u.morph_entries, 5);
  glUniform1i(u.morph_weights, 6);
  glUniform1i(u.occlusion_map, 7);
  glUniform1i(u.emissive_map, 8);
  glUniform1i(u.cloth_slots, 9);
  glUniform1i(u.cloth_vertices, 10);
  glUniform1i(u.cloth_texels, 0);
  glUniform1i(u.morph_channels, 0);
  glUniform1i(u.morph_texels, 1);
  glUseProgram(0);

  make_texture_buffer(GL_RGBA32F, nullptr, sizeof(glm::mat4), GL_STREAM_DRAW, r.palette_buffer, r.palette_texture);
  glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &r.max_texels);
  make_texture_buffer(GL_R32F, nullptr, sizeof(float), GL_STREAM_DRAW, r.morph_weight_buffer, r.morph_weight_texture);
  make_texture_buffer(GL_RGBA32F, nullptr, sizeof(glm::vec4), GL_STREAM_DRAW, r.cloth_buffer, r.cloth_texture);

  r.lines_vao = make_line_array(r.lines_buffer);
  r.grid_vao = make_line_array(r.grid_buffer);
  glGenQueries(2, r.timer_queries);
  if (Status s = check_gl("creating the renderer"); !s) {
    destroy_renderer(r);
    return s.error();
  }
  return r;
}

void release_scene(Renderer& r) {
  for (GpuMesh& m : r.meshes) destroy_gpu_mesh(m);
  r.meshes.clear();
  destroy_materials(r.materials);
  r.bind.clear();
  r.palette_base.clear();
  r.morph_base.clear();
  r.instance_matrices = 0;
}

void destroy_renderer(Renderer& r) {
  release_scene(r);
  if (r.mesh_program) glDeleteProgram(r.mesh_program);
  if (r.line_program) glDeleteProgram(r.line_program);
  const GLuint buffers[] = {r.palette_buffer, r.morph_weight_buffer, r.cloth_buffer, r.lines_buffer, r.grid_buffer};
  for (GLuint b : buffers) {
    if (b) glDeleteBuffers(1, &b);
  }
  if (r.palette_texture) glDeleteTextures(1, &r.palette_texture);
  if (r.morph_weight_texture) glDeleteTextures(1, &r.morph_weight_texture);
  if (r.cloth_texture) glDeleteTextures(1, &r.cloth_texture);
  const GLuint arrays[] = {r.lines_vao, r.grid_vao};
  for (GLuint a : arrays) {
    if (a) glDeleteVertexArrays(1, &a);
  }
  if (r.timer_queries[0]) glDeleteQueries(2, r.timer_queries);
  r = Renderer{};
}

Status upload_scene(Renderer& r, const Scene& scene, std::vector<std::string>& warnings) {
  release_scene(r);
  const Asset& asset = scene.character();
  const std::string& path = scene.paths.front();
  for (size_t i = 0; i < asset.mesh_count(); ++i) {
    const MeshView view = asset.mesh(i);
    const std::span<const int32_t> targets =
        i < scene.morph_targets.size() ? std::span<const int32_t>(scene.morph_targets[i]) : std::span<const int32_t>();
    Result<GpuMesh> g = create_gpu_mesh(view, path, targets);
    if (!g) {
      release_scene(r);
      return g.error();
    }
    MorphBase base;
    if (g->has_morphs()) {
      Result<MorphBase> decoded = decode_morph_base(view);
      if (!decoded) {
        destroy_gpu_mesh(*g);
        release_scene(r);
        return Error{path + ": " + decoded.error().message};
      }
      base = std::move(*decoded);
    }
    r.morph_base.push_back(std::move(base));
    r.palette_base.push_back(r.instance_matrices);
    r.instance_matrices += g->palette_slots;
    std::vector<glm::mat4> bind(g->palette_slots);
    prepare_bind_matrices(view, bind);
    r.bind.push_back(std::move(bind));
    r.meshes.push_back(*g);
  }
  r.materials = create_materials(asset, path, warnings);
  return check_gl("uploading " + path);
}

void set_grid(Renderer& r, const Box& area, float ground, float character_radius) {
  const float cell = 0.5f * std::pow(10.0f, std::round(std::log10(std::max(character_radius, 1e-6f))));
  const glm::vec3 c = area.empty() ? glm::vec3(0.0f) : area.centre();
  const float half_extent =
      std::max(5.0f * character_radius, area.empty() ? 0.0f : 0.75f * std::max(area.size().x, area.size().z));
  const int n = std::clamp(static_cast<int>(std::ceil(half_extent / cell)), 1, 200);
  const float x0 = std::round(c.x / cell) * cell, z0 = std::round(c.z / cell) * cell;
  std::vector<LineVertex> v;
  const glm::vec4 minor{0.32f, 0.33f, 0.36f, 1.0f}, major{0.45f, 0.46f, 0.50f, 1.0f};
  for (int k = -n; k <= n; ++k) {
    const glm::vec4 col = (k % 5 == 0) ? major : minor;
    const float x = x0 + static_cast<float>(k) * cell, z = z0 + static_cast<float>(k) * cell;
    const float e = static_cast<float>(n) * cell;
    v.push_back({{x, ground, z0 - e}, col});
    v.push_back({{x, ground, z0 + e}, col});
    v.push_back({{x0 - e, ground, z}, col});
    v.push_back({{x0 + e, ground, z}, col});
  }
  glBindBuffer(GL_ARRAY_BUFFER, r.grid_buffer);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(v.size() * sizeof(LineVertex)), v.data(), GL_STATIC_DRAW);
  r.grid_vertices = static_cast<GLsizei>(v.size());
}

Status render_frame(Renderer& r, const Scene& scene, const Animator& animator, std::span<const glm::vec3> offsets,
                    const OrbitCamera& camera, const ViewToggles& toggles, int width, int height, FrameTimings& timings,
                    const ViewerCloth* cloth) {
  const Asset& asset = scene.character();
  const size_t instances = animator.instances.size();

  // ---- skin: palettes of every instance and mesh, one upload.
  auto t_skin = Clock::now();
  const size_t matrices = instances * r.instance_matrices + 1;
  if (matrices * 4 > static_cast<size_t>(r.max_texels)) {
    return Error{scene.paths.front() + ": " + std::to_string(instances) + " instances x " +
                 std::to_string(r.instance_matrices) + " palette matrices exceed this GL's texture buffer (" +
                 std::to_string(r.max_texels / 4) + " matrices)"};
  }
  r.palette.resize(matrices);
  for (size_t i = 0; i < instances; ++i) {
    const auto& model = animator.instances[i].model;
    const glm::vec3 o = i < offsets.size() ? offsets[i] : glm::vec3(0.0f);
    for (size_t m = 0; m < r.meshes.size(); ++m) {
      const std::span<glm::mat4> out(r.palette.data() + i * r.instance_matrices + r.palette_base[m],
                                     r.meshes[m].palette_slots);
      skinning_matrices(asset.mesh(m).joints(), r.bind[m], model, out);
      for (glm::mat4& p : out) p[3] += glm::vec4(o * p[3].w, 0.0f);  // translate(o) * p
    }
  }
  r.palette.back() = glm::mat4(1.0f);
  glBindBuffer(GL_TEXTURE_BUFFER, r.palette_buffer);
  glBufferData(GL_TEXTURE_BUFFER, static_cast<GLsizeiptr>(r.palette.size() * sizeof(glm::mat4)), r.palette.data(),
               GL_STREAM_DRAW);
  // Morph weights of every instance, one upload (only when some mesh has targets).
  const size_t channels = scene.morph_channels.size();
  const bool morphs =
      channels > 0 && std::any_of(r.meshes.begin(), r.meshes.end(), [](const GpuMesh& g) { return g.has_morphs(); });
  if (morphs) {
    if (instances * channels > static_cast<size_t>(r.max_texels)) {
      return Error{scene.paths.front() + ": " + std::to_string(instances) + " instances x " + std::to_string(channels) +
                   " morph channels exceed this GL's texture buffer (" + std::to_string(r.max_texels) + " texels)"};
    }
    r.morph_weights.resize(instances * channels);
    for (size_t i = 0; i < instances; ++i) {
      const std::vector<float>& w = animator.instances[i].morph_weights;
      std::copy_n(w.begin(), std::min(w.size(), channels),
                  r.morph_weights.begin() + static_cast<std::ptrdiff_t>(i * channels));
    }
    glBindBuffer(GL_TEXTURE_BUFFER, r.morph_weight_buffer);
    glBufferData(GL_TEXTURE_BUFFER, static_cast<GLsizeiptr>(r.morph_weights.size() * sizeof(float)),
                 r.morph_weights.data(), GL_STREAM_DRAW);
  }
  upload_cloth(r, cloth, instances, offsets, toggles.cpu_skinning, timings);
  timings.skin_ms += ms_since(t_skin);

  // ---- draw
  const auto t_draw = Clock::now();
  double cpu_skin_ms = 0.0;
  const unsigned slot = r.frame_index++ & 1u;
  if (r.timer_pending[slot]) {
    GLuint64 ns = 0;
    glGetQueryObjectui64v(r.timer_queries[slot], GL_QUERY_RESULT, &ns);
    timings.gpu_ms += static_cast<double>(ns) * 1e-6;
    r.timer_pending[slot] = false;
  }
  glBeginQuery(GL_TIME_ELAPSED, r.timer_queries[slot]);

  glViewport(r.viewport_x, r.viewport_y, width, height);
  glScissor(r.viewport_x, r.viewport_y, width, height);
  if (!toggles.keep_frame) {
    glEnable(GL_SCISSOR_TEST);
    glClearColor(kBackground.r, kBackground.g, kBackground.b, kBackground.a);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glDisable(GL_SCISSOR_TEST);
  }
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDisable(GL_CULL_FACE);
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);

  const float aspect = height > 0 ? static_cast<float>(width) / static_cast<float>(height) : 1.0f;
  const glm::mat4 view_projection = projection_matrix(camera, aspect) * view_matrix(camera);
  const glm::vec3 eye = eye_position(camera);
  const glm::mat4 v = view_matrix(camera);
  const glm::vec3 right(v[0][0], v[1][0], v[2][0]), up(v[0][1], v[1][1], v[2][1]), back(v[0][2], v[1][2], v[2][2]);
  const glm::vec3 light = glm::normalize(back + 0.8f * up + 0.4f * right);  // from above, behind the camera

  if (toggles.grid && r.grid_vertices > 0) {
    glUseProgram(r.line_program);
    glUniformMatrix4fv(r.line_uniforms.view_projection, 1, GL_FALSE, &view_projection[0][0]);
    glBindVertexArray(r.grid_vao);
    glDrawArrays(GL_LINES, 0, r.grid_vertices);
  }

  glUseProgram(r.mesh_program);
  const auto& u = r.mesh_uniforms;
  glUniformMatrix4fv(u.view_projection, 1, GL_FALSE, &view_projection[0][0]);
  glUniform3f(u.camera_position, eye.x, eye.y, eye.z);
  glUniform3f(u.light_direction, light.x, light.y, light.z);
  glActiveTexture(GL_TEXTURE6);
  glBindTexture(GL_TEXTURE_BUFFER, r.morph_weight_texture);
  glActiveTexture(GL_TEXTURE10);
  glBindTexture(GL_TEXTURE_BUFFER, r.cloth_texture);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_BUFFER, r.palette_texture);
  set_default_attributes();

  const int passes = toggles.wireframe ? 2 : 1;
  for (int pass = 0; pass < passes; ++pass) {
    const bool shaded = pass == 0;
    if (shaded) {
      glUniform4f(u.flat_color, 0.0f, 0.0f, 0.0f, 0.0f);
      if (toggles.wireframe) {
        glEnable(GL_POLYGON_OFFSET_FILL);
        glPolygonOffset(1.0f, 1.0f);
      }
    } else {
      glDisable(GL_POLYGON_OFFSET_FILL);
      glPolygonMode(GL_FRONT_AND_BACK, GL_LINE);
      glUniform4f(u.flat_color, kWireColor.r, kWireColor.g, kWireColor.b, kWireColor.a);
    }
    // Meshes with live cloth: on the GPU path their cloth vertices are read from r.cloth_texture
    // (upload_cloth); one whose cloth the shader cannot read yet is skinned on the CPU with its
    // particles written over the streams (cloth_view.h).
    const auto simulated = [&](size_t i, size_t m) { return cloth != nullptr && cloth->find(i, m) != nullptr; };
    const auto cpu_cloth = [&](size_t m) { return simulated(0, m) && r.cloth_first[m] < 0; };
    bool any_cpu_cloth = false;
    for (size_t m = 0; m < r.meshes.size(); ++m) any_cpu_cloth = any_cpu_cloth || cpu_cloth(m);
    if (!toggles.cpu_skinning) {
      glUniform1i(u.instance_texels, static_cast<GLint>(4 * r.instance_matrices));
      for (size_t m = 0; m < r.meshes.size(); ++m) {
        if (cpu_cloth(m)) continue;
        const GpuMesh& g = r.meshes[m];
        set_mesh_encoding(r, g, false);
        bind_mesh_morphs(r, g, morphs ? channels : 0);
        if (r.cloth_first[m] >= 0) {
          glUniform1i(u.cloth_first, static_cast<GLint>(r.cloth_first[m]));
          glUniform1i(u.cloth_texels, static_cast<GLint>(2 * g.cloth_particles));
          glUniform1i(u.cloth_normals, g.has_normals ? 1 : 0);
          glActiveTexture(GL_TEXTURE9);
          glBindTexture(GL_TEXTURE_BUFFER, g.cloth_slot_texture);
          glActiveTexture(GL_TEXTURE0);
        }
        glUniform1i(u.palette_base, static_cast<GLint>(4 * r.palette_base[m]));
        glBindVertexArray(g.vao);
        draw_submeshes(r, asset.mesh(m), g, static_cast<GLsizei>(instances), shaded);
        glUniform1i(u.cloth_texels, 0);
      }
    }
    if (toggles.cpu_skinning || any_cpu_cloth) {
      // Reference path: skin_cpu per instance and mesh, drawn with the identity palette entry.
      glUniform1i(u.instance_texels, 0);
      glUniform1i(u.palette_base, static_cast<GLint>(4 * (matrices - 1)));
      glUniform1i(u.morph_channels, 0);  // morphed on the CPU
      for (size_t i = 0; i < instances; ++i) {
        for (size_t m = 0; m < r.meshes.size(); ++m) {
          if (!toggles.cpu_skinning && !cpu_cloth(m)) continue;
          if (shaded) timings.cpu_skinned_meshes += 1.0;
          const GpuMesh& g = r.meshes[m];
          const MeshView view = asset.mesh(m);
          const auto t0 = Clock::now();
          const size_t n = view.vertex_count();
          r.skinned_positions.resize(3 * n);
          r.skinned_normals.resize(g.has_normals ? 3 * n : 0);
          r.skinned_tangents.resize(g.has_tangents ? 4 * n : 0);
          const std::span<const glm::mat4> palette(r.palette.data() + i * r.instance_matrices + r.palette_base[m],
                                                   g.palette_slots);
          const SkinnedStreams out{r.skinned_positions, r.skinned_normals, r.skinned_tangents};
          const bool morphed = g.has_morphs() && m < scene.morph_targets.size() &&
                               morph_and_skin_cpu(view, r.morph_base[m], scene.morph_targets[m],
                                                  animator.instances[i].morph_weights, palette, r.morph_scratch, out);
          if (!morphed) skin_cpu(view, palette, SkinningMethod::Linear, out);
          if (const ClothInstance* c = cloth != nullptr ? cloth->find(i, m) : nullptr;
              c != nullptr && c->positions().size() == c->particle_count()) {
            (void)write_cloth_vertices(*c, r.skinned_positions, r.skinned_normals);  // the character's own space
            // Then where it is drawn: its motion through the world (cloth_view.h), the crowd placement.
            const glm::vec3 o = i < offsets.size() ? offsets[i] : glm::vec3(0.0f);
            const glm::mat4& w = cloth->world;
            const glm::mat3 turn(w);
            const bool normals = r.skinned_normals.size() == r.skinned_positions.size();
            for (const uint32_t cv : c->source.vertices) {
              float* p = &r.skinned_positions[3 * static_cast<size_t>(cv)];
              const glm::vec3 q = drawn_cloth_position(w, o, glm::vec3(p[0], p[1], p[2]));
              p[0] = q.x;
              p[1] = q.y;
              p[2] = q.z;
              if (!normals) continue;
              float* nv = &r.skinned_normals[3 * static_cast<size_t>(cv)];
              const glm::vec3 turned = turn * glm::vec3(nv[0], nv[1], nv[2]);
              nv[0] = turned.x;
              nv[1] = turned.y;
              nv[2] = turned.z;
            }
          }
          upload_stream(g.cpu_positions, r.skinned_positions);
          if (g.has_normals) upload_stream(g.cpu_normals, r.skinned_normals);
          if (g.has_tangents) upload_stream(g.cpu_tangents, r.skinned_tangents);
          cpu_skin_ms += ms_since(t0);
          set_mesh_encoding(r, g, true);
          glBindVertexArray(g.cpu_vao);
          draw_submeshes(r, view, g, 1, shaded);
        }
      }
    }
  }
  glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
  glDisable(GL_POLYGON_OFFSET_FILL);

  if ((toggles.skeleton || shows_bones_only(scene)) && scene.joint_count() > 0) {
    size_t bone_vertices = 0;
    build_skeleton_lines(r, scene, animator, offsets, bone_vertices);
    upload_lines(r.lines_buffer, r.lines);
    glDisable(GL_DEPTH_TEST);  // the skeleton is inside the mesh: draw it on top
    glUseProgram(r.line_program);
    glUniformMatrix4fv(r.line_uniforms.view_projection, 1, GL_FALSE, &view_projection[0][0]);
    glUniform1f(r.line_uniforms.point_size, 6.0f);
    glEnable(GL_PROGRAM_POINT_SIZE);
    glBindVertexArray(r.lines_vao);
    glDrawArrays(GL_LINES, 0, static_cast<GLsizei>(bone_vertices));
    glDrawArrays(GL_POINTS, static_cast<GLint>(bone_vertices), static_cast<GLsizei>(r.lines.size() - bone_vertices));
    glDisable(GL_PROGRAM_POINT_SIZE);
    glEnable(GL_DEPTH_TEST);
  }
  if (!r.overlay.empty()) draw_overlay(r, view_projection);
  glBindVertexArray(0);
  glUseProgram(0);
  glEndQuery(GL_TIME_ELAPSED);
  r.timer_pending[slot] = true;

  timings.skin_ms += cpu_skin_ms;
  timings.draw_ms += ms_since(t_draw) - cpu_skin_ms;
  return {};
}

}  // namespace ossa::view
