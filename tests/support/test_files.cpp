// test_files.cpp — see test_files.h. The writer here is deliberately independent of the cooker's
// (cooker/write_ossa.*): tests of the loader must not inherit the cooker's mistakes, and they need
// to write files the cooker never would.
#include "test_files.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <new>
#include <random>
#include <utility>

#include <flatbuffers/flatbuffers.h>
#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>

#include <ossa/format/clip_codec.h>
#include <ossa/format/hash.h>
#include <ossa/format/vertex_codec.h>
#include <ossa/format/vertex_format.h>
#include <ossa/version.h>

// Fallbacks when the environment does not say (a binary run by hand, or a CTest registration
// that lost the variables): tests/CMakeLists.txt may define these at compile time.
#ifndef OSSA_TEST_SOURCE_DIR
#define OSSA_TEST_SOURCE_DIR "."
#endif
#ifndef OSSA_TEST_BIN_DIR
#define OSSA_TEST_BIN_DIR "."
#endif
#ifndef OSSA_TEST_SHARED_ASSETS
#define OSSA_TEST_SHARED_ASSETS "../shared/assets"
#endif
#ifndef OSSA_TEST_TMP_DIR
#define OSSA_TEST_TMP_DIR "/tmp/ossa-test"
#endif

namespace ossa::test {
namespace {

// A 2x2 RGBA PNG (generated for these tests; CRCs and zlib stream are real).
constexpr uint8_t kTinyPng[] = {
    0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48, 0x44, 0x52, 0x00, 0x00, 0x00,
    0x02, 0x00, 0x00, 0x00, 0x02, 0x08, 0x06, 0x00, 0x00, 0x00, 0x72, 0xb6, 0x0d, 0x24, 0x00, 0x00, 0x00, 0x11, 0x49,
    0x44, 0x41, 0x54, 0x78, 0xda, 0x63, 0x38, 0x51, 0x11, 0xf5, 0x1f, 0x84, 0x19, 0x60, 0x0c, 0x00, 0x5c, 0x88, 0x0a,
    0x65, 0x38, 0xa8, 0x9b, 0x14, 0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82};

fb::Mat4 to_fb(const glm::mat4& m) {
  float columns[16];
  std::memcpy(columns, glm::value_ptr(m), sizeof columns);
  return fb::Mat4(flatbuffers::make_span(std::as_const(columns)));
}

// Inverse bind model matrix of every joint, from whatever bind pose entries exist.
std::vector<fb::Mat4> inverse_binds(const SyntheticSkeleton& s) {
  std::vector<glm::mat4> model(s.names.size(), glm::mat4(1.0f));
  std::vector<fb::Mat4> out;
  for (size_t i = 0; i < s.names.size(); ++i) {
    glm::mat4 local(1.0f);
    if (i < s.translations.size() && i < s.rotations.size() && i < s.scales.size()) {
      const fb::Vec3& t = s.translations[i];
      const fb::Quat& r = s.rotations[i];
      const fb::Vec3& sc = s.scales[i];
      local = glm::translate(glm::mat4(1.0f), glm::vec3(t.x(), t.y(), t.z())) *
              glm::mat4_cast(glm::quat(r.w(), r.x(), r.y(), r.z())) *
              glm::scale(glm::mat4(1.0f), glm::vec3(sc.x(), sc.y(), sc.z()));
    }
    const int parent = i < s.parents.size() ? s.parents[i] : -1;
    model[i] = parent >= 0 && static_cast<size_t>(parent) < i ? model[parent] * local : local;
    out.push_back(to_fb(glm::inverse(model[i])));
  }
  return out;
}

uint64_t hash_of(const SyntheticSkeleton& s) {
  std::vector<std::string_view> names(s.names.begin(), s.names.end());
  return skeleton_hash(names, s.parents);
}

template <class T>
void put(std::vector<uint8_t>& bytes, size_t at, T value) {
  std::memcpy(bytes.data() + at, &value, sizeof(T));
}

// Writes one attribute of one vertex at `at` when the format suits the semantic.
void encode_attribute(const fb::VertexAttribute& a, const SyntheticVertex& v, const fb::Vec3& offset,
                      const fb::Vec3& scale, std::vector<uint8_t>& bytes, size_t at) {
  using F = fb::VertexFormat;
  const F f = a.format();
  switch (a.semantic()) {
    case fb::VertexSemantic::Position: {
      const float p[3] = {v.position.x(), v.position.y(), v.position.z()};
      if (f == F::Unorm16x4) {
        const float o[3] = {offset.x(), offset.y(), offset.z()}, s[3] = {scale.x(), scale.y(), scale.z()};
        for (int c = 0; c < 3; ++c) put(bytes, at + 2 * c, float_to_unorm16((p[c] - o[c]) / s[c]));
      } else if (f == F::Float32x3 || f == F::Float32x4) {
        for (int c = 0; c < 3; ++c) put(bytes, at + 4 * c, p[c]);
        if (f == F::Float32x4) put(bytes, at + 12, 1.0f);
      }
      break;
    }
    case fb::VertexSemantic::Normal:
      if (f == F::Snorm16x2) {
        const Float2 e = octahedral_encode({v.normal.x(), v.normal.y(), v.normal.z()});
        put(bytes, at, float_to_snorm16(e.x));
        put(bytes, at + 2, float_to_snorm16(e.y));
      } else if (f == F::Float32x3) {
        put(bytes, at, v.normal.x());
        put(bytes, at + 4, v.normal.y());
        put(bytes, at + 8, v.normal.z());
      }
      break;
    case fb::VertexSemantic::TexCoord0:
      if (f == F::Float16x2) {
        put(bytes, at, float_to_half(v.u));
        put(bytes, at + 2, float_to_half(v.v));
      } else if (f == F::Float32x2) {
        put(bytes, at, v.u);
        put(bytes, at + 4, v.v);
      }
      break;
    case fb::VertexSemantic::Joints:
      for (int c = 0; c < 4; ++c) {
        if (f == F::Uint8x4) put(bytes, at + c, static_cast<uint8_t>(v.slots[c]));
        if (f == F::Uint16x4) put(bytes, at + 2 * c, v.slots[c]);
      }
      break;
    case fb::VertexSemantic::Weights:
      if (f == F::Unorm8x4)
        for (int c = 0; c < 4; ++c) put(bytes, at + c, v.weights[c]);
      break;
    default: break;  // Tangent, Color0: left zero
  }
}

flatbuffers::Offset<flatbuffers::Vector<uint8_t>> aligned_bytes(flatbuffers::FlatBufferBuilder& fbb,
                                                                const std::vector<uint8_t>& bytes) {
  fbb.ForceVectorAlignment(bytes.size(), 1, 16);
  return fbb.CreateVector(bytes);
}

flatbuffers::Offset<fb::Mesh> write_mesh(flatbuffers::FlatBufferBuilder& fbb, const SyntheticMesh& m,
                                         const std::vector<fb::Mat4>& skeleton_inverse_bind) {
  // Quantization range: the bounds of the positions (a zero extent quantizes with scale 1).
  fb::Vec3 lo(0, 0, 0), hi(0, 0, 0);
  if (!m.vertices.empty()) {
    float mn[3] = {INFINITY, INFINITY, INFINITY}, mx[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (const SyntheticVertex& v : m.vertices) {
      const float p[3] = {v.position.x(), v.position.y(), v.position.z()};
      for (int c = 0; c < 3; ++c) {
        mn[c] = std::min(mn[c], p[c]);
        mx[c] = std::max(mx[c], p[c]);
      }
    }
    lo = fb::Vec3(mn[0], mn[1], mn[2]);
    hi = fb::Vec3(mx[0], mx[1], mx[2]);
  }
  const auto extent = [](float a, float b) { return b > a ? b - a : 1.0f; };
  bool quantized = false;
  for (const fb::VertexAttribute& a : m.layout)
    quantized |= a.semantic() == fb::VertexSemantic::Position && a.format() == fb::VertexFormat::Unorm16x4;
  const fb::Vec3 offset = quantized ? lo : fb::Vec3(0, 0, 0);
  const fb::Vec3 scale =
      quantized ? fb::Vec3(extent(lo.x(), hi.x()), extent(lo.y(), hi.y()), extent(lo.z(), hi.z())) : fb::Vec3(1, 1, 1);

  std::vector<uint8_t> vertices(m.vertices.size() * m.vertex_stride, 0);
  for (size_t i = 0; i < m.vertices.size(); ++i) {
    for (const fb::VertexAttribute& a : m.layout) {
      const size_t size = vertex_format_info(a.format()).size;
      if (size == 0 || a.offset() + size > m.vertex_stride) continue;
      encode_attribute(a, m.vertices[i], offset, scale, vertices, i * m.vertex_stride + a.offset());
    }
  }

  std::vector<uint8_t> indices;
  for (uint32_t index : m.indices) {
    if (m.index_format == fb::IndexFormat::Uint16) {
      const auto i16 = static_cast<uint16_t>(index);
      indices.insert(indices.end(), reinterpret_cast<const uint8_t*>(&i16), reinterpret_cast<const uint8_t*>(&i16) + 2);
    } else {
      indices.insert(indices.end(), reinterpret_cast<const uint8_t*>(&index),
                     reinterpret_cast<const uint8_t*>(&index) + 4);
    }
  }
  indices.resize(indices.size() + m.index_padding_bytes, 0);

  std::vector<fb::Mat4> slot_inverse_bind;
  if (m.inverse_bind) {
    slot_inverse_bind = *m.inverse_bind;
  } else {
    for (uint16_t joint : m.joints)
      slot_inverse_bind.push_back(joint < skeleton_inverse_bind.size() ? skeleton_inverse_bind[joint]
                                                                       : to_fb(glm::mat4(1.0f)));
  }

  const auto name = fbb.CreateString(m.name);
  const auto layout = fbb.CreateVectorOfStructs(m.layout);
  const auto vertex_bytes = aligned_bytes(fbb, vertices);
  const auto index_bytes = aligned_bytes(fbb, indices);
  const auto submeshes = fbb.CreateVectorOfStructs(m.submeshes);
  const auto joints = fbb.CreateVector(m.joints);
  const auto inverse_bind = fbb.CreateVectorOfStructs(slot_inverse_bind);
  const uint32_t count = m.vertex_count.value_or(static_cast<uint32_t>(m.vertices.size()));
  std::vector<flatbuffers::Offset<fb::MorphTarget>> targets;
  for (const SyntheticMorphTarget& t : m.morph_targets) {
    const auto normal_deltas = t.normal_deltas.empty() ? 0 : fbb.CreateVector(t.normal_deltas);
    targets.push_back(fb::CreateMorphTarget(fbb, fbb.CreateString(t.name), fbb.CreateVector(t.vertices),
                                            fbb.CreateVector(t.position_deltas), &t.position_step, normal_deltas,
                                            &t.normal_step, 0, nullptr, t.default_weight, 0.0f, 0.0f));
  }
  const auto target_vector = targets.empty() ? 0 : fbb.CreateVector(targets);
  flatbuffers::Offset<fb::Cloth> cloth;
  if (const std::optional<SyntheticCloth>& c = m.cloth) {
    const auto max_distances = c->max_distances.empty() ? 0 : fbb.CreateVector(c->max_distances);
    const fb::Vec3 gravity(0, -9.81f, 0);
    cloth = fb::CreateCloth(fbb, fbb.CreateVector(c->particle_vertices), fbb.CreateVector(c->inverse_masses),
                            max_distances, 0, fbb.CreateVector(c->vertices), fbb.CreateVector(c->vertex_particles), 0,
                            fbb.CreateVector(c->triangles), fbb.CreateVectorOfStructs(c->stretch), 0,
                            fbb.CreateVectorOfStructs(c->tethers), fbb.CreateVectorOfStructs(c->colliders), 0.01f, 0.0f,
                            1e-4f, 1.0f, c->damping, 0.5f, &gravity);
  }
  return fb::CreateMesh(fbb, name, count, m.vertex_stride, layout, vertex_bytes, m.index_format, index_bytes, submeshes,
                        &lo, &hi, &offset, &scale, joints, inverse_bind, target_vector, cloth);
}

/// Writes quantized codes q (one per key) of a channel of widths w segmented (clip_codec.h), with
/// data offsets of `offset_bits` bits (truncated to them when too narrow).
void write_segmented(BitWriter& writer, const std::vector<std::array<uint32_t, 3>>& q, const KeyWidths& w,
                     uint32_t offset_bits) {
  const auto n = static_cast<uint32_t>(q.size());
  const uint32_t count = segment_count(n);
  std::vector<std::array<uint32_t, 3>> lo(count), width(count);
  for (uint32_t s = 0; s < count; ++s) {
    for (uint32_t c = 0; c < 3; ++c) {
      uint32_t a = quant_max(w.c[c]), b = 0;
      for (uint32_t k = s * kSegmentKeys; k < std::min(n, (s + 1) * kSegmentKeys); ++k) {
        a = std::min(a, q[k][c]);
        b = std::max(b, q[k][c]);
      }
      while (((b - a) >> width[s][c]) != 0) ++width[s][c];
      lo[s][c] = std::min(a, quant_max(w.c[c]) - quant_max(width[s][c]));
    }
  }
  uint64_t data = segment_header_bits(w, offset_bits) * count;
  for (uint32_t s = 0; s < count; ++s) {
    for (uint32_t c = 0; c < 3; ++c) writer.write(width[s][c], kSegmentWidthBits);
    writer.write(data, offset_bits);
    for (uint32_t c = 0; c < 3; ++c) writer.write(lo[s][c], w.c[c]);
    data += (uint64_t{width[s][0]} + width[s][1] + width[s][2]) * std::min(kSegmentKeys, n - s * kSegmentKeys);
  }
  for (uint32_t k = 0; k < n; ++k)
    for (uint32_t c = 0; c < 3; ++c) writer.write(q[k][c] - lo[k / kSegmentKeys][c], width[k / kSegmentKeys][c]);
}

flatbuffers::Offset<fb::Clip> write_clip(flatbuffers::FlatBufferBuilder& fbb, const SyntheticClip& c,
                                         uint64_t skeleton_hash, uint16_t joint_count) {
  // Pack every animated channel in order: frames appended to key_frames, keys to one bit stream.
  std::vector<uint16_t> key_frames;
  BitWriter writer;
  std::vector<fb::AnimatedChannel> animated;
  for (const SyntheticAnimated& a : c.animated) {
    float lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    for (size_t k = 0; k < a.values.size(); ++k)
      for (int i = 0; i < 3; ++i) {
        lo[i] = k == 0 ? a.values[k][i] : std::min(lo[i], a.values[k][i]);
        hi[i] = k == 0 ? a.values[k][i] : std::max(hi[i], a.values[k][i]);
      }
    const fb::Vec3 range_min = a.range_min.value_or(fb::Vec3(lo[0], lo[1], lo[2]));
    const fb::Vec3 range_extent = a.range_extent.value_or(fb::Vec3(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]));
    const float rmin[3] = {range_min.x(), range_min.y(), range_min.z()};
    const float rext[3] = {range_extent.x(), range_extent.y(), range_extent.z()};
    // A channel keyed at every frame stores no key frames (first_key 0).
    const uint32_t key_count = a.key_count.value_or(static_cast<uint32_t>(a.frames.size()));
    const bool every_frame = keyed_every_frame(static_cast<uint32_t>(a.frames.size()), c.frame_count);
    const auto first_key = every_frame ? 0u : static_cast<uint32_t>(key_frames.size());
    if (!every_frame) key_frames.insert(key_frames.end(), a.frames.begin(), a.frames.end());
    const std::array<uint8_t, 3> widths = a.widths.value_or(std::array<uint8_t, 3>{a.bits, a.bits, a.bits});
    if (widths[0] == kRawFloatBits) writer.align_byte();
    const auto bit_offset = static_cast<uint32_t>(writer.bit_size());
    const KeyWidths kw{{widths[0], widths[1], widths[2]}};
    const bool quantized = std::all_of(kw.c, kw.c + 3, [](uint32_t w) { return w >= 1 && w <= kMaxQuantBits; });
    if (a.segment_offset_bits != 0 && quantized) {
      std::vector<std::array<uint32_t, 3>> q;
      for (const auto& v : a.values)
        q.push_back({quantize(v[0], rmin[0], rext[0], kw.c[0]), quantize(v[1], rmin[1], rext[1], kw.c[1]),
                     quantize(v[2], rmin[2], rext[2], kw.c[2])});
      write_segmented(writer, q, kw, a.segment_offset_bits);
    } else {
      for (const auto& v : a.values) {
        for (int i = 0; i < 3; ++i) {
          if (widths[i] == kRawFloatBits) writer.write_float(v[i]);
          else if (widths[i] >= 1 && widths[i] <= kMaxQuantBits)
            writer.write(quantize(v[i], rmin[i], rext[i], widths[i]), widths[i]);
        }
      }
    }
    animated.emplace_back(a.joint, a.channel, flatbuffers::span<const uint8_t, 3>(widths),
                          a.dropped.value_or(a.channel == fb::Channel::Rotation ? 3 : 0), a.segment_offset_bits,
                          a.first_key.value_or(first_key), key_count, a.bit_offset.value_or(bit_offset), range_min,
                          range_extent);
  }
  std::vector<uint8_t> key_values = writer.finish();
  key_values.resize(key_values.size() - kKeyValuePadding + c.key_value_padding, 0);
  if (c.key_frames) key_frames = *c.key_frames;
  if (c.key_values) key_values = *c.key_values;

  std::vector<fb::ConstantChannel> constants;
  for (const SyntheticConstant& k : c.constants) {
    const float v[4] = {k.value.x(), k.value.y(), k.value.z(), k.value.w()};
    float stored[3] = {v[0], v[1], v[2]};
    uint8_t dropped = 0;
    if (k.channel == fb::Channel::Rotation) {  // the largest component left out, as the cooker does
      dropped = static_cast<uint8_t>(largest_component(v));
      rotation_to_stored(v, dropped, stored);
    }
    const uint8_t d = k.dropped.value_or(dropped);
    constants.emplace_back(k.joint, k.channel, d, k.stored.value_or(fb::Vec3(stored[0], stored[1], stored[2])));
  }

  const bool e = c.write_empty_channels;
  const auto name = fbb.CreateString(c.name);
  const auto constant_vector = constants.empty() && !e ? 0 : fbb.CreateVectorOfStructs(constants);
  const auto animated_vector = animated.empty() && !e ? 0 : fbb.CreateVectorOfStructs(animated);
  const auto frame_vector = key_frames.empty() && !e ? 0 : fbb.CreateVector(key_frames);
  // A clip without animated channels needs no key stream (nor its padding).
  const bool write_values = !animated.empty() || c.key_values || e;
  const auto value_vector = write_values ? aligned_bytes(fbb, key_values) : 0;
  const uint16_t joints = c.joint_count.value_or(joint_count);
  flatbuffers::Offset<fb::ClipCompression> compression = 0;
  if (c.compression) {
    const auto raw = static_cast<uint32_t>(10ull * 4 * joints * c.frame_count);
    compression = fb::CreateClipCompression(fbb, 0.0001f, 0.1f, 0.00005f, 0.00001f, 1, raw);
  }
  flatbuffers::Offset<fb::RootMotion> root_motion = 0;
  if (c.root_motion) {
    const auto translations = fbb.CreateVectorOfStructs(c.root_motion->translations);
    const auto yaws = fbb.CreateVector(c.root_motion->yaws);
    root_motion = fb::CreateRootMotion(fbb, translations, yaws, c.root_motion->up_axis);
  }
  std::vector<flatbuffers::Offset<fb::ClipEvent>> events;
  for (const auto& [event_name, time] : c.events)
    events.push_back(fb::CreateClipEventDirect(fbb, event_name.c_str(), time));
  const auto event_vector = events.empty() ? 0 : fbb.CreateVector(events);
  std::vector<flatbuffers::Offset<fb::MorphTrack>> tracks;
  for (const SyntheticMorphTrack& t : c.morph_weights)
    tracks.push_back(fb::CreateMorphTrack(fbb, fbb.CreateString(t.name), fbb.CreateVector(t.key_frames),
                                          fbb.CreateVector(t.values), t.range_min, t.range_extent, 0.0f));
  const auto track_vector = tracks.empty() ? 0 : fbb.CreateVector(tracks);
  return fb::CreateClip(fbb, name, c.duration_value(), c.sample_rate, c.frame_count,
                        c.skeleton_hash.value_or(skeleton_hash), joints, constant_vector, animated_vector, frame_vector,
                        value_vector, compression, root_motion, event_vector, track_vector);
}

/// The synthetic graph (SyntheticSpec::graph): every node kind (the procedural ones on top), parameter
/// type and transition mode.
/// The synthetic montage's tables: Graph.montages.
flatbuffers::Offset<flatbuffers::Vector<flatbuffers::Offset<fb::Montage>>> write_montages(
    flatbuffers::FlatBufferBuilder& fbb, const SyntheticMontage& m) {
  const std::vector<fb::MontageSegment> segments = {{m.clip, m.start, m.end, m.segment_rate}};
  std::vector<flatbuffers::Offset<fb::MontageTrack>> tracks = {
      fb::CreateMontageTrack(fbb, fbb.CreateString(m.track_slot), fbb.CreateVectorOfStructs(segments))};
  std::vector<flatbuffers::Offset<fb::MontageSection>> sections;
  for (size_t k = 0; k < m.section_starts.size(); ++k)
    sections.push_back(
        fb::CreateMontageSection(fbb, fbb.CreateString(k < m.section_names.size() ? m.section_names[k] : "s"),
                                 m.section_starts[k], k < m.section_next.size() ? m.section_next[k] : -1));
  std::vector<flatbuffers::Offset<fb::MontageNotify>> notifies = {
      fb::CreateMontageNotify(fbb, fbb.CreateString(m.notify), m.notify_time, m.notify_duration, m.notify_kind)};
  std::vector<flatbuffers::Offset<fb::Montage>> montages = {
      fb::CreateMontage(fbb, fbb.CreateString(m.name), fbb.CreateString(m.group), fbb.CreateVector(tracks),
                        fbb.CreateVector(sections), fbb.CreateVector(notifies), m.rate, m.blend_in, m.blend_in_curve,
                        m.blend_out, m.blend_out_curve, m.trigger, m.root_motion)};
  return fbb.CreateVector(montages);
}

flatbuffers::Offset<fb::Graph> write_graph(flatbuffers::FlatBufferBuilder& fbb, const std::string& clip,
                                           uint64_t skeleton_hash, uint16_t joint_count,
                                           const std::optional<SyntheticMontage>& montage,
                                           const std::optional<SyntheticRetarget>& retarget) {
  using PT = fb::ParameterType;
  std::vector<flatbuffers::Offset<fb::Parameter>> params;
  params.push_back(fb::CreateParameterDirect(fbb, "speed", PT::Float, 1.0f, 0.0f, 4.0f));
  params.push_back(fb::CreateParameterDirect(fbb, "flag", PT::Bool));
  params.push_back(fb::CreateParameterDirect(fbb, "go", PT::Trigger));
  std::vector<flatbuffers::Offset<flatbuffers::String>> values = {fbb.CreateString("a"), fbb.CreateString("b")};
  params.push_back(
      fb::CreateParameter(fbb, fbb.CreateString("mode"), PT::Enum, 0.0f, -3.4e38f, 3.4e38f, fbb.CreateVector(values)));
  params.push_back(fb::CreateParameterDirect(fbb, "count", PT::Int, 0.0f, 0.0f, 3.0f));
  const fb::Vec3 target_default(0.5f, 1.5f, 0.2f);
  params.push_back(fb::CreateParameter(fbb, fbb.CreateString("target"), PT::Vector, 0.0f, -3.4e38f, 3.4e38f, 0,
                                       &target_default, fb::ParameterSpace::World));  // 5
  const auto node = [&](fb::NodeData type, flatbuffers::Offset<void> data) {
    return fb::CreateNode(fbb, fbb.CreateString(""), type, data);
  };
  std::vector<flatbuffers::Offset<fb::Node>> nodes;
  const uint16_t first_clip = retarget && retarget->clip_node_plays_it ? retarget->clip : 0;
  nodes.push_back(node(fb::NodeData::ClipNode, fb::CreateClipNode(fbb, first_clip, 1.0f, 0).Union()));  // 0
  nodes.push_back(node(fb::NodeData::ClipNode, fb::CreateClipNode(fbb, 0, -1.0f, -1, false).Union()));  // 1
  nodes.push_back(node(fb::NodeData::BlendAlphaNode, fb::CreateBlendAlphaNode(fbb, 0, 1, 0).Union()));  // 2
  const std::vector<fb::BlendSample> samples = {{0, 0.0f, 0.0f}, {0, 2.0f, 0.0f}};
  nodes.push_back(node(fb::NodeData::BlendSpaceNode,
                       fb::CreateBlendSpaceNode(fbb, 0, -1, fbb.CreateVectorOfStructs(samples)).Union()));  // 3
  const std::vector<uint16_t> children = {2, 3};
  nodes.push_back(
      node(fb::NodeData::SelectNode, fb::CreateSelectNode(fbb, 3, fbb.CreateVector(children), 0.2f).Union()));  // 4
  nodes.push_back(node(fb::NodeData::ClipNode, fb::CreateClipNode(fbb, 0, 1.0f, -1, true, 0.5f).Union()));      // 5
  nodes.push_back(node(fb::NodeData::AdditiveNode, fb::CreateAdditiveNode(fbb, 4, 5, 0.5f).Union()));           // 6
  nodes.push_back(node(fb::NodeData::ClipNode, fb::CreateClipNode(fbb, 0).Union()));                            // 7
  nodes.push_back(node(fb::NodeData::StateMachineNode, fb::CreateStateMachineNode(fbb, 0).Union()));            // 8
  nodes.push_back(node(fb::NodeData::ClipNode, fb::CreateClipNode(fbb, 0).Union()));                            // 9
  const std::vector<fb::MaskEntry> mask = {{1, -1}};
  std::vector<flatbuffers::Offset<fb::Layer>> layers = {
      fb::CreateLayer(fbb, 9, fbb.CreateVectorOfStructs(mask), 1.0f, 1, 0.1f, true)};
  nodes.push_back(node(fb::NodeData::LayeredBlendNode,
                       fb::CreateLayeredBlendNode(fbb, 8, fbb.CreateVector(layers)).Union()));  // 10
  // Procedural nodes (format v6) over the chain 0 > 1 > 2, one of each kind.
  const fb::Vec3 pole(0.0f, 0.0f, 1.0f), axis(0.0f, 0.0f, 1.0f), up(0.0f, 1.0f, 0.0f), forward(0.0f, 0.0f, 1.0f);
  nodes.push_back(
      node(fb::NodeData::TwoBoneIkNode,
           fb::CreateTwoBoneIkNode(fbb, 10, 0, 1, 2, 5, -1, &pole, &axis, 0.1f, 0.95f, 1.0f, 0).Union()));  // 11
  const std::vector<fb::AimJoint> aim = {{1, 0.5f, 1.0f}, {2, 1.0f, 3.2f}};
  nodes.push_back(
      node(fb::NodeData::AimNode,
           fb::CreateAimNode(fbb, 11, fbb.CreateVectorOfStructs(aim), 5, &forward, &up, &up, 1.0f, 1).Union()));  // 12
  const auto leg = [&](bool lock) {
    return fb::CreateFootLeg(fbb, 0, 1, 2, lock ? -1 : 0, lock ? -1 : 5, lock ? 1 : -1,
                             fbb.CreateString(lock ? "plant" : ""), fbb.CreateString(lock ? "lift" : ""));
  };
  std::vector<flatbuffers::Offset<fb::FootLeg>> place_legs = {leg(false)}, lock_legs = {leg(true)};
  nodes.push_back(
      node(fb::NodeData::FootPlacementNode,
           fb::CreateFootPlacementNode(fbb, 12, 0, fbb.CreateVector(place_legs), &up, 0.3f).Union()));  // 13
  nodes.push_back(node(fb::NodeData::FootLockNode,
                       fb::CreateFootLockNode(fbb, 13, fbb.CreateVector(lock_legs), 0.2f, 0.1f).Union()));  // 14
  const std::vector<uint16_t> spring_joints = {1, 2};
  const fb::Vec3 gravity(0.0f, -9.81f, 0.0f);
  std::vector<flatbuffers::Offset<fb::SpringChainSettings>> chains = {
      fb::CreateSpringChainSettings(fbb, fbb.CreateVector(spring_joints), 4.0f, 0.4f, &gravity, 0.05f, 0.5f)};
  const std::vector<fb::SpringColliderShape> colliders = {{0, {0.0f, 0.5f, 0.0f}, {0.0f, 1.0f, 0.0f}, 0.2f}};
  nodes.push_back(
      node(fb::NodeData::SpringNode, fb::CreateSpringNode(fbb, 14, fbb.CreateVector(chains),
                                                          fbb.CreateVectorOfStructs(colliders), 1.0f / 120.0f, 10.0f)
                                         .Union()));  // 15

  using Op = fb::ConditionOp;
  const std::vector<fb::ConditionInstr> go = {{Op::Trigger, 2, 0.0f}};
  // (speed > 1 && !flag) || count == 2
  const std::vector<fb::ConditionInstr> back = {{Op::Greater, 0, 1.0f}, {Op::Bool, 1, 0.0f},  {Op::Not, 0, 0.0f},
                                                {Op::And, 0, 0.0f},     {Op::Equal, 4, 2.0f}, {Op::Or, 0, 0.0f}};
  const std::vector<fb::ConditionInstr> flag = {{Op::Bool, 1, 0.0f}};
  std::vector<flatbuffers::Offset<fb::Transition>> transitions = {
      fb::CreateTransition(fbb, 0, 1, fbb.CreateVectorOfStructs(go), -1.0f, 0.2f, fb::TransitionMode::Crossfade),
      fb::CreateTransition(fbb, 1, 0, fbb.CreateVectorOfStructs(back), 0.5f, 0.3f, fb::TransitionMode::SyncCrossfade),
      fb::CreateTransition(fbb, -1, 0, fbb.CreateVectorOfStructs(flag), -1.0f, 0.1f, fb::TransitionMode::Inertialize)};
  std::vector<flatbuffers::Offset<fb::State>> states = {fb::CreateStateDirect(fbb, "s0", 6, true),
                                                        fb::CreateStateDirect(fbb, "s1", 7, false)};
  std::vector<flatbuffers::Offset<fb::StateMachine>> machines = {
      fb::CreateStateMachine(fbb, fbb.CreateString("m"), fbb.CreateVector(states), 0, fbb.CreateVector(transitions))};
  uint16_t root = 15;
  flatbuffers::Offset<flatbuffers::Vector<flatbuffers::Offset<fb::Montage>>> montages_v;
  if (montage) {  // format v9: a slot over the root, and the montage playing on it
    const std::vector<fb::MaskEntry> slot_mask = {{montage->mask_joint, montage->mask_depth}};
    nodes.push_back(node(fb::NodeData::SlotNode,
                         fb::CreateSlotNode(fbb, 15, fbb.CreateString(montage->slot), fbb.CreateString(montage->group),
                                            fbb.CreateVectorOfStructs(slot_mask), false, true)
                             .Union()));  // 16
    root = 16;
    montages_v = write_montages(fbb, *montage);
  }
  std::vector<flatbuffers::Offset<flatbuffers::String>> clips = {fbb.CreateString(clip)};
  if (retarget) {  // format v10: beside the root, read by no node
    const SyntheticRetarget& r = *retarget;
    const std::vector<fb::RetargetRestRotation> rests = {{r.rest_joint, r.rest_rotation}};
    const auto source_bones = fbb.CreateVector(r.source_bones);
    const auto target_bones = fbb.CreateVector(r.target_bones);
    const auto rest_v = fbb.CreateVectorOfStructs(rests);
    nodes.push_back(
        node(fb::NodeData::RetargetNode,
             fb::CreateRetargetNode(fbb, r.clip, r.source_hash, r.source_joints, source_bones, target_bones, r.rate,
                                    r.rate_parameter, true, r.start, true, r.source_rest, r.target_rest, 0, rest_v)
                 .Union()));
    clips.push_back(fbb.CreateString("other_walk"));
  }
  return fb::CreateGraph(fbb, fbb.CreateString("g"), skeleton_hash, joint_count, fbb.CreateVector(params),
                         fbb.CreateVector(clips), fbb.CreateVector(nodes), fbb.CreateVector(machines), root,
                         montages_v);
}

flatbuffers::Offset<fb::Material> write_material(flatbuffers::FlatBufferBuilder& fbb, const SyntheticMaterial& m) {
  std::vector<flatbuffers::Offset<fb::Texture>> textures;
  for (const SyntheticTexture& t : m.textures) {
    const auto path = t.path.empty() ? 0 : fbb.CreateString(t.path);
    const auto mime = t.mime.empty() ? 0 : fbb.CreateString(t.mime);
    const auto data = t.data ? aligned_bytes(fbb, *t.data) : 0;
    textures.push_back(
        fb::CreateTexture(fbb, t.role, path, mime, data, t.encoding, t.srgb, t.width, t.height, t.mip_count));
  }
  const auto name = fbb.CreateString(m.name);
  const auto texture_vector = fbb.CreateVector(textures);
  return fb::CreateMaterial(fbb, name, &m.ambient, &m.diffuse, &m.specular, m.shininess, m.opacity, texture_vector,
                            m.emissive ? &*m.emissive : nullptr, m.pbr ? &*m.pbr : nullptr);
}

}  // namespace

std::vector<fb::VertexAttribute> SyntheticMesh::quantized_layout() {
  using S = fb::VertexSemantic;
  using F = fb::VertexFormat;
  return {{S::Position, F::Unorm16x4, 0},
          {S::Normal, F::Snorm16x2, 8},
          {S::TexCoord0, F::Float16x2, 12},
          {S::Joints, F::Uint8x4, 16},
          {S::Weights, F::Unorm8x4, 20}};
}

std::vector<SyntheticVertex> SyntheticMesh::default_vertices() {
  // Row 0 follows the spine, row 1 blends spine and head, row 2 blends head and arm.
  std::vector<SyntheticVertex> out;
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 2; ++col) {
      SyntheticVertex v;
      v.position = fb::Vec3(col == 0 ? -0.5f : 0.5f, static_cast<float>(row), col == 0 ? 0.1f : -0.1f);
      v.normal = fb::Vec3(0, 0, 1);
      v.u = static_cast<float>(col);
      v.v = static_cast<float>(row) / 2.0f;
      if (row == 0) v.slots = {0, 0, 0, 0}, v.weights = {255, 0, 0, 0};
      if (row == 1) v.slots = {0, 1, 0, 0}, v.weights = {128, 127, 0, 0};
      if (row == 2) v.slots = {1, 2, 0, 0}, v.weights = {200, 55, 0, 0};
      out.push_back(v);
    }
  }
  return out;
}

