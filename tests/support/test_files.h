// test_files.h — what several test suites share: a synthetic .ossa file built in memory, and the
// file-system / process helpers that tests driving files and command-line tools need.
//
// The synthetic file is described by a SyntheticSpec: plain data (names, parents, vertices,
// indices, keys ...) that make_valid_file serializes with FlatBufferBuilder. Its defaults describe
// a small but complete valid file, so a test that needs one specific defect edits one field
// (`spec.skeleton->parents[2] = 5`) and gets a file that is valid in every other respect; a test
// that checks what the runtime reads compares its views with the same spec. Derived values (the
// skeleton hash, inverse binds, quantization ranges, vertex bytes) are computed from the spec
// unless an optional override says otherwise, so they stay consistent when a test edits the data.
//
// Paths come from the environment CTest sets (tests/CMakeLists.txt: OSSA_SOURCE_DIR,
// OSSA_BIN_DIR, OSSA_SHARED_ASSETS, OSSA_TEST_TMP); when a variable is unset the fallback is the
// compile-time OSSA_TEST_SOURCE_DIR / _BIN_DIR / _SHARED_ASSETS / _TMP_DIR definition if the build
// gives one, else a path relative to the working directory.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <ossa/format/ossa_generated.h>

namespace ossa::test {

// ---------------------------------------------------------------------------------------------
// Synthetic .ossa files

struct SyntheticSkeleton {
  // A chain root -> spine -> head with a branch spine -> arm.
  std::vector<std::string> names = {"root", "spine", "head", "arm"};
  std::vector<int16_t> parents = {-1, 0, 1, 1};
  std::vector<fb::Vec3> translations = {{0, 0, 0}, {0, 1, 0}, {0, 1, 0}, {0.5f, 0.5f, 0}};
  std::vector<fb::Quat> rotations = {{0, 0, 0, 1}, {0, 0, 0, 1}, {0, 0, 0, 1}, {0, 0, 0.70710678f, 0.70710678f}};
  std::vector<fb::Vec3> scales = {{1, 1, 1}, {1, 1, 1}, {1, 1, 1}, {1, 1, 1}};
  /// Default: inverse of each joint's bind model matrix, computed from the three arrays above.
  std::optional<std::vector<fb::Mat4>> inverse_bind;
  /// Default: skeleton_hash(names, parents).
  std::optional<uint64_t> hash;
};

struct SyntheticVertex {
  fb::Vec3 position;
  fb::Vec3 normal;
  float u = 0, v = 0;
  std::array<uint16_t, 4> slots{};   // mesh-local joint slots
  std::array<uint8_t, 4> weights{};  // unorm8, summing to 255
};

/// A morph target as stored (ossa.fbs MorphTarget): listed vertices with int16 deltas times steps.
struct SyntheticMorphTarget {
  std::string name = "smile";
  std::vector<uint32_t> vertices = {4, 5};  // the head row of the default grid
  std::vector<int16_t> position_deltas = {0, 1000, 0, 0, 2000, 0};
  fb::Vec3 position_step{0.0001f, 0.0001f, 0.0001f};
  std::vector<int16_t> normal_deltas;  // empty: none
  fb::Vec3 normal_step{0, 0, 0};
  float default_weight = 0.0f;
};

/// A morph weight track as stored (ossa.fbs MorphTrack).
struct SyntheticMorphTrack {
  std::string name = "smile";
  std::vector<uint16_t> key_frames = {0, 30};
  std::vector<uint16_t> values = {0, 65535};
  float range_min = 0.0f;
  float range_extent = 1.0f;
};

/// A cloth region (ossa.fbs Cloth) over the default 2 x 3 grid: the bottom row (vertices 0, 1)
/// fixed, the rest simulated and tethered to it, stretch edges along the triangles' edges. Valid as
/// given; bad-input cases break one field.
struct SyntheticCloth {
  std::vector<uint32_t> particle_vertices = {0, 1, 2, 3, 4, 5};
  std::vector<float> inverse_masses = {0, 0, 1, 1, 1, 1};
  std::vector<float> max_distances;
  std::vector<uint32_t> vertices = {0, 1, 2, 3, 4, 5};
  std::vector<uint16_t> vertex_particles = {0, 1, 2, 3, 4, 5};
  std::vector<uint16_t> triangles = {0, 1, 2, 1, 3, 2, 2, 3, 4, 3, 5, 4};
  std::vector<fb::ClothEdge> stretch = {{0, 1, 1.0f}, {2, 3, 1.0f}, {4, 5, 1.0f}, {0, 2, 1.0f},
                                        {1, 3, 1.0f}, {2, 4, 1.0f}, {3, 5, 1.0f}};
  std::vector<fb::ClothTether> tethers = {{2, 0, 1.0f}, {3, 1, 1.0f}, {4, 0, 2.0f}, {5, 1, 2.0f}};
  std::vector<fb::ClothCollider> colliders = {{1, fb::Vec3(0, 0, 0), fb::Vec3(0, 1, 0), 0.1f}};
  float damping = 1.0f;
};

struct SyntheticMesh {
  std::string name = "body";
  /// A 2 x 3 grid of vertices up the spine: rows y = 0, 1, 2.
  std::vector<SyntheticVertex> vertices = default_vertices();
  /// Default: vertices.size(). Vertex bytes always hold vertices.size() * vertex_stride bytes.
  std::optional<uint32_t> vertex_count;
  uint16_t vertex_stride = 24;
  /// Each attribute is encoded from the vertices when its format suits its semantic and it fits
  /// in the stride; otherwise its bytes stay zero (that is how layout defects are written).
  std::vector<fb::VertexAttribute> layout = quantized_layout();
  fb::IndexFormat index_format = fb::IndexFormat::Uint16;
  std::vector<uint32_t> indices = {0, 1, 2, 1, 3, 2, 2, 3, 4, 3, 5, 4};
  size_t index_padding_bytes = 0;  // zero bytes appended after the encoded indices
  std::vector<fb::Submesh> submeshes = {{0, 6, 0}, {6, 6, 0}};
  std::vector<uint16_t> joints = {1, 2, 3};  // slot -> skeleton joint (spine, head, arm)
  /// Default: the skeleton's inverse bind of each slot's joint (identity when out of range).
  std::optional<std::vector<fb::Mat4>> inverse_bind;
  std::vector<SyntheticMorphTarget> morph_targets;  // none by default
  std::optional<SyntheticCloth> cloth;              // none by default

