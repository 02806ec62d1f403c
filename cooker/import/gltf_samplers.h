// gltf_samplers.h — glTF animation samplers read straight from the .gltf / .glb, and evaluated
// the way the glTF 2.0 specification defines them.
//
// Why the cooker reads glTF JSON next to Assimp: Assimp 5.2.5's glTF2 importer drops a sampler's
// `interpolation`. STEP keys come out as plain keys (so they would be interpolated linearly) and
// CUBICSPLINE keys lose their tangents (Assimp keeps the value element of each [in-tangent, value,
// out-tangent] triple). The importer (import_clips.cpp) therefore reads, for every animation, which
// channels step or curve and their keys from here, and resamples those channels itself.
//
// Shape: plain data in, plain data out, no Assimp type. read_gltf_animations() parses the JSON
// (nlohmann_json, its exceptions caught) and decodes only the samplers that are not LINEAR, since
// LINEAR keys are exactly what Assimp already gives; buffers are loaded only when such a sampler
// exists. A file-level problem (not JSON, a broken GLB container) is an Error; a problem with one
// sampler (accessor out of range, wrong type, times not increasing) is recorded on that sampler so
// the importer can warn and keep Assimp's keys for it alone. Nothing throws out of this file.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <ossa/format/result.h>

namespace ossa::cook::gltf {

enum class Interpolation : uint8_t { Linear, Step, CubicSpline };

/// What a channel animates; anything unknown is Other (not read).
enum class TargetPath : uint8_t { Translation, Rotation, Scale, Weights, Other };

struct Sampler {
  Interpolation interpolation = Interpolation::Linear;
  /// Seconds, finite and strictly increasing (checked). Empty for LINEAR samplers: not decoded.
  std::vector<float> times;
  /// `width` floats per output element, as stored: one element per key for STEP, three per key
  /// (in-tangent, value, out-tangent) for CUBICSPLINE. Normalized integer outputs are converted
  /// to float with the specification's formulas. Rotations are (x, y, z, w).
  std::vector<float> values;
  int width = 0;  // components per element: 3 (VEC3) or 4 (VEC4); weights: the mesh's target count
  /// A morph weights sampler (SCALAR output, `width` weights per element): never a rotation.
  bool weights = false;
  /// Non-empty when the sampler's keys could not be read: why, naming the accessor at fault.
  std::string error;
};

struct Channel {
  int node = -1;  // glTF node index, -1 when absent
  TargetPath path = TargetPath::Other;
  int sampler = -1;  // index into Animation::samplers, -1 when out of range
};

struct Animation {
  std::string name;  // "" when the file names none (Assimp then names the aiAnimation "")
  std::vector<Channel> channels;
  std::vector<Sampler> samplers;
};

struct Node {
  std::string name;           // "" when unnamed
  std::vector<int> children;  // glTF node indices, in the file's order
  int mesh = -1;              // glTF mesh index, -1 when none
};

/// A mesh's morph targets as the file names them (for weight channels).
struct MeshTargets {
  /// One per target: `extras.targetNames[i]`, or "target<i>" (the name the cooker gives an unnamed
  /// target on the mesh side too, import_meshes.cpp).
  std::vector<std::string> names;
};

struct Animations {
  std::vector<Node> nodes;
  /// Root nodes of the scene Assimp imports: `scene` when given, else scenes[0].
  std::vector<int> scene_roots;
  std::vector<Animation> animations;
  std::vector<MeshTargets> meshes;  // one per glTF mesh
  /// True when at least one sampler is STEP or CUBICSPLINE (only then are buffers read).
  bool any_nonlinear = false;
};

/// Weights samplers (channels with path "weights") are always decoded, whatever their
/// interpolation: Assimp 5.2.5 clamps negative weights and drops CUBICSPLINE tangents.
/// Reads the animation part of a .gltf or .glb file (by its first bytes, not its extension).
/// External buffers are resolved relative to the file; `data:` URIs must be base64.
/// Errors name the file and what is wrong. Cost: the JSON parse, plus reading the buffers that
/// STEP / CUBICSPLINE samplers use.
Result<Animations> read_gltf_animations(const std::string& path);

/// As read_gltf_animations, on bytes already in memory; `directory` resolves relative buffer URIs
/// and `label` starts every message (the file's path).
Result<Animations> parse_gltf_animations(const std::vector<uint8_t>& bytes, const std::string& directory,
                                         const std::string& label);

/// The name Assimp 5.2.5 gives the aiNode of glTF node `index`: the node's name, or "nodes[i]"
/// for an unnamed one (checked against Assimp by tests/cooker/gltf_sampler_test.cpp).
std::string assimp_node_name(const Animations& file, int index);

/// The sampler's value at `time` seconds, as the specification defines it: the first / last
/// value outside the keys, the held value for STEP, the Hermite spline for CUBICSPLINE (tangents
/// scaled by the key interval), a lerp (slerp for width 4) for LINEAR. A key up to `snap` seconds
/// after `time` counts as reached: a frame that should sit exactly on a key but was rounded a
/// hair before it gets that key's STEP value. Writes `width` doubles to out; rotations (width 4,
/// not weights) are slerped and normalized. Requires a sampler without error and with at least one key.
void evaluate(const Sampler& sampler, double time, double snap, double* out);

/// True when the sampler's curve is the straight line between its values, so Assimp's linear
/// keys already reproduce it: STEP whose consecutive values are equal, CUBICSPLINE whose
/// tangents are the chord slopes of their segments (constant or linear data exported as
/// cubic). Both within `tolerance`, relative to max(1, |value|). Such samplers need no resampling.
bool is_linear_equivalent(const Sampler& sampler, double tolerance = 1e-6);

}  // namespace ossa::cook::gltf