std::vector<SyntheticConstant> SyntheticClip::default_constants() {
  return {{1, fb::Channel::Translation, fb::Quat(0, 1, 0, 0)},
          {2, fb::Channel::Rotation, fb::Quat(0, 0, 0.25881905f, 0.96592583f)}};
}

std::vector<SyntheticAnimated> SyntheticClip::default_animated() {
  const auto channel = [](uint16_t joint, fb::Channel c, uint8_t bits, std::vector<uint16_t> frames,
                          std::vector<std::array<float, 3>> values) {
    SyntheticAnimated a;
    a.joint = joint;
    a.channel = c;
    a.bits = bits;
    a.frames = std::move(frames);
    a.values = std::move(values);
    return a;
  };
  return {channel(1, fb::Channel::Rotation, 16, {0, 15, 30}, {{0, 0, 0}, {0, 0.38268343f, 0}, {0, 0, 0}}),
          channel(3, fb::Channel::Translation, 12, {0, 30}, {{0.5f, 0.5f, 0}, {0.6f, 0.4f, 0}}),
          channel(3, fb::Channel::Scale, 32, {0, 8, 23, 30},
                  {{1, 1, 1}, {1, 1, 1}, {1.2f, 1.2f, 1.2f}, {1.2f, 1.2f, 1.2f}})};
}