  /// Position Unorm16x4 @0, Normal Snorm16x2 @8, TexCoord0 Float16x2 @12, Joints Uint8x4 @16,
  /// Weights Unorm8x4 @20: stride 24, the cooker's default layout.
  static std::vector<fb::VertexAttribute> quantized_layout();
  static std::vector<SyntheticVertex> default_vertices();
};

/// A channel with one value (ossa.fbs ConstantChannel): xyz for translation/scale, xyzw rotation
/// (written as its three components other than the largest). The optional fields override what
/// is derived, which is how defects are written.
struct SyntheticConstant {
  SyntheticConstant() = default;
  SyntheticConstant(uint16_t j, fb::Channel c, fb::Quat v) : joint(j), channel(c), value(v) {}
  uint16_t joint = 0;
  fb::Channel channel = fb::Channel::Translation;
  fb::Quat value{0, 0, 0, 0};
  std::optional<uint8_t> dropped;  // default: rotations the largest component, else 0
  std::optional<fb::Vec3> stored;  // default: from value
};

/// An animated channel given by its key frames and decoded-to-be values; make_valid_file packs
/// them with ossa/format/clip_codec.h (range-reduced to `bits`, or raw floats for bits == 32). The
/// optional fields override what is derived, which is how defects are written.
struct SyntheticAnimated {
  uint16_t joint = 0;
  fb::Channel channel = fb::Channel::Translation;
  uint8_t bits = 16;                             // 1..19, or 32 (raw floats): every component's width
  std::optional<std::array<uint8_t, 3>> widths;  // per stored component instead of `bits`
  /// Rotations: the component not stored (0..3 = x, y, z, w). Default: 3 (w) for rotations, 0
  /// for other channels (which store 0).
  std::optional<uint8_t> dropped;
  std::vector<uint16_t> frames;  // one per key (not written when there is one per frame)
  /// One per key, as stored: rotations give the three components other than `dropped` (in x, y,
  /// z, w order) of the unit quaternion taken with its dropped component >= 0.
  std::vector<std::array<float, 3>> values;
  std::optional<fb::Vec3> range_min;     // default: the values' minimum per component
  std::optional<fb::Vec3> range_extent;  // default: max - min
  std::optional<uint32_t> first_key;     // default: where its frames were appended
  std::optional<uint32_t> key_count;     // default: frames.size()
  std::optional<uint32_t> bit_offset;    // default: where its keys were packed
  /// Non-zero: the keys are written segmented (format v14, ossa/format/clip_codec.h) with data
  /// offsets of this many bits, each segment's minimum and widths the tightest for its codes.
  uint8_t segment_offset_bits = 0;
};

struct SyntheticRootMotion {
  std::vector<fb::Vec3> translations;  // one per frame
  std::vector<float> yaws;             // one per frame
  uint8_t up_axis = 1;
};

struct SyntheticClip {
  std::string name = "walk";
  float sample_rate = 30.0f;
  uint32_t frame_count = 31;
  std::optional<float> duration;          // default: (frame_count - 1) / sample_rate
  std::optional<uint64_t> skeleton_hash;  // default: the file skeleton's hash (0 without one)
  std::optional<uint16_t> joint_count;    // default: the file skeleton's joint count
  std::vector<SyntheticConstant> constants = default_constants();
  std::vector<SyntheticAnimated> animated = default_animated();
  /// Zero bytes after the packed keys (the decoder reads 64 bits at a time).
  uint32_t key_value_padding = 8;
  /// Replace the derived key_frames / key_values vectors wholesale.
  std::optional<std::vector<uint16_t>> key_frames;
  std::optional<std::vector<uint8_t>> key_values;
  /// Write a ClipCompression table (plausible numbers).
  bool compression = true;
  std::optional<SyntheticRootMotion> root_motion;
  /// Write empty channel vectors instead of leaving the fields out.
  bool write_empty_channels = false;
  /// Clip events (name, seconds), written when not empty.
  std::vector<std::pair<std::string, float>> events;
  /// Morph weight tracks (format v5), written when not empty.
  std::vector<SyntheticMorphTrack> morph_weights;

