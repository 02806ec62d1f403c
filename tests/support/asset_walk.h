// asset_walk.h — reads everything an accepted Asset exposes and re-checks the promises the loader
// made by accepting it, for tests that feed the loader hostile bytes (bad_input_test, fuzz_load).
//
// "Accepted" must mean "safe to use without further checks": every span and name lies inside the
// asset's own bytes, and every invariant listed in ossa/loader/validate.h holds. walk_asset touches
// every byte the views expose (so ASan sees any read past the buffer) and checks those invariants
// independently of runtime/loader/validate.cpp, reading raw values only through bounds it has itself
// established, so a loader that accepts a bad file is reported instead of trusted. It returns the
// first broken promise as text (empty when all hold) rather than using GoogleTest, because the
// libFuzzer target includes it too. Header-only: the fuzz target is built from one source file.
// Every accepted clip is also played once through sample() at a few times (looping, clamped,
// nlerp, slerp), so the fuzzer proves the sampler never reads outside a validated file; every
// accepted graph that binds (its clips may legitimately be missing) is played for a few updates
// with every parameter and trigger set, so the evaluator is proven the same way.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include <flatbuffers/flatbuffers.h>

#include <ossa/format/clip_codec.h>
#include <ossa/format/hash.h>
#include <ossa/format/vertex_format.h>
#include <ossa/version.h>
#include <ossa/loader/asset.h>
#include <ossa/loader/texture.h>
#include <ossa/graph/graph.h>
#include <ossa/anim/pose.h>
#include <ossa/anim/sample.h>

namespace ossa::test {

class AssetWalker {
 public:
  explicit AssetWalker(const Asset& asset)
      : asset_(asset), begin_(reinterpret_cast<uintptr_t>(asset.bytes().data())), end_(begin_ + asset.bytes().size()) {}

  /// The first broken promise, or "" when every check passed.
  std::string run() {
    if (asset_.file().version() != kFormatVersion) fail("file", "version is not kFormatVersion");
    if (asset_.bytes().size() < 8 || std::memcmp(asset_.bytes().data() + 4, kFileIdentifier, 4) != 0)
      fail("file", "identifier is not OSSA");
    skeleton();
    for (size_t i = 0; i < asset_.mesh_count(); ++i) mesh(i);
    for (size_t i = 0; i < asset_.clip_count(); ++i) clip(i);
    for (size_t i = 0; i < asset_.material_count(); ++i) material(i);
    for (size_t i = 0; i < graph_count(asset_); ++i) graph(i);
    if (const fb::Provenance* p = asset_.file().provenance()) {
      text(p->source_name(), "provenance.source_name");
      text(p->cooker_version(), "provenance.cooker_version");
      text(p->options(), "provenance.options");
      sum_ += p->source_hash();
    }
    return problem_;
  }

  /// A value folded from every byte read, so the reads cannot be optimized away.
  uint64_t checksum() const { return sum_; }

 private:
  void fail(const std::string& where, const std::string& what) {
    if (problem_.empty()) problem_ = where + ": " + what;
  }

  bool inside(const void* p, size_t size) const {
    const auto a = reinterpret_cast<uintptr_t>(p);
    return size == 0 || (a >= begin_ && a <= end_ && size <= end_ - a);
  }

  void touch(const void* p, size_t size, const std::string& what) {
    if (size == 0) return;
    if (!inside(p, size)) return fail(what, "points outside the asset's bytes");
    const auto* b = static_cast<const uint8_t*>(p);
    for (size_t i = 0; i < size; ++i) sum_ = sum_ * 1099511628211ull + b[i];
  }

  template <class T>
  void touch(std::span<const T> s, const std::string& what) {
    touch(s.data(), s.size_bytes(), what);
  }
  void touch(std::string_view s, const std::string& what) { touch(s.data(), s.size(), what); }

  void text(const flatbuffers::String* s, const std::string& what) {
    if (s) touch(s->data(), s->size() + 1, what);  // with its terminating zero
  }