namespace {
/// Five BC4 blocks: endpoints 255 / 0 then 3-bit indices, distinct per block so a byte flip shows.
std::vector<uint8_t> bc4_chain() {
  std::vector<uint8_t> out;
  for (uint8_t b = 0; b < 5; ++b) {
    const uint8_t block[8] = {
        255, 0, static_cast<uint8_t>(0x49 * (b + 1)), 0x92, 0x24, 0x49, 0x92, static_cast<uint8_t>(b)};
    out.insert(out.end(), block, block + 8);
  }
  return out;
}
}  // namespace
const std::vector<uint8_t> kBc4Chain = bc4_chain();

std::vector<SyntheticTexture> SyntheticMaterial::default_textures() {
  return {{fb::TextureRole::Diffuse, "", "image/png", std::vector<uint8_t>(std::begin(kTinyPng), std::end(kTinyPng))},
          {fb::TextureRole::Normal, "textures/skin_normal.png", "", std::nullopt},
          // A cooked BC4 chain 8 x 4 -> 4 x 2 -> 2 x 1 -> 1 x 1: blocks of 8 bytes, 2 + 1 + 1 + 1 of them.
          {fb::TextureRole::Specular, "", "", kBc4Chain, fb::TextureEncoding::Bc4, false, 8, 4, 4}};
}