  float duration_value() const { return duration.value_or(static_cast<float>(frame_count - 1) / sample_rate); }

  /// spine: constant translation (0, 1, 0); head: constant rotation (30 degrees about z).
  static std::vector<SyntheticConstant> default_constants();
  /// spine rotation: 3 keys (frames 0, 15, 30: identity, 45 degrees about y, identity), 16 bits,
  /// w dropped;
  /// arm translation: 2 keys (frames 0, 30), 12 bits; arm scale: 4 raw-float keys (0, 8, 23, 30).
  static std::vector<SyntheticAnimated> default_animated();
};

struct SyntheticTexture {
  fb::TextureRole role = fb::TextureRole::Diffuse;
  std::string path;  // empty: field left out
  std::string mime;  // empty: field left out
  std::optional<std::vector<uint8_t>> data;
  // A cooked mip chain (format v7; ossa/loader/texture.h): Source leaves the rest out.
  fb::TextureEncoding encoding = fb::TextureEncoding::Source;
  bool srgb = false;
  uint32_t width = 0, height = 0;
  uint8_t mip_count = 0;
};

/// The default material's cooked specular map: a BC4 chain from 8 x 4 texels (40 bytes).
extern const std::vector<uint8_t> kBc4Chain;

struct SyntheticMaterial {
  std::string name = "skin";
  fb::Vec3 ambient{0.1f, 0.1f, 0.1f};
  fb::Vec3 diffuse{0.8f, 0.6f, 0.5f};
  fb::Vec3 specular{0.2f, 0.2f, 0.2f};
  float shininess = 16.0f;
  float opacity = 1.0f;
  std::optional<fb::Vec3> emissive;   // format v11
  std::optional<fb::PbrFactors> pbr;  // format v11
  /// An embedded 2x2 PNG (diffuse) and a normal map referenced by path.
  std::vector<SyntheticTexture> textures = default_textures();

