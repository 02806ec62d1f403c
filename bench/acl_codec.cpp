// acl_codec.cpp — ACL behind acl_codec.h's interface. The only file that includes ACL.
#include "bench/acl_codec.h"

#include <chrono>
#include <cstring>

#include <acl/compression/compress.h>
#include <acl/compression/track_array.h>
#include <acl/compression/transform_error_metrics.h>
#include <acl/core/ansi_allocator.h>
#include <acl/core/compressed_tracks.h>
#include <acl/decompression/decompress.h>
#include <acl/version.h>

namespace ossa::bench {
namespace {

acl::ansi_allocator& allocator() {
  static acl::ansi_allocator a;
  return a;
}

/// ossa's probe measure as an ACL error metric: the larger displacement of +-p for each of the
/// three shell points p (ACL's own metric takes +p only). With scale, ACL hands over object-space
/// matrices (the base class converts and accumulates them); without, qvv transforms.
class ProbeMetric final : public acl::qvvf_matrix3x4f_transform_error_metric {
 public:
  const char* get_name() const override { return "ossa probe points (six, +-shell per axis)"; }

  rtm::scalarf RTM_SIMD_CALL calculate_error(const calculate_error_args& args) const override {
    const auto& a = *static_cast<const rtm::matrix3x4f*>(args.transform0);
    const auto& b = *static_cast<const rtm::matrix3x4f*>(args.transform1);
    return worst(args, [&](rtm::vector4f p) {
      return rtm::vector_distance3(rtm::matrix_mul_point3(p, a), rtm::matrix_mul_point3(p, b));
    });
  }
  rtm::scalarf RTM_SIMD_CALL calculate_error_no_scale(const calculate_error_args& args) const override {
    const auto& a = *static_cast<const rtm::qvvf*>(args.transform0);
    const auto& b = *static_cast<const rtm::qvvf*>(args.transform1);
    return worst(args, [&](rtm::vector4f p) {
      return rtm::vector_distance3(rtm::qvv_mul_point3_no_scale(p, a), rtm::qvv_mul_point3_no_scale(p, b));
    });
  }

 private:
  template <class Distance>
  static rtm::scalarf worst(const calculate_error_args& args, Distance distance) {
    rtm::scalarf e = rtm::scalar_set(0.0F);
    for (const rtm::vector4f& p : {args.shell_point_x, args.shell_point_y, args.shell_point_z}) {
      e = rtm::scalar_max(e, distance(p));
      e = rtm::scalar_max(e, distance(rtm::vector_neg(p)));
    }
    return e;
  }
};

// What ACL's own decompression benchmark uses: the default (variable) formats, the latest
// version only, and no safety checks when a context is initialized.
struct PlaySettings final : acl::default_transform_decompression_settings {
  static constexpr acl::compressed_tracks_version16 version_supported() {
    return acl::compressed_tracks_version16::latest;
  }
  static constexpr bool skip_initialize_safety_checks() { return true; }
};

/// Writes a whole pose into an rtm::qvvf array; default sub-tracks take the bind pose.
struct PoseWriter final : acl::track_writer {
  rtm::qvvf* out = nullptr;
  const rtm::qvvf* bind = nullptr;