uint32_t SyntheticSpec::default_version() { return kFormatVersion; }

std::vector<std::pair<std::string, SyntheticSpec>> valid_variants() {
  using S = fb::VertexSemantic;
  using F = fb::VertexFormat;
  std::vector<std::pair<std::string, SyntheticSpec>> out;
  out.emplace_back("default", SyntheticSpec{});

  SyntheticSpec spec;
  spec.meshes[0].index_format = fb::IndexFormat::Uint32;
  out.emplace_back("uint32-indices", spec);

  spec = {};
  spec.meshes[0].layout = {{S::Position, F::Float32x3, 0},
                           {S::Normal, F::Float32x3, 12},
                           {S::TexCoord0, F::Float32x2, 24},
                           {S::Joints, F::Uint16x4, 32},
                           {S::Weights, F::Unorm8x4, 40}};
  spec.meshes[0].vertex_stride = 44;
  out.emplace_back("float32-layout", spec);

  spec = {};
  spec.skeleton.reset();
  spec.clips.clear();
  spec.meshes[0].layout.resize(3);  // position, normal, uv
  spec.meshes[0].vertex_stride = 16;
  spec.meshes[0].joints.clear();
  out.emplace_back("static-mesh", spec);

  spec = {};
  spec.skeleton.reset();
  spec.meshes.clear();
  spec.materials.clear();
  spec.provenance = false;
  spec.clips[0].skeleton_hash = 0x1234;
  spec.clips[0].joint_count = 4;
  out.emplace_back("clip-only", spec);

  spec = {};
  spec.clips[0].write_empty_channels = true;
  SyntheticClip idle;
  idle.name = "idle";
  idle.constants.clear();
  idle.animated.clear();
  spec.clips.push_back(idle);
  out.emplace_back("empty-channels", spec);

  spec = {};
  spec.clips[0].name = "pose";
  spec.clips[0].frame_count = 1;
  spec.clips[0].animated.clear();
  spec.clips[0].constants.push_back({3, fb::Channel::Scale, fb::Quat(2, 2, 2, 0)});
  out.emplace_back("single-frame", spec);

  spec = {};
  {
    SyntheticRootMotion rm;
    for (uint32_t f = 0; f < spec.clips[0].frame_count; ++f) {
      rm.translations.emplace_back(0.0f, 0.0f, 0.05f * static_cast<float>(f));
      rm.yaws.push_back(0.01f * static_cast<float>(f));
    }
    spec.clips[0].root_motion = rm;
  }
  out.emplace_back("root-motion", spec);

  spec = {};
  spec.clips[0].animated[0].bits = 3;
  spec.clips[0].animated[1].bits = 1;
  spec.clips[0].compression = false;
  out.emplace_back("low-bits", spec);

  spec = {};
  // The spine turns about y, so y is its largest component: store x, z, w and rebuild y.
  spec.clips[0].animated[0].dropped = 1;
  spec.clips[0].animated[0].bits = 19;
  spec.clips[0].animated[0].values = {{0, 0, 1}, {0, 0, 0.92387953f}, {0, 0, 1}};
  out.emplace_back("drop-y", spec);

  spec = {};
  // A width per component (format v12): wide, narrow and 1-bit components in one key, and keys
  // that straddle byte boundaries at every offset.
  spec.clips[0].animated[0].widths = std::array<uint8_t, 3>{19, 2, 11};
  spec.clips[0].animated[1].widths = std::array<uint8_t, 3>{1, 17, 6};
  out.emplace_back("mixed-widths", spec);

  spec = {};
  // A channel keyed at every frame (format v13: it stores no key frames) beside channels that are
  // not, and a rotation constant whose largest component is x, the one left out.
  {
    SyntheticAnimated& a = spec.clips[0].animated[1];
    a.frames.clear();
    a.values.clear();
    for (uint16_t f = 0; f < spec.clips[0].frame_count; ++f) {
      a.frames.push_back(f);
      a.values.push_back({0.5f + 0.01f * static_cast<float>(f), 0.5f - 0.005f * static_cast<float>(f), 0.0f});
    }
    spec.clips[0].constants[1].value = fb::Quat(0.96592583f, 0, 0.25881905f, 0);
  }
  out.emplace_back("every-frame", spec);

  spec = {};
  spec.meshes.push_back(spec.meshes[0]);
  spec.meshes[1].name = "head";
  out.emplace_back("two-meshes", spec);
  spec = {};
  spec.graph = true;
  spec.montage = SyntheticMontage{};
  spec.clips[0].events = {{"start", 0.0f}, {"step", 0.25f}, {"step", 0.75f}, {"end", 1.0f}};
  out.emplace_back("graph", spec);

  spec = {};
  SyntheticMorphTarget frown;
  frown.name = "frown";
  frown.vertices = {2, 3, 4};
  frown.position_deltas = {-500, 0, 0, 500, 0, 0, 0, -300, 0};
  frown.normal_deltas = {0, 0, 100, 0, 0, -100, 0, 0, 0};
  frown.normal_step = {0.001f, 0.001f, 0.001f};
  frown.default_weight = 0.25f;
  spec.meshes[0].morph_targets = {SyntheticMorphTarget{}, frown};
  SyntheticMorphTrack constant_frown;
  constant_frown.name = "frown";
  constant_frown.key_frames = {0};
  constant_frown.values = {32768};
  spec.clips[0].morph_weights = {constant_frown, SyntheticMorphTrack{}};
  out.emplace_back("morph", spec);

  spec = {};
  spec.meshes[0].cloth = SyntheticCloth{};  // format v10: the fuzz corpus mutates cloth too
  out.emplace_back("cloth", spec);
  return out;
}

