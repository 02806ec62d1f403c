// first_frame_assimp.cpp — see first_frame_assimp.h.
#include "bench/first_frame_assimp.h"

#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <span>
#include <string>
#include <vector>

#include <assimp/Importer.hpp>
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <stb_image.h>

#include "cooker/import/import_scene.h"
#include "viewer/bounds.h"
#include "viewer/camera.h"
#include "viewer/gl_util.h"
#include "viewer/offscreen.h"
#include "viewer/window.h"

namespace ossa::bench {
namespace {

constexpr const char* kVertex = R"(#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_uv;
layout(location = 3) in uvec4 a_joints;
layout(location = 4) in vec4 a_weights;
uniform samplerBuffer u_palette;
uniform mat4 u_view_projection;
out vec3 v_normal; out vec3 v_position; out vec2 v_uv;
mat4 palette(uint s) { int t = 4 * int(s); return mat4(texelFetch(u_palette, t), texelFetch(u_palette, t + 1),
  texelFetch(u_palette, t + 2), texelFetch(u_palette, t + 3)); }
void main() {
  mat4 m = a_weights.x * palette(a_joints.x) + a_weights.y * palette(a_joints.y) + a_weights.z * palette(a_joints.z)
      + a_weights.w * palette(a_joints.w);
  vec4 p = m * vec4(a_position, 1.0);
  v_position = p.xyz; v_normal = mat3(m) * a_normal; v_uv = a_uv;
  gl_Position = u_view_projection * p;
})";

constexpr const char* kFragment = R"(#version 330 core
in vec3 v_normal; in vec3 v_position; in vec2 v_uv;
uniform vec3 u_eye; uniform vec3 u_light; uniform vec3 u_color; uniform sampler2D u_map; uniform bool u_has_map;
out vec4 o_color;
void main() {
  vec3 n = normalize(v_normal); vec3 v = normalize(u_eye - v_position); if (dot(n, v) < 0.0) n = -n;
  vec3 c = u_color; if (u_has_map) c *= texture(u_map, v_uv).rgb;
  float d = max(dot(n, u_light), 0.0); float s = 0.5 * pow(max(dot(v, reflect(-u_light, n)), 0.0), 32.0);
  o_color = vec4((0.1 + d + s) * c, 1.0);
})";

struct Vertex {
  float position[3];
  float normal[3];
  float uv[2];
  uint32_t joints[4];
  float weights[4];
};

struct DrawMesh {
  GLuint vao = 0;
  GLsizei indices = 0;
  size_t palette_first = 0;  // matrices
  GLuint texture = 0;
  glm::vec3 color{0.8f};
};

glm::mat4 to_glm(const aiMatrix4x4& m) { return glm::transpose(glm::make_mat4(&m.a1)); }

void globals(const aiNode* node, const glm::mat4& parent, std::map<std::string, glm::mat4>& out,
             std::map<const aiNode*, glm::mat4>& by_node) {
  const glm::mat4 g = parent * to_glm(node->mTransformation);
  out[node->mName.C_Str()] = g;
  by_node[node] = g;
  for (unsigned i = 0; i < node->mNumChildren; ++i) globals(node->mChildren[i], g, out, by_node);
}

void mesh_nodes(const aiNode* node, std::map<unsigned, const aiNode*>& out) {
  for (unsigned i = 0; i < node->mNumMeshes; ++i) out.emplace(node->mMeshes[i], node);
  for (unsigned i = 0; i < node->mNumChildren; ++i) mesh_nodes(node->mChildren[i], out);
}

uint64_t g_texture_bytes = 0;  // RGBA8 level 0 and the mips glGenerateMipmap makes

GLuint decode(const unsigned char* bytes, int size) {
  int w = 0, h = 0, c = 0;
  stbi_set_flip_vertically_on_load(1);
  unsigned char* p = stbi_load_from_memory(bytes, size, &w, &h, &c, 4);
  if (p == nullptr) return 0;
  GLuint t = 0;
  glGenTextures(1, &t);
  glBindTexture(GL_TEXTURE_2D, t);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE, p);
  glGenerateMipmap(GL_TEXTURE_2D);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  stbi_image_free(p);
  for (int lw = w, lh = h;; lw = std::max(1, lw / 2), lh = std::max(1, lh / 2)) {
    g_texture_bytes += static_cast<uint64_t>(lw) * static_cast<uint64_t>(lh) * 4;
    if (lw == 1 && lh == 1) break;
  }
  return t;
}

