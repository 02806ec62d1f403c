// layout.cpp — see layout.h.
#include "viewer/layout.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <imgui.h>
#include <ossa/format/clip_codec.h>

#include "viewer/montage_panel.h"

namespace ossa::view {

SceneLayout compute_layout(int window_w, int window_h, int fb_w, int fb_h, float panel_width, float timeline_height) {
  SceneLayout l;
  const float ww = static_cast<float>(std::max(window_w, 1)), wh = static_cast<float>(std::max(window_h, 1));
  const float sx = static_cast<float>(std::max(fb_w, 1)) / ww, sy = static_cast<float>(std::max(fb_h, 1)) / wh;
  const float panel = std::clamp(std::isfinite(panel_width) ? panel_width : 0.0f, 0.0f, ww - 1.0f);
  const float strip = std::clamp(std::isfinite(timeline_height) ? timeline_height : 0.0f, 0.0f, wh - 1.0f);
  l.scene = Rect{panel, 0.0f, ww - panel, wh - strip};
  l.timeline = Rect{panel, wh - strip, ww - panel, strip};
  // Framebuffer pixels: round the edges, not the sizes, so adjacent strips meet exactly.
  const int left = static_cast<int>(std::lround(panel * sx));
  const int bottom = static_cast<int>(std::lround(strip * sy));
  l.fb_x = std::min(left, std::max(fb_w, 1) - 1);
  l.fb_y = std::min(bottom, std::max(fb_h, 1) - 1);
  l.fb_width = std::max(std::max(fb_w, 1) - l.fb_x, 1);
  l.fb_height = std::max(std::max(fb_h, 1) - l.fb_y, 1);
  l.aspect = static_cast<float>(l.fb_width) / static_cast<float>(l.fb_height);
  return l;
}

float ui_scale_for(float content_scale, float framebuffer_per_window) {
  const auto sane = [](float v) { return std::isfinite(v) && v > 0.0f ? v : 1.0f; };
  return std::clamp(sane(content_scale) / sane(framebuffer_per_window), 0.5f, 4.0f);
}

std::vector<KeyMark> clip_key_marks(const ClipView& clip) {
  std::vector<KeyMark> out;
  const uint32_t frames = std::max<uint32_t>(clip.frame_count(), 1);
  const float rate = clip.sample_rate() > 0.0f ? clip.sample_rate() : 30.0f;
  std::vector<uint32_t> per_frame(frames, 0);
  const std::span<const uint16_t> key_frames = clip.key_frames();
  for (const fb::AnimatedChannel& a : clip.animated()) {
    for (uint32_t k = 0; k < a.key_count(); ++k) {
      const uint32_t f = key_frame(key_frames.data(), a.first_key(), a.key_count(), clip.frame_count(), k);
      if (f < frames) ++per_frame[f];
    }
  }
  for (uint32_t f = 0; f < frames; ++f) {
    if (per_frame[f] == 0) continue;
    out.push_back({std::min(static_cast<float>(f) / rate, clip.duration()), per_frame[f]});
  }
  if (out.empty()) out.push_back({0.0f, 0});
  return out;
}

std::vector<EventMark> clip_event_marks(const ClipView& clip) {
  std::vector<EventMark> out;
  if (clip.fb == nullptr || clip.fb->events() == nullptr) return out;
  for (const fb::ClipEvent* e : *clip.fb->events()) out.push_back({e->name()->str(), e->time()});
  return out;
}

float time_to_x(float t, float duration, float x0, float width) {
  if (!(duration > 0.0f)) return x0;
  return x0 + width * std::clamp(t / duration, 0.0f, 1.0f);
}

float x_to_time(float x, float duration, float x0, float width) {
  if (!(duration > 0.0f) || !(width > 0.0f)) return 0.0f;
  return duration * std::clamp((x - x0) / width, 0.0f, 1.0f);
}

TimelineGrab timeline_grab(float x, bool in_handle_row, float loop_start_x, float loop_end_x, float reach) {
  if (in_handle_row) {
    const float ds = std::fabs(x - loop_start_x), de = std::fabs(x - loop_end_x);
    // Both handles at one spot (an empty range): grab the end when pressing right of it.
    if (std::min(ds, de) <= reach)
      return ds < de || (ds == de && x < loop_start_x) ? TimelineGrab::kLoopStart : TimelineGrab::kLoopEnd;
  }
  return TimelineGrab::kPlayhead;
}

float timeline_height(const App& app, float ui_scale) {
  const Animator& a = app.animator;
  if (!app.scene.assets.empty() && a.graph && a.use_graph) return montage_timeline_height(app, ui_scale);
  if (app.scene.assets.empty() || a.playback.clip < 0) return 0.0f;
  return std::round(56.0f * ui_scale);
}

void timeline_panel(App& app, TimelineState& st, const Rect& strip, float ui_scale) {
  if (app.animator.graph && app.animator.use_graph) return montage_timeline(app, strip, ui_scale);  // montages
  if (strip.height <= 0.0f || app.animator.playback.clip < 0) return;
  Playback& p = app.animator.playback;
  const ClipView clip = app.scene.clips[static_cast<size_t>(p.clip)].clip;
  if (st.clip != clip.fb) {
    st.clip = clip.fb;
    st.keys = clip_key_marks(clip);
    st.events = clip_event_marks(clip);
  }
  const float duration = clip.duration();
  const bool has_range = p.loop_end > p.loop_start;
  const float loop_start = has_range ? p.loop_start : 0.0f;
  const float loop_end = has_range ? std::min(p.loop_end, duration) : duration;

  ImGui::SetNextWindowPos(ImVec2(strip.x, strip.y));
  ImGui::SetNextWindowSize(ImVec2(strip.width, strip.height));
  ImGui::PushStyleVar(ImGuiStyleVar_WindowPadding, ImVec2(0.0f, 0.0f));
  ImGui::PushStyleVar(ImGuiStyleVar_WindowBorderSize, 0.0f);
  ImGui::Begin("##timeline", nullptr,
               ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoSavedSettings |
                   ImGuiWindowFlags_NoScrollWithMouse | ImGuiWindowFlags_NoFocusOnAppearing);
  ImDrawList* dl = ImGui::GetWindowDrawList();
  const float pad = 10.0f * ui_scale;
  const float label_w = ImGui::CalcTextSize("000.00 / 000.00 s").x + 12.0f * ui_scale;  // the time read-out
  const float x0 = strip.x + label_w, width = std::max(strip.width - label_w - pad, 1.0f);
  const float handle_h = 10.0f * ui_scale;
  const float top = strip.y + 4.0f * ui_scale, track_top = top + handle_h,
              bottom = strip.y + strip.height - 4.0f * ui_scale;
  const float track_h = bottom - track_top;

  dl->AddRectFilled(ImVec2(strip.x, strip.y), ImVec2(strip.x + strip.width, strip.y + strip.height),
                    IM_COL32(24, 26, 30, 255));
  dl->AddRectFilled(ImVec2(x0, track_top), ImVec2(x0 + width, bottom), IM_COL32(40, 44, 52, 255));
  // The loop range: shaded, with a handle at each end.
  const float ls = time_to_x(loop_start, duration, x0, width), le = time_to_x(loop_end, duration, x0, width);
  dl->AddRectFilled(ImVec2(ls, track_top), ImVec2(le, bottom),
                    p.loop ? IM_COL32(60, 90, 140, 255) : IM_COL32(55, 60, 70, 255));
  for (const float hx : {ls, le}) {
    dl->AddTriangleFilled(ImVec2(hx - 5.0f * ui_scale, top), ImVec2(hx + 5.0f * ui_scale, top), ImVec2(hx, track_top),
                          IM_COL32(120, 170, 240, 255));
  }
  // Keys: a tick per keyed frame, its height by how many channels key it.
  uint32_t most = 1;
  for (const KeyMark& k : st.keys) most = std::max(most, k.channels);
  for (const KeyMark& k : st.keys) {
    const float x = std::floor(time_to_x(k.time, duration, x0, width)) + 0.5f;
    const float h = track_h * (0.25f + 0.5f * static_cast<float>(k.channels) / static_cast<float>(most));
    dl->AddLine(ImVec2(x, bottom - h), ImVec2(x, bottom), IM_COL32(170, 175, 185, 200));
  }
  // Events: a diamond at the top of the track, named on hover.
  const ImVec2 mouse = ImGui::GetIO().MousePos;
  const EventMark* hovered = nullptr;
  for (const EventMark& e : st.events) {
    const float x = time_to_x(e.time, duration, x0, width), r = 5.0f * ui_scale, y = track_top + r + 1.0f;
    dl->AddQuadFilled(ImVec2(x, y - r), ImVec2(x + r, y), ImVec2(x, y + r), ImVec2(x - r, y),
                      IM_COL32(250, 200, 60, 255));
    if (std::fabs(mouse.x - x) <= r + 1.0f && std::fabs(mouse.y - y) <= r + 1.0f) hovered = &e;
  }
  // The playhead.
  const float px = time_to_x(p.time, duration, x0, width);
  dl->AddLine(ImVec2(px, top), ImVec2(px, bottom), IM_COL32(240, 80, 80, 255), 2.0f * ui_scale);
  char readout[48];
  std::snprintf(readout, sizeof readout, "%.2f / %.2f s", p.time, duration);
  dl->AddText(ImVec2(strip.x + 6.0f * ui_scale, track_top), IM_COL32(220, 220, 220, 255), readout);

  // Input: one invisible button over the track and the handle row.
  ImGui::SetCursorScreenPos(ImVec2(x0 - pad, top));
  ImGui::InvisibleButton("##track", ImVec2(width + 2.0f * pad, bottom - top));
  if (ImGui::IsItemActivated()) {
    st.dragging = timeline_grab(mouse.x, mouse.y < track_top, ls, le, 8.0f * ui_scale);
    if (st.dragging == TimelineGrab::kPlayhead) {
      st.was_playing = p.playing;
      p.playing = false;
    }
  }
  if (ImGui::IsItemActive()) {
    const float t = x_to_time(mouse.x, duration, x0, width);
    if (st.dragging == TimelineGrab::kPlayhead) set_time(app.scene, app.animator, t);
    if (st.dragging == TimelineGrab::kLoopStart) {
      p.loop_start = std::min(t, loop_end);
      p.loop_end = loop_end;
    }
    if (st.dragging == TimelineGrab::kLoopEnd) {
      p.loop_start = loop_start;
      p.loop_end = std::max(t, loop_start);
    }
  } else if (st.dragging != TimelineGrab::kNone) {
    if (st.dragging == TimelineGrab::kPlayhead) p.playing = st.was_playing;
    if (p.loop_start <= 0.0f && p.loop_end >= duration) p.loop_start = p.loop_end = 0.0f;  // the whole clip again
    st.dragging = TimelineGrab::kNone;
  }
  if (hovered != nullptr) ImGui::SetTooltip("%s at %.3f s", hovered->name.c_str(), hovered->time);
  else if (ImGui::IsItemHovered() && st.dragging == TimelineGrab::kNone)
    ImGui::SetTooltip("drag: scrub   drag a blue handle: loop range (%.2f - %.2f s)", loop_start, loop_end);
  ImGui::End();
  ImGui::PopStyleVar(2);
}

}  // namespace ossa::view