std::vector<uint8_t> make_valid_file(const SyntheticSpec& spec) {
  flatbuffers::FlatBufferBuilder fbb(4096);

  flatbuffers::Offset<fb::Skeleton> skeleton = 0;
  std::vector<fb::Mat4> skeleton_inverse_bind;
  uint64_t hash = 0;
  uint16_t joint_count = 0;
  if (spec.skeleton) {
    const SyntheticSkeleton& s = *spec.skeleton;
    skeleton_inverse_bind = s.inverse_bind.value_or(inverse_binds(s));
    hash = s.hash.value_or(hash_of(s));
    joint_count = static_cast<uint16_t>(s.names.size());
    std::vector<flatbuffers::Offset<flatbuffers::String>> names;
    for (const std::string& n : s.names) names.push_back(fbb.CreateString(n));
    const auto name_vector = fbb.CreateVector(names);
    const auto parents = fbb.CreateVector(s.parents);
    const auto translations = fbb.CreateVectorOfStructs(s.translations);
    const auto rotations = fbb.CreateVectorOfStructs(s.rotations);
    const auto scales = fbb.CreateVectorOfStructs(s.scales);
    const auto inverse_bind = fbb.CreateVectorOfStructs(skeleton_inverse_bind);
    skeleton = fb::CreateSkeleton(fbb, name_vector, parents, translations, rotations, scales, inverse_bind, hash);
  }

  std::vector<flatbuffers::Offset<fb::Mesh>> meshes;
  for (const SyntheticMesh& m : spec.meshes) meshes.push_back(write_mesh(fbb, m, skeleton_inverse_bind));
  std::vector<flatbuffers::Offset<fb::Clip>> clips;
  for (const SyntheticClip& c : spec.clips) clips.push_back(write_clip(fbb, c, hash, joint_count));
  std::vector<flatbuffers::Offset<fb::Material>> materials;
  for (const SyntheticMaterial& m : spec.materials) materials.push_back(write_material(fbb, m));

  flatbuffers::Offset<fb::Provenance> provenance = 0;
  if (spec.provenance) {
    const char source[] = "synthetic";
    provenance = fb::CreateProvenanceDirect(fbb, "synthetic.gltf", hash_bytes(source, sizeof source - 1),
                                            kCookerVersion, "synthetic");
  }
  std::vector<flatbuffers::Offset<fb::Graph>> graphs;
  if (spec.graph && !spec.clips.empty())
    graphs.push_back(write_graph(fbb, spec.clips[0].name, hash, joint_count, spec.montage, spec.retarget));
  const auto root =
      fb::CreateFileDirect(fbb, spec.version, spec.metres_per_unit, skeleton, spec.meshes.empty() ? nullptr : &meshes,
                           spec.clips.empty() ? nullptr : &clips, spec.materials.empty() ? nullptr : &materials,
                           provenance, graphs.empty() ? nullptr : &graphs);
  std::string identifier = spec.identifier;
  identifier.resize(4, ' ');
  fbb.Finish(root, identifier.c_str());
  return {fbb.GetBufferPointer(), fbb.GetBufferPointer() + fbb.GetSize()};
}

