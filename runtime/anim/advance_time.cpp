// advance_time.cpp — a clip's time after dt at a rate, wrapped or clamped (ossa/anim/sample.h).
//
// Kept apart from the sampler: it is plain arithmetic on one time, which every clip player (the
// graph's clip nodes, the viewer) calls before it samples. The sum is taken in double so that a
// long playback does not drift, and the wrap count is clamped so that a huge dt stays an int.
#include <cmath>

#include <ossa/anim/sample.h>

namespace ossa {

float advance_time(float time, float dt, float rate, float duration, bool loop, int* loops) {
  if (loops) *loops = 0;
  double t = static_cast<double>(time) + static_cast<double>(dt) * static_cast<double>(rate);
  if (!std::isfinite(t)) t = 0.0;
  if (!(duration > 0.0f) || !std::isfinite(duration)) return 0.0f;
  const double d = duration;
  if (!loop) return static_cast<float>(t < 0.0 ? 0.0 : (t > d ? d : t));
  const double wraps = std::floor(t / d);
  double r = t - wraps * d;
  if (r < 0.0) r = 0.0;
  auto result = static_cast<float>(r);
  int n = wraps > 1e9 ? 1000000000 : (wraps < -1e9 ? -1000000000 : static_cast<int>(wraps));
  if (result >= duration) {  // r just below d rounds to d in float: that is the next cycle's start
    result = 0.0f;
    ++n;
  }
  if (loops) *loops = n;
  return result;
}

}  // namespace ossa