  template <class T>
  static std::span<const T> scalars(const flatbuffers::Vector<T>* v) {
    return v ? std::span<const T>(v->data(), v->size()) : std::span<const T>();
  }
  template <class T>
  static std::span<const T> structs(const flatbuffers::Vector<const T*>* v) {
    return v ? std::span<const T>(reinterpret_cast<const T*>(v->Data()), v->size()) : std::span<const T>();
  }

  static bool finite(const fb::Vec3& v) { return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z()); }
  static bool finite(const fb::Quat& q) {
    return std::isfinite(q.x()) && std::isfinite(q.y()) && std::isfinite(q.z()) && std::isfinite(q.w());
  }

  void skeleton() {
    const SkeletonView s = asset_.skeleton();
    if (s.empty()) return;
    const size_t n = s.joint_count();
    touch(s.parents(), "skeleton.parents");
    touch(s.bind_translations(), "skeleton.bind_translations");
    touch(s.bind_rotations(), "skeleton.bind_rotations");
    touch(s.bind_scales(), "skeleton.bind_scales");
    touch(s.inverse_bind(), "skeleton.inverse_bind");
    if (s.parents().size() != n || s.bind_translations().size() != n || s.bind_rotations().size() != n ||
        s.bind_scales().size() != n || s.inverse_bind().size() != n)
      return fail("skeleton", "per-joint arrays differ in length");
    std::vector<std::string_view> names;
    for (size_t i = 0; i < n; ++i) {
      names.push_back(s.joint_name(i));
      touch(names.back(), "skeleton.joint_names");
      const int16_t parent = s.parents()[i];
      if (parent < -1 || parent >= static_cast<int64_t>(i)) fail("skeleton", "parents[i] not in [-1, i)");
    }
    if (s.hash() != skeleton_hash(names, s.parents())) fail("skeleton", "stored hash != recomputed hash");
    for (size_t i = 0; i < n; ++i) {
      const int found = s.find_joint(names[i]);
      if (found < 0 || static_cast<size_t>(found) >= n || s.joint_name(static_cast<size_t>(found)) != names[i])
        fail("skeleton", "find_joint does not find a joint by its own name");
    }
  }