  static std::vector<SyntheticTexture> default_textures();
};

/// A montage and the slot node it plays on (format v9), written with the synthetic graph: the slot
/// over the graph's root, the montage a segment of the first clip cut into sections with a window
/// notify. One field per stored value, so a bad-input case spoils exactly one.
struct SyntheticMontage {
  std::string name = "wave", group = "upper", slot = "upper", track_slot = "upper";
  uint16_t clip = 0;
  float start = 0.0f, end = 0.75f, segment_rate = 1.0f;
  std::vector<std::string> section_names = {"start", "loop"};
  std::vector<float> section_starts = {0.0f, 0.25f};
  std::vector<int16_t> section_next = {1, 1};
  std::string notify = "swing";
  float notify_time = 0.1f, notify_duration = 0.3f;
  fb::MontageNotifyKind notify_kind = fb::MontageNotifyKind::Window;
  float rate = 1.0f, blend_in = 0.2f, blend_out = 0.2f, trigger = -1.0f;
  fb::MontageCurve blend_in_curve = fb::MontageCurve::Cubic, blend_out_curve = fb::MontageCurve::Inertialize;
  uint16_t mask_joint = 1;
  int16_t mask_depth = -1;
  bool root_motion = false;
};

/// A retarget node (format v10), written with the synthetic graph beside its root (no node reads
/// it), playing a second graph clip "other_walk" made for another rig. One field per stored value,
/// so a bad-input case spoils exactly one.
struct SyntheticRetarget {
  uint16_t clip = 1;  // index into the graph's clips: 1 is the one added for it
  uint64_t source_hash = 0x5eed;
  uint16_t source_joints = 30;
  std::vector<int16_t> source_bones = std::vector<int16_t>(52, -1), target_bones = std::vector<int16_t>(52, -1);
  float rate = 1.0f, start = 0.0f;
  int16_t rate_parameter = 0;  // "speed"
  uint8_t source_rest = 0, target_rest = 1;
  uint16_t rest_joint = 2;  // one target rest rotation
  fb::Quat rest_rotation{0.0f, 0.0f, 0.0f, 1.0f};
  bool clip_node_plays_it = false;  // the graph's first clip node plays the retarget clip too
};

struct SyntheticSpec {
  std::string identifier = "OSSA";  // exactly 4 characters
  uint32_t version = default_version();
  float metres_per_unit = 1.0f;
  std::optional<SyntheticSkeleton> skeleton = SyntheticSkeleton{};
  std::vector<SyntheticMesh> meshes = {SyntheticMesh{}};
  std::vector<SyntheticClip> clips = {SyntheticClip{}};
  std::vector<SyntheticMaterial> materials = {SyntheticMaterial{}};
  bool provenance = true;
  /// Add an animation graph "g" over the skeleton and the first clip using every node kind, every
  /// parameter type, nested conditions and each transition mode (needs the default skeleton).
  bool graph = false;
  /// With `graph`: a slot node over its root and this montage (format v9).
  std::optional<SyntheticMontage> montage;
  /// With `graph`: a retarget node (format v10).
  std::optional<SyntheticRetarget> retarget;

