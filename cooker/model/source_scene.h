// source_scene.h — what the import stage hands to the processing and writing stages.
//
// Plain float data in the conventions of the .ossa format (parents-first joints, model space =
// the skeleton root's parent space, seconds for time), but not yet quantized, optimized or
// serialized. Keeping Assimp types out of this struct is what lets mesh processing and writing
// be tested without importing anything, and keeps the importer the only Assimp-aware file.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

namespace ossa::cook {

struct SourceJoint {
  std::string name;
  int parent = -1;              // < own index; -1 for the root
  glm::vec3 translation{0.0f};  // bind pose, local to parent
  glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};
  glm::vec3 scale{1.0f};
  glm::mat4 inverse_bind{1.0f};  // inverse of the bind model-space matrix
};

struct SourceSkeleton {
  std::vector<SourceJoint> joints;  // parents first
  /// Length of one of its units in metres, when known (a cooked rig's File.metres_per_unit, a
  /// source's unit); 0 when unknown. Clips cooked against it are converted into its units.
  float metres_per_unit = 0.0f;
};

/// A morph target (blend shape) of one source mesh: dense deltas, one per vertex of the mesh,
/// added to the base vertex scaled by the target's weight (before skinning). Importers that give
/// targets as absolute values (Assimp does for glTF and FBX) subtract the base here.
struct SourceMorphTarget {
  std::string name;                  // unique within the mesh; binds clips' weight tracks
  std::vector<glm::vec3> positions;  // one per vertex
  std::vector<glm::vec3> normals;    // empty or one per vertex
  std::vector<glm::vec3> tangents;   // empty or one per vertex (direction only)
  float default_weight = 0.0f;       // glTF mesh.weights
};

/// One source mesh (Assimp splits by material, so one material each). Positions etc. are in mesh
/// space; joints are skeleton joint indices with the matching inverse bind in `bind`.
struct SourceMesh {
  std::string name;
  uint32_t material = 0;  // index into SourceScene::materials
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;   // empty or one per vertex, unit length
  std::vector<glm::vec4> tangents;  // empty or one per vertex: xyz unit, w = bitangent sign
  std::vector<glm::vec2> uv0;       // empty or one per vertex
  /// Empty or one per vertex: RGBA as the source stored it (glTF COLOR_0 is linear), the shader
  /// multiplies the material colour by it. The importer leaves it empty when every vertex is
  /// white, which draws exactly as no colours.
  std::vector<glm::vec4> colors;
  /// Up to 4 influences per vertex, largest first, weights summing to 1; unused slots have weight 0
  /// and joint 0. Empty when the mesh is not skinned (no skeleton in the file).
  std::vector<std::array<uint16_t, 4>> joints;
  std::vector<glm::vec4> weights;
  std::vector<uint32_t> indices;  // triangle list
  /// Skeleton joint -> the inverse bind matrix this mesh's skin uses for it. Sorted by joint,
  /// covering every joint referenced by `joints`.
  std::vector<std::pair<uint16_t, glm::mat4>> bind;
  std::vector<SourceMorphTarget> morph_targets;
  /// Empty or one per vertex: colour set 1 as the source stored it, which marks cloth
  /// (cooker/mesh/cloth_build.h reads it; it is not drawn).
  std::vector<glm::vec4> cloth_paint;
  /// Empty or one per vertex: what the mesh stage carries for cloth (cloth_build.h's
  /// cloth_attributes fill it: weight, max distance, backstop, 1).
  std::vector<glm::vec4> cloth;
};

struct SourceTrack {
  uint16_t joint = 0;
  std::vector<float> translation_times;  // seconds, strictly increasing
  std::vector<glm::vec3> translations;
  std::vector<float> rotation_times;
  std::vector<glm::quat> rotations;  // unit, neighbours on the same hemisphere
  std::vector<float> scale_times;
  std::vector<glm::vec3> scales;
};

/// Root motion taken out of a clip at cook time (cooker/clip/root_motion.h), one sample per frame of
/// the clip's frame grid (cooker/model/clip_grid.h), relative to frame 0.
struct SourceRootMotion {
  std::vector<glm::vec3> translations;
  std::vector<float> yaws;  // radians about up_axis
  uint8_t up_axis = 1;      // 0 x, 1 y, 2 z
};