  void mesh(size_t m) {
    const MeshView v = asset_.mesh(m);
    const std::string where = "mesh " + std::to_string(m);
    touch(v.name(), where + " name");
    const std::span<const fb::VertexAttribute> layout = v.layout();
    const std::span<const uint8_t> vertices = v.vertex_bytes(), indices = v.index_bytes();
    touch(layout, where + " layout");
    touch(vertices, where + " vertices");
    touch(indices, where + " indices");
    touch(v.submeshes(), where + " submeshes");
    touch(v.joints(), where + " joints");
    touch(v.inverse_bind(), where + " inverse_bind");
    if (!problem_.empty()) return;

    const uint64_t stride = v.vertex_stride(), count = v.vertex_count();
    if (count * stride != vertices.size()) return fail(where, "vertex bytes != vertex_count * stride");
    if (!vertices.empty() && reinterpret_cast<uintptr_t>(vertices.data()) % 16 != 0)
      fail(where, "vertex bytes not 16-byte aligned");
    if (!indices.empty() && reinterpret_cast<uintptr_t>(indices.data()) % 16 != 0)
      fail(where, "index bytes not 16-byte aligned");

    const fb::VertexAttribute* joints_attribute = nullptr;
    uint32_t seen = 0;
    for (const fb::VertexAttribute& a : layout) {
      const VertexFormatInfo info = vertex_format_info(a.format());
      if (info.size == 0) return fail(where, "unknown vertex format");
      if (a.offset() + info.size > stride) return fail(where, "attribute past the stride");
      const auto semantic = static_cast<unsigned>(a.semantic());
      if (semantic < 32) {
        if (seen & (1u << semantic)) return fail(where, "duplicate semantic");
        seen |= 1u << semantic;
      }
      const fb::VertexAttribute* found = v.attribute(a.semantic());
      if (found == nullptr || found->semantic() != a.semantic()) fail(where, "attribute() misses a semantic");
      if (a.semantic() == fb::VertexSemantic::Joints) joints_attribute = &a;
    }

    const size_t index_size = v.index_format() == fb::IndexFormat::Uint16 ? 2 : 4;
    if (v.index_format() != fb::IndexFormat::Uint16 && v.index_format() != fb::IndexFormat::Uint32)
      return fail(where, "unknown index format");
    if (indices.size() % index_size != 0) return fail(where, "index bytes not a multiple of the index size");
    const size_t index_count = indices.size() / index_size;
    if (v.index_count() != index_count) fail(where, "index_count() != index bytes / index size");
    if (index_count % 3 != 0) fail(where, "index count not a multiple of 3");
    for (size_t i = 0; i < index_count; ++i) {
      uint32_t index = 0;
      if (index_size == 2) {
        uint16_t i16;
        std::memcpy(&i16, indices.data() + 2 * i, 2);
        index = i16;
      } else {
        std::memcpy(&index, indices.data() + 4 * i, 4);
      }
      if (index >= count) return fail(where, "index >= vertex_count");
    }
    for (const fb::Submesh& s : v.submeshes()) {
      if (uint64_t{s.first_index()} + s.index_count() > index_count) fail(where, "submesh past the index range");
      // A file without materials may use material 0: the reader's default material.
      if (s.material() >= std::max<size_t>(asset_.material_count(), 1)) fail(where, "submesh material out of range");
    }

    // Morph targets: every listed vertex inside the mesh, ascending, three deltas per stream.
    for (size_t t = 0; t < v.morph_target_count(); ++t) {
      const fb::MorphTarget& target = v.morph_target(t);
      const std::string tw = where + " morph target " + std::to_string(t);
      text(target.name(), tw + " name");
      const std::span<const uint32_t> listed = scalars(target.vertices());
      touch(listed, tw + " vertices");
      for (size_t i = 0; i < listed.size(); ++i) {
        if (listed[i] >= count) return fail(tw, "vertex >= vertex_count");
        if (i > 0 && listed[i] <= listed[i - 1]) return fail(tw, "vertices not strictly increasing");
      }
      for (const auto* deltas : {target.position_deltas(), target.normal_deltas(), target.tangent_deltas()}) {
        const std::span<const int16_t> d = scalars(deltas);
        touch(d, tw + " deltas");
        if (!d.empty() && d.size() != 3 * listed.size()) return fail(tw, "deltas not 3 per listed vertex");
      }
      if (scalars(target.position_deltas()).size() != 3 * listed.size()) return fail(tw, "no position deltas");
      if (!std::isfinite(target.default_weight())) return fail(tw, "default weight not finite");
    }

    const std::span<const uint16_t> slots = v.joints();
    if (slots.size() != v.inverse_bind().size()) fail(where, "joints and inverse_bind differ in length");
    const size_t joint_count = asset_.skeleton().empty() ? 0 : asset_.skeleton().joint_count();
    for (uint16_t joint : slots)
      if (joint >= joint_count) fail(where, "slot joint >= skeleton joint count");
    if (joints_attribute != nullptr) {
      const bool wide = joints_attribute->format() == fb::VertexFormat::Uint16x4;
      if (!wide && joints_attribute->format() != fb::VertexFormat::Uint8x4)
        return fail(where, "joints attribute is not Uint8x4 or Uint16x4");
      for (uint64_t i = 0; i < count; ++i) {
        const uint8_t* p = vertices.data() + i * stride + joints_attribute->offset();
        for (int c = 0; c < 4; ++c) {
          uint16_t slot = 0;
          if (wide) std::memcpy(&slot, p + 2 * c, 2);
          else slot = p[c];
          if (slot >= slots.size()) return fail(where, "vertex joint slot >= slot count");
        }
      }
    }
  }

  /// (joint, channel) as one sortable number.
  static uint32_t channel_key(uint16_t joint, fb::Channel channel) {
    return (static_cast<uint32_t>(joint) << 8) | static_cast<uint8_t>(channel);
  }