  static uint32_t default_version();  // kFormatVersion
};

/// Serializes spec as a finished FlatBuffer (identifier included). With the default spec the
/// result is a valid .ossa file; vertex, index and texture bytes are 16-byte aligned in it.
std::vector<uint8_t> make_valid_file(const SyntheticSpec& spec = {});

/// Valid files of different shapes, by name: default, uint32-indices, float32-layout (16-bit joint
/// slots), static-mesh (no skeleton), clip-only, empty-channels (plus a clip without channels),
/// single-frame (a 1-frame clip of constants), root-motion, low-bits (1- and 3-bit keys), drop-y
/// (a rotation storing x, z, w in 19 bits), mixed-widths (a width per key component), two-meshes, graph (an animation
/// graph with a montage, and clip events), morph (a mesh with two morph targets and a clip driving them). For suites
/// that must not over-fit the default, and for seeding fuzz corpora.
std::vector<std::pair<std::string, SyntheticSpec>> valid_variants();

/// A 16-byte aligned copy of some bytes: what verify_buffer expects, and what a std::vector
/// does not promise.
class AlignedBytes {
 public:
  explicit AlignedBytes(std::span<const uint8_t> bytes);
  AlignedBytes(const AlignedBytes&) = delete;
  AlignedBytes& operator=(const AlignedBytes&) = delete;
  ~AlignedBytes();
  std::span<const uint8_t> span() const { return {data_, size_}; }

 private:
  uint8_t* data_ = nullptr;
  size_t size_ = 0;
};

// ---------------------------------------------------------------------------------------------
// Environment, files and processes

/// getenv(name), or fallback when unset or empty.
std::string env_or(const char* name, const char* fallback);
std::filesystem::path source_dir();     // OSSA_SOURCE_DIR (the repo root)
std::filesystem::path bin_dir();        // OSSA_BIN_DIR (where the tools are built)
std::filesystem::path shared_assets();  // OSSA_SHARED_ASSETS (may not exist)
/// tests/fixtures: files ossa-cook made, committed so suites that must not link the cooker (the
/// runtime's, in runtime-only and Windows builds too) read real cooked data. fixtures_test re-cooks
/// them (tests/fixtures/cook_fixtures.cmake) and fails when they are stale.
std::filesystem::path fixtures_dir();

/// A new, empty directory under OSSA_TEST_TMP (created as needed) named <prefix>-XXXXXX.
std::filesystem::path make_temp_dir(std::string_view prefix = "test");

/// A valid 2x2 RGBA PNG (decodes with stb_image): a texture file for cooker tests.
std::span<const uint8_t> tiny_png();

/// tiny_png with a tEXt chunk carrying `text` after its header: the same image, other bytes (a
/// texture that changed, or one whose bytes are recognisable when embedded as they are).
std::string tiny_png_with_text(std::string_view text);

/// Whole-file read; nullopt when the file cannot be opened or read.
std::optional<std::vector<uint8_t>> read_file(const std::filesystem::path& path);
std::optional<std::string> read_text(const std::filesystem::path& path);
/// Whole-file write (truncating); false on any failure.
bool write_file(const std::filesystem::path& path, std::span<const uint8_t> bytes);
/// Regular files below dir, recursively (0 when it does not exist).
size_t count_files(const std::filesystem::path& dir);
bool write_file(const std::filesystem::path& path, std::string_view text);

struct CommandResult {
  int exit_code = -1;  // the exit status, 128 + signal when killed, -1 when it could not start
  std::string out;
  std::string err;
};
/// (test_process.cpp) Runs `/bin/sh -c command` with stdout and stderr captured (through temporary files, so a
/// chatty tool cannot dead-lock on a full pipe) and waits for it.
CommandResult run_command(const std::string& command);

}  // namespace ossa::test