GLuint load_diffuse_texture(const aiScene& scene, const aiString& path, const std::filesystem::path& dir);

/// The material's diffuse map, decoded once per distinct path (meshes sharing a material, or
/// materials sharing an image, share the texture, as any viewer would).
std::map<std::string, GLuint> g_loaded;  // one source's textures by path (cleared per source)

GLuint diffuse_texture(const aiScene& scene, const aiMaterial& material, const std::filesystem::path& dir) {
  std::map<std::string, GLuint>& loaded = g_loaded;
  aiString path;
  if (material.GetTexture(aiTextureType_DIFFUSE, 0, &path) != AI_SUCCESS &&
      material.GetTexture(aiTextureType_BASE_COLOR, 0, &path) != AI_SUCCESS) {
    return 0;
  }
  const auto [it, added] = loaded.emplace(path.C_Str(), 0);
  if (added) it->second = load_diffuse_texture(scene, path, dir);
  return it->second;
}

GLuint load_diffuse_texture(const aiScene& scene, const aiString& path, const std::filesystem::path& dir) {
  if (const aiTexture* t = scene.GetEmbeddedTexture(path.C_Str())) {
    if (t->mHeight == 0) return decode(reinterpret_cast<const unsigned char*>(t->pcData), static_cast<int>(t->mWidth));
    return 0;  // raw texels: not in the samples
  }
  std::FILE* f = std::fopen((dir / path.C_Str()).string().c_str(), "rb");
  if (f == nullptr) return 0;
  std::vector<unsigned char> bytes;
  unsigned char buf[65536];
  for (size_t n; (n = std::fread(buf, 1, sizeof buf, f)) > 0;) bytes.insert(bytes.end(), buf, buf + n);
  std::fclose(f);
  return decode(bytes.data(), static_cast<int>(bytes.size()));
}