  void clip(size_t c) {
    const ClipView v = asset_.clip(c);
    const std::string where = "clip " + std::to_string(c);
    touch(v.name(), where + " name");
    const std::span<const fb::ConstantChannel> constants = v.constants();
    const std::span<const fb::AnimatedChannel> animated = v.animated();
    const std::span<const uint16_t> frames = v.key_frames();
    const std::span<const uint8_t> values = v.key_values();
    touch(constants, where + " constants");
    touch(animated, where + " animated");
    touch(frames, where + " key_frames");
    touch(values, where + " key_values");
    const float numbers[2] = {v.duration(), v.sample_rate()};  // folded as bits: they may be NaN
    uint32_t bits[2];
    std::memcpy(bits, numbers, sizeof bits);
    sum_ += bits[0] + bits[1] + v.skeleton_hash() + v.frame_count() + v.joint_count();
    if (!problem_.empty()) return;

    const float rate = v.sample_rate();
    const uint32_t frame_count = v.frame_count();
    if (!(std::isfinite(rate) && rate > 0.0f)) return fail(where, "sample rate not finite and > 0");
    if (frame_count < 1 || frame_count > 65536) return fail(where, "frame count not in 1..65536");
    const double expected = (frame_count - 1) / static_cast<double>(rate);
    if (!(std::fabs(v.duration() - expected) <= 1e-4 * expected + 1e-6))
      return fail(where, "duration != (frame_count - 1) / sample_rate");
    const uint32_t joints = v.joint_count();

    for (size_t k = 0; k < v.morph_track_count(); ++k) {
      const fb::MorphTrack& track = v.morph_track(k);
      const std::string kw = where + " morph track " + std::to_string(k);
      text(track.name(), kw + " name");
      const std::span<const uint16_t> f = scalars(track.key_frames());
      touch(f, kw + " key_frames");
      touch(scalars(track.values()), kw + " values");
      if (f.empty() || f.size() != track.values()->size()) return fail(kw, "key frames and values differ or are empty");
      if (f[0] != 0) return fail(kw, "first key not at frame 0");
      for (size_t i = 1; i < f.size(); ++i)
        if (f[i] <= f[i - 1]) return fail(kw, "key frames not strictly increasing");
      if (f.size() > 1 && f.back() != frame_count - 1) return fail(kw, "last key not at the last frame");
      if (!std::isfinite(track.range_min()) || !std::isfinite(track.range_extent()))
        return fail(kw, "range not finite");
    }

    size_t keys = constants.size();
    for (size_t k = 0; k < constants.size(); ++k) {
      const fb::ConstantChannel& ch = constants[k];
      if (static_cast<unsigned>(ch.channel()) > 2) return fail(where, "constant channel enum unknown");
      if (ch.joint() >= joints) return fail(where, "constant joint >= clip joint_count");
      if (k > 0 &&
          channel_key(ch.joint(), ch.channel()) <= channel_key(constants[k - 1].joint(), constants[k - 1].channel()))
        return fail(where, "constants not sorted by (joint, channel) or repeated");
      if (!finite(fb::Vec3(ch.value().x(), ch.value().y(), ch.value().z())))
        return fail(where, "constant value not finite");
      if (ch.channel() == fb::Channel::Rotation) {
        if (ch.dropped() > 3) return fail(where, "rotation constant drops no component 0..3");
        // validate.h promises "normalizable": the rebuilt quaternion's squared norm, in float as
        // the sampler computes it, neither underflows below FLT_MIN nor overflows.
        float q[4];
        constant_value(ch, q);
        const float n2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
        if (!(n2 >= std::numeric_limits<float>::min() && n2 <= std::numeric_limits<float>::max()))
          return fail(where, "zero rotation constant");
      }
    }
    for (size_t k = 0; k < animated.size(); ++k) {
      const fb::AnimatedChannel& ch = animated[k];
      const std::string at = where + " animated " + std::to_string(k);
      if (static_cast<unsigned>(ch.channel()) > 2) return fail(at, "channel enum unknown");
      if (ch.joint() >= joints) return fail(at, "joint >= clip joint_count");
      const uint32_t key = channel_key(ch.joint(), ch.channel());
      if (k > 0 && key <= channel_key(animated[k - 1].joint(), animated[k - 1].channel()))
        return fail(at, "animated not sorted by (joint, channel) or repeated");
      for (const fb::ConstantChannel& cc : constants)
        if (channel_key(cc.joint(), cc.channel()) == key) return fail(at, "also a constant channel");
      const uint64_t first = ch.first_key(), n = ch.key_count();
      keys += n;
      if (n < 2) return fail(at, "fewer than 2 keys");
      if (n > frame_count) return fail(at, "more keys than frames");
      if (n == frame_count) {  // keyed at every frame: no key frames stored
        if (first != 0) return fail(at, "keyed at every frame with first_key != 0");
      } else {
        if (first + n > frames.size()) return fail(at, "keys past key_frames");
        if (frames[first] != 0 || frames[first + n - 1] != frame_count - 1)
          return fail(at, "keys do not run from frame 0 to the last frame");
        for (uint64_t i = first + 1; i < first + n; ++i)
          if (!(frames[i] > frames[i - 1])) return fail(at, "key frames not strictly increasing");
      }
      const uint32_t w[3] = {ch.bits()->Get(0), ch.bits()->Get(1), ch.bits()->Get(2)};
      const bool raw = w[0] == 32;
      for (const uint32_t x : w)
        if (raw ? x != 32 : !(x >= 1 && x <= 19)) return fail(at, "bits not each in 1..19, or all 32");
      const uint32_t b = raw ? 32 : 0;  // 32 marks raw floats below
      if (ch.channel() == fb::Channel::Rotation && ch.dropped() > 3)
        return fail(at, "rotation drops no component 0..3");
      if (values.size() < 8) return fail(at, "key values shorter than their padding");
      uint64_t end = ch.bit_offset() + (uint64_t{w[0]} + w[1] + w[2]) * n;
      if (const uint32_t o = ch.segment_offset_bits(); o != 0) {  // segmented: walk the headers
        if (raw || o > 32 || n != frame_count) return fail(at, "segmented, but raw, past 32 bits or not every frame");
        const KeyWidths kw{{w[0], w[1], w[2]}};
        const uint64_t segments = (n + 15) / 16, header = o + kw.total() + 15;
        if (ch.bit_offset() + segments * header > 8ull * (values.size() - 8))
          return fail(at, "segment headers past key_values");
        uint64_t data = segments * header;
        for (uint64_t s = 0; s < segments; ++s) {
          const SegmentHeader h = read_segment(values.data(), ch.bit_offset(), kw, o, static_cast<uint32_t>(s));
          if (h.data != data) return fail(at, "segment keys not where the previous segment ends");
          for (uint32_t i = 0; i < 3; ++i)
            if (h.widths.c[i] > w[i] || uint64_t{h.min[i]} + ((1ull << h.widths.c[i]) - 1) > (1ull << w[i]) - 1)
              return fail(at, "segment width or minimum outside the channel's codes");
          data += h.widths.total() * std::min<uint64_t>(16, n - 16 * s);
        }
        end = ch.bit_offset() + data;
      }
      if (end > 8ull * (values.size() - 8)) return fail(at, "keys past key_values (before padding)");
      if (b == 32) {
        if (ch.bit_offset() % 8 != 0) return fail(at, "raw keys not byte-aligned");
        for (uint64_t i = 0; i < 3 * n; ++i) {
          float f;
          std::memcpy(&f, values.data() + ch.bit_offset() / 8 + 4 * i, 4);
          if (!std::isfinite(f)) return fail(at, "raw key not finite");
        }
      } else if (!finite(ch.range_min()) || !finite(ch.range_extent()) || ch.range_extent().x() < 0 ||
                 ch.range_extent().y() < 0 || ch.range_extent().z() < 0) {
        return fail(at, "range not finite or negative extent");
      }
    }
    if (v.key_count() != keys) fail(where, "key_count() != constants + animated keys");
    if (const fb::RootMotion* rm = v.root_motion()) {
      touch(structs(rm->translations()), where + " root motion translations");
      touch(scalars(rm->yaws()), where + " root motion yaws");
      if (rm->translations()->size() != frame_count || rm->yaws()->size() != frame_count)
        fail(where, "root motion not one sample per frame");
      if (rm->up_axis() > 2) fail(where, "root motion up axis > 2");
    }
    if (const fb::ClipCompression* cc = v.compression()) sum_ += cc->raw_bytes() + cc->worst_joint();
    const Status binding = check_clip_binding(v, asset_.skeleton(), asset_.name());
    for (char ch : binding.message()) sum_ = sum_ * 31 + static_cast<unsigned char>(ch);  // not file bytes
    if (problem_.empty()) play(v, where, binding.ok());
  }