  static constexpr acl::default_sub_track_mode get_default_rotation_mode() {
    return acl::default_sub_track_mode::variable;
  }
  static constexpr acl::default_sub_track_mode get_default_translation_mode() {
    return acl::default_sub_track_mode::variable;
  }
  static constexpr acl::default_sub_track_mode get_default_scale_mode() {
    return acl::default_sub_track_mode::variable;
  }
  rtm::quatf RTM_SIMD_CALL get_variable_default_rotation(uint32_t i) const { return bind[i].rotation; }
  rtm::vector4f RTM_SIMD_CALL get_variable_default_translation(uint32_t i) const { return bind[i].translation; }
  rtm::vector4f RTM_SIMD_CALL get_variable_default_scale(uint32_t i) const { return bind[i].scale; }
  void RTM_SIMD_CALL write_rotation(uint32_t i, rtm::quatf_arg0 v) { out[i].rotation = v; }
  void RTM_SIMD_CALL write_translation(uint32_t i, rtm::vector4f_arg0 v) { out[i].translation = v; }
  void RTM_SIMD_CALL write_scale(uint32_t i, rtm::vector4f_arg0 v) { out[i].scale = v; }
};

rtm::qvvf to_qvv(const RawTransform& r) {
  return rtm::qvv_set(rtm::quat_set(r.q[0], r.q[1], r.q[2], r.q[3]), rtm::vector_set(r.t[0], r.t[1], r.t[2]),
                      rtm::vector_set(r.s[0], r.s[1], r.s[2]));
}

volatile float g_sink;

}  // namespace

struct AclClip::Impl {
  acl::compressed_tracks* tracks = nullptr;
  acl::decompression_context<PlaySettings> context;
  std::vector<rtm::qvvf> bind, pose;
  PoseWriter writer;
  ~Impl() {
    if (tracks) allocator().deallocate(tracks, tracks->get_size());
  }
};

AclClip::AclClip(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
AclClip::~AclClip() = default;

std::unique_ptr<AclClip> AclClip::compress(const RawClipData& raw, double precision, std::span<const double> shell,
                                           std::string* error) {
  auto impl = std::make_unique<Impl>();
  acl::track_array_qvvf tracks(allocator(), raw.joints);
  for (uint32_t j = 0; j < raw.joints; ++j) {
    acl::track_desc_transformf desc;
    desc.output_index = j;
    desc.parent_index = raw.parents[j] < 0 ? acl::k_invalid_track_index : static_cast<uint32_t>(raw.parents[j]);
    desc.precision = static_cast<float>(precision);
    desc.shell_distance = static_cast<float>(shell[j]);
    desc.default_value = to_qvv(raw.bind[j]);
    acl::track_qvvf track = acl::track_qvvf::make_reserve(desc, allocator(), raw.frames, raw.sample_rate);
    for (uint32_t f = 0; f < raw.frames; ++f) track[f] = to_qvv(raw.samples[static_cast<size_t>(f) * raw.joints + j]);
    tracks[j] = std::move(track);
  }
  acl::compression_settings settings = acl::get_default_compression_settings();
  ProbeMetric metric;
  settings.error_metric = &metric;
  acl::output_stats stats;
  const acl::error_result result = acl::compress_track_list(allocator(), tracks, settings, impl->tracks, stats);
  if (result.any()) {
    if (error) *error = result.c_str();
    return nullptr;
  }
  impl->context.initialize(*impl->tracks);
  impl->bind.resize(raw.joints);
  impl->pose.resize(raw.joints);
  for (uint32_t j = 0; j < raw.joints; ++j) impl->bind[j] = to_qvv(raw.bind[j]);
  impl->writer.out = impl->pose.data();
  impl->writer.bind = impl->bind.data();
  return std::unique_ptr<AclClip>(new AclClip(std::move(impl)));
}

uint32_t AclClip::bytes() const { return impl_->tracks->get_size(); }

uint32_t AclClip::segments() const { return acl::acl_impl::get_transform_tracks_header(*impl_->tracks).num_segments; }

void AclClip::sample(float time, PoseSpan out) {
  impl_->context.seek(time, acl::sample_rounding_policy::none);
  impl_->context.decompress_tracks(impl_->writer);
  for (uint32_t j = 0; j < out.joint_count; ++j) {
    const rtm::qvvf& v = impl_->pose[j];
    out[kTx][j] = rtm::vector_get_x(v.translation);
    out[kTy][j] = rtm::vector_get_y(v.translation);
    out[kTz][j] = rtm::vector_get_z(v.translation);
    out[kRx][j] = rtm::quat_get_x(v.rotation);
    out[kRy][j] = rtm::quat_get_y(v.rotation);
    out[kRz][j] = rtm::quat_get_z(v.rotation);
    out[kRw][j] = rtm::quat_get_w(v.rotation);
    out[kSx][j] = rtm::vector_get_x(v.scale);
    out[kSy][j] = rtm::vector_get_y(v.scale);
    out[kSz][j] = rtm::vector_get_z(v.scale);
  }
}

double AclClip::time_poses(std::span<const float> times) {
  Impl& s = *impl_;
  float sink = 0.0f;
  const auto start = std::chrono::steady_clock::now();
  for (const float t : times) {
    s.context.seek(t, acl::sample_rounding_policy::none);
    s.context.decompress_tracks(s.writer);
    sink += rtm::vector_get_x(s.pose[0].translation);
  }
  const auto stop = std::chrono::steady_clock::now();
  g_sink = sink;
  return std::chrono::duration<double, std::nano>(stop - start).count() / static_cast<double>(times.size());
}

std::string acl_version() {
  return "ACL " + std::to_string(ACL_VERSION_MAJOR) + "." + std::to_string(ACL_VERSION_MINOR) + "." +
         std::to_string(ACL_VERSION_PATCH);
}

}  // namespace ossa::bench