/// A new offscreen target of the frame's size, bound and cleared to the viewer's background.
Result<view::Offscreen> cleared_target(int width, int height, int samples) {
  Result<view::Offscreen> target = view::create_offscreen(width, height, samples);
  if (!target) return target;
  view::bind_offscreen(*target);
  glViewport(0, 0, width, height);
  glClearColor(0.17f, 0.18f, 0.2f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  return target;
}

/// Imports `source`, uploads it and draws one frame into a new offscreen target (a context must be
/// current), finished with glFinish.
Status draw_source(const std::string& source, int width, int height, int samples) {
  g_loaded.clear();
  Assimp::Importer importer;
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_PRESERVE_PIVOTS, false);
  // What a plain Assimp viewer asks for: the cooker's flags plus welding, normals and 4 weights.
  const aiScene* scene = importer.ReadFile(source, cook::assimp_import_flags() | aiProcess_JoinIdenticalVertices |
                                                       aiProcess_GenSmoothNormals | aiProcess_LimitBoneWeights);
  if (scene == nullptr || scene->mRootNode == nullptr) return Error{source + ": " + importer.GetErrorString()};

  std::map<std::string, glm::mat4> by_name;
  std::map<const aiNode*, glm::mat4> by_node;
  globals(scene->mRootNode, glm::mat4(1.0f), by_name, by_node);
  std::map<unsigned, const aiNode*> owner;
  mesh_nodes(scene->mRootNode, owner);

  std::vector<glm::mat4> palette;
  std::vector<DrawMesh> draws;
  view::Box bounds;
  const std::filesystem::path dir = std::filesystem::path(source).parent_path();
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh& mesh = *scene->mMeshes[m];
    if (!(mesh.mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
    DrawMesh d;
    d.palette_first = palette.size();
    std::vector<Vertex> vertices(mesh.mNumVertices);
    std::vector<int> used(mesh.mNumVertices, 0);
    for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
      Vertex& x = vertices[v];
      std::memcpy(x.position, &mesh.mVertices[v], 12);
      if (mesh.mNormals) std::memcpy(x.normal, &mesh.mNormals[v], 12);
      if (mesh.mTextureCoords[0]) {
        x.uv[0] = mesh.mTextureCoords[0][v].x;
        x.uv[1] = mesh.mTextureCoords[0][v].y;
      }
    }
    if (mesh.mNumBones == 0) {  // rigid: the node's placement
      const auto it = owner.find(m);
      palette.push_back(it != owner.end() ? by_node[it->second] : glm::mat4(1.0f));
      for (Vertex& x : vertices) x.weights[0] = 1.0f;
    }
    for (unsigned b = 0; b < mesh.mNumBones; ++b) {
      const aiBone& bone = *mesh.mBones[b];
      palette.push_back(by_name[bone.mName.C_Str()] * to_glm(bone.mOffsetMatrix));
      for (unsigned w = 0; w < bone.mNumWeights; ++w) {
        const unsigned v = bone.mWeights[w].mVertexId;
        if (v >= mesh.mNumVertices || used[v] >= 4) continue;
        vertices[v].joints[used[v]] = b;
        vertices[v].weights[used[v]] = bone.mWeights[w].mWeight;
        ++used[v];
      }
    }
    const glm::mat4 placement = palette[d.palette_first];
    for (const Vertex& x : vertices)
      bounds.add(glm::vec3(placement * glm::vec4(x.position[0], x.position[1], x.position[2], 1.0f)));
    std::vector<uint32_t> indices;
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      if (mesh.mFaces[f].mNumIndices != 3) continue;
      indices.insert(indices.end(), mesh.mFaces[f].mIndices, mesh.mFaces[f].mIndices + 3);
    }
    glGenVertexArrays(1, &d.vao);
    glBindVertexArray(d.vao);
    GLuint vb = 0, ib = 0;
    glGenBuffers(1, &vb);
    glBindBuffer(GL_ARRAY_BUFFER, vb);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertices.size() * sizeof(Vertex)), vertices.data(),
                 GL_STATIC_DRAW);
    glGenBuffers(1, &ib);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ib);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(indices.size() * 4), indices.data(), GL_STATIC_DRAW);
    const auto at = [](size_t offset) { return reinterpret_cast<const void*>(offset); };
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(Vertex), at(offsetof(Vertex, position)));
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(Vertex), at(offsetof(Vertex, normal)));
    glEnableVertexAttribArray(2);
    glVertexAttribPointer(2, 2, GL_FLOAT, GL_FALSE, sizeof(Vertex), at(offsetof(Vertex, uv)));
    glEnableVertexAttribArray(3);
    glVertexAttribIPointer(3, 4, GL_UNSIGNED_INT, sizeof(Vertex), at(offsetof(Vertex, joints)));
    glEnableVertexAttribArray(4);
    glVertexAttribPointer(4, 4, GL_FLOAT, GL_FALSE, sizeof(Vertex), at(offsetof(Vertex, weights)));
    d.indices = static_cast<GLsizei>(indices.size());
    if (mesh.mMaterialIndex < scene->mNumMaterials) {
      const aiMaterial& material = *scene->mMaterials[mesh.mMaterialIndex];
      aiColor3D c(0.8f, 0.8f, 0.8f);
      material.Get(AI_MATKEY_COLOR_DIFFUSE, c);
      d.color = glm::vec3(c.r, c.g, c.b);
      d.texture = diffuse_texture(*scene, material, dir);
    }
    draws.push_back(d);
  }

  Result<GLuint> program = view::build_program("assimp first frame", kVertex, kFragment);
  if (!program) return program.error();
  GLuint palette_buffer = 0, palette_texture = 0;
  glGenBuffers(1, &palette_buffer);
  glBindBuffer(GL_TEXTURE_BUFFER, palette_buffer);
  glGenTextures(1, &palette_texture);
  glBindTexture(GL_TEXTURE_BUFFER, palette_texture);
  glTexBuffer(GL_TEXTURE_BUFFER, GL_RGBA32F, palette_buffer);

  Result<view::Offscreen> target = cleared_target(width, height, samples);
  if (!target) return target.error();
  glEnable(GL_DEPTH_TEST);
  const float aspect = static_cast<float>(width) / static_cast<float>(height);
  const view::OrbitCamera camera = view::frame_box(bounds, 0.52f, 0.17f, aspect);
  const glm::mat4 vp = view::projection_matrix(camera, aspect) * view::view_matrix(camera);
  const glm::vec3 eye = view::eye_position(camera);
  glUseProgram(*program);
  glUniformMatrix4fv(glGetUniformLocation(*program, "u_view_projection"), 1, GL_FALSE, &vp[0][0]);
  glUniform3f(glGetUniformLocation(*program, "u_eye"), eye.x, eye.y, eye.z);
  const glm::vec3 light = glm::normalize(eye - camera.target + glm::vec3(0.0f, camera.distance, 0.0f));
  glUniform3f(glGetUniformLocation(*program, "u_light"), light.x, light.y, light.z);
  glUniform1i(glGetUniformLocation(*program, "u_palette"), 0);
  glUniform1i(glGetUniformLocation(*program, "u_map"), 1);
  for (const DrawMesh& d : draws) {
    // Each mesh's palette from its first matrix (bone indices are per mesh).
    glBindBuffer(GL_TEXTURE_BUFFER, palette_buffer);
    const size_t end = &d == &draws.back() ? palette.size() : (&d + 1)->palette_first;
    glBufferData(GL_TEXTURE_BUFFER, static_cast<GLsizeiptr>((end - d.palette_first) * sizeof(glm::mat4)),
                 palette.data() + d.palette_first, GL_STREAM_DRAW);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_BUFFER, palette_texture);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, d.texture);
    glUniform1i(glGetUniformLocation(*program, "u_has_map"), d.texture != 0);
    glUniform3f(glGetUniformLocation(*program, "u_color"), d.color.x, d.color.y, d.color.z);
    glBindVertexArray(d.vao);
    glDrawElements(GL_TRIANGLES, d.indices, GL_UNSIGNED_INT, nullptr);
  }
  glFinish();
  if (Status s = view::check_gl("the Assimp frame"); !s) return Error{source + ": " + s.message()};
  return {};
}