  /// Samples an accepted clip at a few times, looping and clamped, nlerp and slerp, on its own
  /// skeleton when it binds to the file's, else on a stand-in rig with the clip's hash and joint
  /// count (identity bind pose): the sampler must stay inside the file and produce finite poses.
  void play(const ClipView& v, const std::string& where, bool binds_here) {
    flatbuffers::FlatBufferBuilder fbb;
    SkeletonView skeleton = asset_.skeleton();
    if (!binds_here) {
      const uint32_t n = v.joint_count();
      std::vector<std::string> names(n);
      for (uint32_t i = 0; i < n; ++i) names[i] = "j" + std::to_string(i);
      const std::vector<int16_t> parents(n, -1);
      const std::vector<fb::Vec3> zero(n, fb::Vec3(0, 0, 0)), one(n, fb::Vec3(1, 1, 1));
      const std::vector<fb::Quat> identity(n, fb::Quat(0, 0, 0, 1));
      const std::vector<fb::Mat4> matrices(n);
      const auto name_vector = fbb.CreateVectorOfStrings(names);
      const auto parent_vector = fbb.CreateVector(parents);
      const auto t = fbb.CreateVectorOfStructs(zero);
      const auto r = fbb.CreateVectorOfStructs(identity);
      const auto sc = fbb.CreateVectorOfStructs(one);
      const auto m = fbb.CreateVectorOfStructs(matrices);
      fbb.Finish(fb::CreateSkeleton(fbb, name_vector, parent_vector, t, r, sc, m, v.skeleton_hash()));
      skeleton = SkeletonView{flatbuffers::GetRoot<fb::Skeleton>(fbb.GetBufferPointer())};
    }
    Result<SamplingCache> cache = make_sampling_cache(v, skeleton);
    if (!cache) return fail(where, "make_sampling_cache refused a clip bound to its rig: " + cache.error().message);
    const uint32_t joints = v.joint_count();
    const uint32_t stride = pose_stride(joints);
    std::vector<float> storage(size_t(kPoseComponents) * stride);
    const PoseSpan pose{storage.data(), joints, stride};
    const float d = v.duration();
    const float times[] = {0.0f, d * 0.37f, d, d * 0.5f, -0.25f * d - 0.01f, d * 2.6f, 0.0f};
    for (int mode = 0; mode < 4; ++mode) {
      SampleOptions options;
      options.loop = (mode & 1) == 0;
      options.rotation = mode & 2 ? RotationInterpolation::Slerp : RotationInterpolation::Nlerp;
      for (float t : times) {
        sample(v, t, options, *cache, pose);
        for (uint32_t j = 0; j < joints; ++j) {
          for (PoseComponent k : {kTx, kTy, kTz, kSx, kSy, kSz})
            if (std::isnan(pose[k][j])) return fail(where, "sample() produced a NaN translation or scale");
          const double x = pose[kRx][j], y = pose[kRy][j], z = pose[kRz][j], w = pose[kRw][j];
          if (!(std::fabs(x * x + y * y + z * z + w * w - 1.0) < 1e-3))
            return fail(where, "sample() produced a rotation that is not unit");
          uint32_t word;
          std::memcpy(&word, &pose[kRx][j], 4);
          sum_ += word;
        }
      }
    }
  }