AlignedBytes::AlignedBytes(std::span<const uint8_t> bytes) : size_(bytes.size()) {
  // Aligned operator new with the exact size (not aligned_alloc, which rounds up and which MinGW
  // lacks), so AddressSanitizer reports a read one byte past the end instead of letting it land
  // in rounding slack.
  data_ = static_cast<uint8_t*>(::operator new (bytes.empty() ? 1 : bytes.size(), std::align_val_t{16}));
  if (!bytes.empty()) std::memcpy(data_, bytes.data(), bytes.size());
}

AlignedBytes::~AlignedBytes() { ::operator delete (data_, std::align_val_t{16}); }

// ---------------------------------------------------------------------------------------------

std::string env_or(const char* name, const char* fallback) {
  const char* value = std::getenv(name);
  return value && *value ? value : fallback;
}

std::filesystem::path source_dir() { return env_or("OSSA_SOURCE_DIR", OSSA_TEST_SOURCE_DIR); }
std::filesystem::path bin_dir() { return env_or("OSSA_BIN_DIR", OSSA_TEST_BIN_DIR); }
std::filesystem::path shared_assets() { return env_or("OSSA_SHARED_ASSETS", OSSA_TEST_SHARED_ASSETS); }
std::filesystem::path fixtures_dir() { return source_dir() / "tests" / "fixtures"; }