/// One window and context, then each source in turn as a viewer opening them one after another.
Status run(std::span<const std::string> sources, int width, int height, int samples,
           std::chrono::steady_clock::time_point start) {
  Result<view::Window> window = child_window();
  if (!window) return window.error();
  for (const std::string& source : sources)
    if (Status s = draw_source(source, width, height, samples); !s) return s;
  print_first_frame(g_texture_bytes, start);
  return {};
}

/// The floor both sides stand on: the same hidden window, context and offscreen framebuffer,
/// cleared and finished, with nothing loaded and nothing drawn.
Status run_empty(int width, int height, int samples, std::chrono::steady_clock::time_point start) {
  Result<view::Window> window = child_window();
  if (!window) return window.error();
  Result<view::Offscreen> target = cleared_target(width, height, samples);
  if (!target) return target.error();
  glFinish();
  if (Status s = view::check_gl("the empty frame"); !s) return s;
  print_first_frame(0, start);
  return {};
}

}  // namespace

Result<view::Window> child_window() {
  view::WindowOptions wo;
  wo.width = 64;
  wo.height = 64;
  wo.visible = false;
  return view::create_window(wo);
}

void print_first_frame(uint64_t texture_bytes, std::chrono::steady_clock::time_point start) {
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::printf("texture-bytes %llu\n", static_cast<unsigned long long>(texture_bytes));
  std::printf("first-frame-ms %.3f\n", ms);
  std::fflush(stdout);
}

int exit_status(const Status& status) {
  if (status) return 0;
  std::fprintf(stderr, "ossa-bench-first-frame: %s\n", status.message().c_str());
  return 1;
}

int run_empty_first_frame(int width, int height, int samples) {
  const auto start = std::chrono::steady_clock::now();
  return exit_status(run_empty(width, height, samples, start));
}

int run_assimp_first_frame(std::span<const std::string> sources, int width, int height, int samples) {
  const auto start = std::chrono::steady_clock::now();
  return exit_status(run(sources, width, height, samples, start));
}

}  // namespace ossa::bench