  void graph(size_t i) {
    const fb::Graph& g = *asset_.file().graphs()->Get(static_cast<flatbuffers::uoffset_t>(i));
    const std::string where = "graph " + std::to_string(i);
    text(g.name(), where + ".name");
    auto def = GraphDefinition::create(asset_, g.name()->string_view());
    if (!def.ok()) return;  // e.g. a clip it names is not in this file: an error, not a broken promise
    auto inst = GraphInstance::create(*def, 4);
    if (!inst.ok()) return fail(where, "binds but cannot be instantiated: " + inst.error().message);
    const float steps[] = {0.0f, 0.016f, 0.5f, 0.033f, 3.7f, 0.016f, 0.25f, 0.016f};
    for (size_t k = 0; k < std::size(steps); ++k) {
      for (size_t m = 0; m < def->montage_count(); ++m) {  // montages played, jumped and stopped on the way
        const int idx = static_cast<int>(m);
        if (k % 4 == 0) inst->play_montage(idx, 0.5f + static_cast<float>(k), -1);
        if (k % 4 == 1) inst->jump_to_section(idx, static_cast<int>(def->section_count(m)) - 1);
        if (k % 4 == 2) inst->set_next_section(idx, 0, -1);
        if (k == 6) inst->stop_montage(idx, 0.1f);
        sum_ += static_cast<uint64_t>(inst->montage_status(idx).section + 1);
      }
      for (size_t p = 0; p < def->parameter_count(); ++p) {
        const int idx = static_cast<int>(p);
        const float v = static_cast<float>((k * 7 + p * 3) % 5) * 0.75f;
        inst->set_float(idx, v);
        inst->set_int(idx, static_cast<int>(k % 4));
        inst->set_bool(idx, (k + p) % 2 == 0);
        inst->set_enum(idx, static_cast<int>(k % 2));
        if (k % 3 == 0) inst->set_trigger(idx);
      }
      inst->update(steps[k]);
      const ConstPoseSpan pose = inst->pose();
      for (uint32_t j = 0; j < pose.joint_count; ++j)
        for (uint32_t c = 0; c < kPoseComponents; ++c)
          if (!std::isfinite(pose[PoseComponent(c)][j])) return fail(where, "update produced a non-finite pose");
      for (const GraphEvent& e : inst->events()) touch(e.name, where + " event name");
      for (const MontageEvent& e : inst->montage_events()) touch(e.name, where + " montage event name");
      for (size_t m = 0; m < def->machine_count(); ++m) sum_ += static_cast<uint64_t>(inst->machine_status(m).current);
    }
  }