/// A named marker at a time on a clip (sidecar JSON or graph file; see docs/GRAPH.md).
struct SourceEvent {
  std::string name;
  float time = 0.0f;  // seconds, in [0, duration]
};

/// One morph target's weight over a clip: keys in seconds, linear between (the importer resamples
/// STEP and CUBICSPLINE curves onto the clip's frame grid plus its key times).
struct SourceMorphTrack {
  std::string name;            // the targets it drives (SourceMorphTarget::name)
  std::vector<float> times;    // seconds, strictly increasing, at least one
  std::vector<float> weights;  // one per time
};

struct SourceClip {
  std::string name;
  /// The name the source gave the clip, when the cooker chose another (a file's single clip with a
  /// generic source name, "mixamo.com" or "Take 001", is named after the file); empty otherwise.
  /// Sidecars, cook settings and graph files may name a clip by either (clip_named).
  std::string source_name;
  float duration = 0.0f;            // seconds
  float sample_rate = 0.0f;         // source keys per second, 0 when unknown
  std::vector<SourceTrack> tracks;  // sorted by joint, one per animated joint
  bool has_root_motion = false;
  SourceRootMotion root_motion;                 // when has_root_motion
  std::vector<SourceEvent> events;              // sorted by time
  std::vector<SourceMorphTrack> morph_weights;  // sorted by name, names unique
};

/// Whether `name` names this clip: its cooked name, or the name its source gave it.
inline bool clip_named(const SourceClip& clip, const std::string& name) {
  return clip.name == name || (!clip.source_name.empty() && clip.source_name == name);
}

enum class TextureRole : uint8_t {
  Diffuse = 0,
  Normal = 1,
  Specular = 2,
  Occlusion = 3,
  MetallicRoughness = 4,
  Emissive = 5
};

struct SourceTexture {
  TextureRole role = TextureRole::Diffuse;
  std::string path;           // relative to the source file, when external
  std::string name;           // for messages and the report: the path, or the embedded image's name
  std::string mime;           // "image/png", "image/jpeg" when embedded
  std::vector<uint8_t> data;  // encoded bytes as the source had them, when embedded;
                              // after the texture stage, in `encoding`
  // Set by the texture stage (cooker/texture/texture_cook.h); the format's Texture fields.
  uint8_t encoding = 0;  // fb::TextureEncoding; 0: Source (data as read)
  bool srgb = false;
  uint32_t width = 0, height = 0;
  uint8_t mip_count = 0;
  /// >= 0: this texture is the same image in the same role as the scene's texture number
  /// `same_as` (counting every material's textures in order), which holds the data; the writer
  /// stores one Texture table for both.
  int32_t same_as = -1;
};

struct SourceMaterial {
  std::string name;
  glm::vec3 ambient{0.1f};
  glm::vec3 diffuse{0.8f};
  glm::vec3 specular{0.5f};
  float shininess = 32.0f;
  float opacity = 1.0f;
  std::vector<SourceTexture> textures;
  glm::vec3 emissive{0.0f};
  bool pbr = false;  // a PBR source (glTF): metallic and roughness below hold
  float metallic = 1.0f, roughness = 1.0f;
};

struct SourceScene {
  SourceSkeleton skeleton;  // empty for a file without joints
  std::vector<SourceMesh> meshes;
  std::vector<SourceClip> clips;
  std::vector<SourceMaterial> materials;
  float metres_per_unit = 1.0f;             // length of one source unit (FBX UnitScaleFactor / 100, ...)
  std::vector<std::string> warnings;        // human-readable, deterministic order
  uint32_t vertices_over_4_influences = 0;  // vertices that lost weight to the 4-influence cap
};

/// The skeleton hash of a SourceSkeleton (ossa/format/hash.h's skeleton_hash over its names and
/// parents): what clip-only files and graphs are bound by, the same value the loader recomputes.
uint64_t skeleton_hash_of(const SourceSkeleton& skeleton);

}  // namespace ossa::cook
