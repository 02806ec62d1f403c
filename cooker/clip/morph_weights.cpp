// morph_weights.cpp — weight track compression (morph_weights.h).
#include "cooker/clip/morph_weights.h"

#include <algorithm>
#include <cmath>

namespace ossa::cook {
namespace {

constexpr uint32_t kMaxSegment = 256;

}  // namespace

float source_morph_weight(const SourceMorphTrack& track, float time) {
  const auto& t = track.times;
  if (t.empty()) return 0.0f;
  if (time <= t.front()) return track.weights.front();
  if (time >= t.back()) return track.weights.back();
  const size_t b = static_cast<size_t>(std::upper_bound(t.begin(), t.end(), time) - t.begin());
  const size_t a = b - 1;
  const float u = (time - t[a]) / (t[b] - t[a]);
  return track.weights[a] + (track.weights[b] - track.weights[a]) * u;
}

CompressedMorphTrack compress_morph_track(const SourceMorphTrack& track, const FrameGrid& grid, float tolerance) {
  CompressedMorphTrack out;
  out.name = track.name;
  const uint32_t n = std::max<uint32_t>(grid.frame_count, 1);
  std::vector<double> w(n);
  double lo = 0.0, hi = 0.0;
  for (uint32_t f = 0; f < n; ++f) {
    w[f] = source_morph_weight(track, grid.time(f));
    lo = f == 0 ? w[f] : std::min(lo, w[f]);
    hi = f == 0 ? w[f] : std::max(hi, w[f]);
  }
  if (tolerance > 0.0f && (hi - lo) <= 2.0 * tolerance) {
    out.range_min = static_cast<float>(0.5 * (lo + hi));
    out.key_frames = {0};
    out.values = {0};
    for (uint32_t f = 0; f < n; ++f)
      out.max_error = std::max(out.max_error, static_cast<float>(std::abs(w[f] - out.range_min)));
    return out;
  }
  out.range_min = static_cast<float>(lo);
  out.range_extent = static_cast<float>(hi - lo);
  std::vector<uint16_t> q(n);
  std::vector<double> dq(n);
  for (uint32_t f = 0; f < n; ++f) {
    const double x = out.range_extent > 0.0f ? (w[f] - out.range_min) / out.range_extent * 65535.0 : 0.0;
    q[f] = static_cast<uint16_t>(std::clamp(std::round(x), 0.0, 65535.0));
    // As the runtime decodes it (float arithmetic).
    dq[f] = out.range_min + out.range_extent * (static_cast<float>(q[f]) * (1.0f / 65535.0f));
  }
  // Whether keys a and b reproduce every frame between them within the tolerance.
  const auto fits = [&](uint32_t a, uint32_t b) {
    for (uint32_t f = a + 1; f < b; ++f) {
      const double u = static_cast<double>(f - a) / static_cast<double>(b - a);
      if (std::abs(dq[a] + (dq[b] - dq[a]) * u - w[f]) > tolerance) return false;
    }
    return true;
  };
  uint32_t a = 0;
  out.key_frames.push_back(0);
  while (a + 1 < n) {
    uint32_t b = a + 1;
    if (tolerance > 0.0f) {
      while (b + 1 < n && b + 1 - a <= kMaxSegment && fits(a, b + 1)) ++b;
    }
    out.key_frames.push_back(static_cast<uint16_t>(b));
    a = b;
  }
  for (const uint16_t f : out.key_frames) out.values.push_back(q[f]);
  // The achieved error, over every frame.
  for (size_t k = 0; k + 1 < out.key_frames.size(); ++k) {
    const uint32_t ka = out.key_frames[k], kb = out.key_frames[k + 1];
    for (uint32_t f = ka; f <= kb; ++f) {
      const double u = static_cast<double>(f - ka) / static_cast<double>(kb - ka);
      out.max_error = std::max(out.max_error, static_cast<float>(std::abs(dq[ka] + (dq[kb] - dq[ka]) * u - w[f])));
    }
  }
  if (out.key_frames.size() == 1) out.max_error = static_cast<float>(std::abs(dq[0] - w[0]));
  return out;
}

}  // namespace ossa::cook
