// foot_contacts.cpp — planted feet on a source clip (foot_contacts.h).
#include <ossa/retarget/foot_contacts.h>

#include <algorithm>
#include <cmath>

#include <glm/gtc/quaternion.hpp>

namespace ossa {

ContactFrame contact_frame(const RetargetMap& map, const RetargetScratch& s) {
  ContactFrame f;
  for (size_t k = 0; k < 2; ++k) {
    f.source_ankle[k] = glm::vec3(s.source_model[static_cast<size_t>(map.legs[k].source_foot)][3]);
    f.target_ankle[k] = glm::vec3(s.target_model[static_cast<size_t>(map.legs[k].foot)][3]);
  }
  return f;
}

float clip_floor(const RetargetMap& map, std::span<const ContactFrame> frames) {
  const RetargetPose& pose = map.source_pose;
  float lowest = 3.4e38f;
  for (const ContactFrame& f : frames)
    for (const glm::vec3& a : f.source_ankle) lowest = std::min(lowest, glm::dot(a - pose.origin, pose.up));
  return frames.empty() || std::fabs(lowest) <= 0.05f * pose.hips_height ? 0.0f : lowest;
}

std::vector<ContactSpan> find_foot_contacts(const RetargetMap& map, std::span<const ContactFrame> feet,
                                            float sample_rate, float floor, const ContactSettings& settings) {
  std::vector<ContactSpan> out;
  const size_t frames = feet.size();
  if (frames == 0 || !(sample_rate > 0.0f)) return out;
  const RetargetPose& pose = map.source_pose;
  const float h = pose.hips_height;
  const float max_height = settings.max_height * h, max_speed = settings.max_speed * h;
  const auto min_frames = static_cast<uint32_t>(std::max(1.0f, std::ceil(settings.min_duration * sample_rate)));
  for (uint8_t foot = 0; foot < 2; ++foot) {
    auto at = [&](size_t f) { return feet[f].source_ankle[foot]; };
    std::vector<bool> planted(frames, false);
    for (size_t f = 0; f < frames; ++f) {
      const float height = glm::dot(at(f) - pose.origin, pose.up) - floor;
      // Central differences (one-sided at the ends); a one-frame clip is still.
      const size_t a = f > 0 ? f - 1 : f, b = f + 1 < frames ? f + 1 : f;
      const float speed = b > a ? glm::length(at(b) - at(a)) * sample_rate / static_cast<float>(b - a) : 0.0f;
      planted[f] = height <= max_height && speed <= max_speed;
    }
    for (size_t f = 0; f < frames;) {
      if (!planted[f]) {
        ++f;
        continue;
      }
      size_t last = f;
      const float drift = settings.max_drift * h;
      while (last + 1 < frames && planted[last + 1] && glm::length(at(last + 1) - at(f)) <= drift) ++last;
      if (last - f + 1 >= min_frames) {
        ContactSpan c;
        c.foot = foot;
        c.first = static_cast<uint32_t>(f);
        c.last = static_cast<uint32_t>(last);
        // The offset: the target's ankle against the mapped source ankle, averaged, back in source units.
        glm::dvec3 sum(0.0);
        for (size_t k = f; k <= last; ++k)
          sum += glm::dvec3(feet[k].target_ankle[foot] - map.map_point(feet[k].source_ankle[foot], floor));
        const glm::quat back = glm::inverse(map.rotation);
        const glm::vec3 mean_error(sum / static_cast<double>(last - f + 1));
        c.offset = back * mean_error / map.scale;
        auto held_minus_free = [&](size_t k) {
          return back * (map.map_point(feet[k].source_ankle[foot], floor) + mean_error - feet[k].target_ankle[foot]) /
                 map.scale;
        };
        c.entry_shift = held_minus_free(f);
        c.exit_shift = held_minus_free(last);
        out.push_back(c);
      }
      f = last + 1;
    }
  }
  return out;
}

void foot_contacts_at(std::span<const ContactSpan> contacts, float frame, float sample_rate, float blend_time,
                      std::span<FootContact, 2> out) {
  out[0] = FootContact{};
  out[1] = FootContact{};
  const float blend_frames = std::max(blend_time * sample_rate, 1e-3f);
  for (const ContactSpan& c : contacts) {
    if (c.foot > 1) continue;
    const float first = static_cast<float>(c.first), last = static_cast<float>(c.last);
    const float outside = frame < first ? first - frame : frame > last ? frame - last : 0.0f;
    float w = 1.0f - outside / blend_frames;
    if (w <= 0.0f) continue;
    w = w * w * (3.0f - 2.0f * w);  // smoothstep: no velocity jump where the fix-up starts
    FootContact& o = out[c.foot];
    if (w > o.weight)
      o = FootContact{outside > 0.0f ? std::min(w, 0.999f) : 1.0f, c.offset,
                      frame < first  ? c.entry_shift
                      : frame > last ? c.exit_shift
                                     : glm::vec3(0.0f)};
  }
}

}  // namespace ossa