std::filesystem::path make_temp_dir(std::string_view prefix) {
  const std::filesystem::path root = env_or("OSSA_TEST_TMP", OSSA_TEST_TMP_DIR);
  std::error_code ec;
  std::filesystem::create_directories(root, ec);
  // mkdtemp is POSIX-only; create_directory reports whether it made the directory, which gives the
  // same exclusive creation on every platform.
  static std::mt19937_64 rng{std::random_device{}()};
  static constexpr char kChars[] = "abcdefghijklmnopqrstuvwxyz0123456789";
  for (int attempt = 0; attempt < 100; ++attempt) {
    std::string name = std::string(prefix) + "-";
    for (int i = 0; i < 6; ++i) name += kChars[rng() % (sizeof(kChars) - 1)];
    const std::filesystem::path dir = root / name;
    if (std::filesystem::create_directory(dir, ec)) return dir;
    if (ec) return {};
  }
  return {};
}

std::optional<std::vector<uint8_t>> read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) return std::nullopt;
  return bytes;
}

std::optional<std::string> read_text(const std::filesystem::path& path) {
  auto bytes = read_file(path);
  if (!bytes) return std::nullopt;
  return std::string(bytes->begin(), bytes->end());
}

bool write_file(const std::filesystem::path& path, std::span<const uint8_t> bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  out.close();
  return !out.fail();
}