  void material(size_t i) {
    const fb::Material& m = asset_.material(i);
    const std::string where = "material " + std::to_string(i);
    text(m.name(), where + " name");
    if (m.ambient()) touch(m.ambient(), sizeof(fb::Vec3), where + " ambient");
    if (m.diffuse()) touch(m.diffuse(), sizeof(fb::Vec3), where + " diffuse");
    if (m.specular()) touch(m.specular(), sizeof(fb::Vec3), where + " specular");
    if (const auto* textures = m.textures()) {
      for (const fb::Texture* t : *textures) {
        text(t->path(), where + " texture path");
        text(t->mime(), where + " texture mime");
        touch(scalars(t->data()), where + " texture data");
        // A cooked chain: every level inside the data, packed in order, of the size its encoding
        // and level give, and together exactly the data (ossa/loader/texture.h).
        const TextureView view{t};
        uint64_t next = 0;
        for (uint32_t k = 0; k < view.mip_count(); ++k) {
          const TextureLevel level = view.level(k);
          const std::string lw = where + " texture level " + std::to_string(k);
          if (level.width != std::max(1u, view.width() >> k) || level.height != std::max(1u, view.height() >> k))
            fail(lw, "has the wrong size");
          if (level.bytes.size() != texture_level_bytes(view.encoding(), level.width, level.height) ||
              level.bytes.empty())
            fail(lw, "has the wrong byte count");
          if (level.bytes.data() != view.data().data() + next) fail(lw, "is not where the previous level ended");
          next += level.bytes.size();
          touch(level.bytes, lw);
        }
        if (view.gpu_ready() && next != view.data().size()) fail(where + " texture", "levels do not cover its data");
        if (!view.gpu_ready() && view.mip_count() != 0) fail(where + " texture", "source bytes with levels");
      }
    }
  }

  const Asset& asset_;
  uintptr_t begin_, end_;
  uint64_t sum_ = 0;
  std::string problem_;
};

/// Walks every view of an accepted asset; returns the first broken promise, or "" when none.
inline std::string walk_asset(const Asset& asset, uint64_t* checksum = nullptr) {
  AssetWalker walker(asset);
  std::string problem = walker.run();
  if (checksum) *checksum = walker.checksum();
  return problem;
}

}  // namespace ossa::test