bool write_file(const std::filesystem::path& path, std::string_view text) {
  return write_file(path, std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(text.data()), text.size()));
}

size_t count_files(const std::filesystem::path& dir) {
  size_t n = 0;
  std::error_code ec;
  for (std::filesystem::recursive_directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
    if (it->is_regular_file()) ++n;
  return n;
}

std::span<const uint8_t> tiny_png() { return kTinyPng; }

std::string tiny_png_with_text(std::string_view text) {
  std::string bytes(std::begin(kTinyPng), std::end(kTinyPng));
  const std::string chunk = "tEXtComment" + std::string(1, '\0') + std::string(text);
  uint32_t crc = 0xFFFFFFFFu;
  for (unsigned char ch : chunk) {
    crc ^= ch;
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  crc ^= 0xFFFFFFFFu;
  const auto length = static_cast<uint32_t>(chunk.size() - 4);
  std::string framed;
  for (int k = 3; k >= 0; --k) framed += static_cast<char>((length >> (8 * k)) & 0xFF);
  framed += chunk;
  for (int k = 3; k >= 0; --k) framed += static_cast<char>((crc >> (8 * k)) & 0xFF);
  bytes.insert(8 + 25, framed);  // after the signature (8 bytes) and the IHDR chunk (25)
  return bytes;
}

}  // namespace ossa::test
