// montage_panel.cpp — see montage_panel.h.
#include "viewer/montage_panel.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include <imgui.h>

#include "viewer/montage_control.h"

namespace ossa::view {
namespace {

std::string str(std::string_view s) { return std::string(s); }

}  // namespace

void montage_panel(GraphDriver& g) {
  const GraphDefinition& d = *g.definition;
  if (d.montage_count() == 0 || g.instances.empty()) return;
  ImGui::Separator();
  ImGui::TextDisabled("montages (M: play, M again: let it finish)");
  for (size_t m = 0; m < d.montage_count(); ++m) {
    const int mi = static_cast<int>(m);
    ImGui::PushID(mi);
    if (ImGui::Button("play")) play_montage_everywhere(g, mi);
    ImGui::SameLine();
    if (ImGui::Button("stop"))
      for (GraphInstance& inst : g.instances) inst.stop_montage(mi);
    ImGui::SameLine();
    ImGui::Text("%s (group %s, %.2f s)", str(d.montage_name(m)).c_str(), str(d.montage_group(m)).c_str(),
                d.montage_length(m));
    const MontageStatus st = g.instances.front().montage_status(mi);
    const std::string state = montage_state_text(g, mi);
    ImGui::ProgressBar(st.playing ? st.position / std::max(d.montage_length(m), 1e-6f) : 0.0f, ImVec2(-1.0f, 0.0f),
                       state.c_str());
    // Sections: a button jumps there (while it plays); "(loop)" marks a section that repeats.
    for (size_t k = 0; k < d.section_count(m); ++k) {
      if (k > 0) ImGui::SameLine();
      const bool loops = d.section_next(m, k) == static_cast<int>(k);
      const std::string label = "-> " + str(d.section_name(m, k)) + (loops ? " (loop)" : "");
      if (ImGui::SmallButton(label.c_str())) {
        g.shown_montage = mi;
        for (GraphInstance& inst : g.instances) inst.jump_to_section(mi, static_cast<int>(k));
      }
    }
    if (st.playing && !st.blending_out && ImGui::SmallButton("let it finish")) {
      g.shown_montage = mi;
      (void)toggle_montage(g);
    }
    ImGui::PopID();
  }
}

float montage_timeline_height(const App& app, float ui_scale) {
  const Animator& a = app.animator;
  if (!a.graph || !a.use_graph || a.graph->definition->montage_count() == 0) return 0.0f;
  return std::round(64.0f * ui_scale);
}

void montage_timeline(App& app, const Rect& strip, float ui_scale) {
  Animator& a = app.animator;
  if (strip.height <= 0.0f || !a.graph || a.graph->instances.empty()) return;
  GraphDriver& g = *a.graph;
  const GraphDefinition& d = *g.definition;
  if (d.montage_count() == 0) return;
  const int m = g.shown_montage >= 0 ? g.shown_montage : 0;
  const size_t mu = static_cast<size_t>(m);
  const fb::Montage& fm = *d.graph().montages()->Get(static_cast<flatbuffers::uoffset_t>(m));
  const float length = d.montage_length(mu);
  const MontageStatus st = g.instances.front().montage_status(m);

  ImGui::SetNextWindowPos(ImVec2(strip.x, strip.y));
  ImGui::SetNextWindowSize(ImVec2(strip.width, strip.height));
  ImGui::PushStyleVar(ImGuiStyleVar_WindowPadding, ImVec2(0.0f, 0.0f));
  ImGui::PushStyleVar(ImGuiStyleVar_WindowBorderSize, 0.0f);
  ImGui::Begin("##montage-timeline", nullptr,
               ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoSavedSettings |
                   ImGuiWindowFlags_NoScrollWithMouse | ImGuiWindowFlags_NoFocusOnAppearing);
  ImDrawList* dl = ImGui::GetWindowDrawList();
  const float pad = 10.0f * ui_scale;
  const float label_w = ImGui::CalcTextSize("cross_arms_montage 00.00 s").x + 12.0f * ui_scale;
  const float x0 = strip.x + label_w, width = std::max(strip.width - label_w - pad, 1.0f);
  const float top = strip.y + 4.0f * ui_scale, bottom = strip.y + strip.height - 4.0f * ui_scale;
  const float row = (bottom - top) / 3.0f;  // sections, events, windows
  dl->AddRectFilled(ImVec2(strip.x, strip.y), ImVec2(strip.x + strip.width, strip.y + strip.height),
                    IM_COL32(24, 26, 30, 255));
  const ImVec2 mouse = ImGui::GetIO().MousePos;

  // Sections: spans in alternating shades, named; the playing one brighter; a loop says so.
  for (size_t k = 0; k < d.section_count(mu); ++k) {
    const float s0 = d.section_start(mu, k);
    const float s1 = k + 1 < d.section_count(mu) ? d.section_start(mu, k + 1) : length;
    const float xa = time_to_x(s0, length, x0, width), xb = time_to_x(s1, length, x0, width);
    const bool playing = st.playing && st.section == static_cast<int>(k);
    const ImU32 fill =
        playing ? IM_COL32(70, 110, 170, 255) : (k % 2 ? IM_COL32(48, 54, 66, 255) : IM_COL32(56, 62, 76, 255));
    dl->AddRectFilled(ImVec2(xa, top), ImVec2(xb - 1.0f, bottom), fill);
    const int next = d.section_next(mu, k);
    const std::string label = str(d.section_name(mu, k)) + (next == static_cast<int>(k) ? " (loop)"
                                                            : next < 0                  ? " |"
                                                                                        : "");
    dl->PushClipRect(ImVec2(xa, top), ImVec2(xb - 2.0f, top + row), true);
    dl->AddText(ImVec2(xa + 3.0f * ui_scale, top), IM_COL32(225, 225, 225, 255), label.c_str());
    dl->PopClipRect();
    if (ImGui::IsMouseClicked(ImGuiMouseButton_Left) && mouse.x >= xa && mouse.x < xb && mouse.y >= top &&
        mouse.y < bottom) {
      for (GraphInstance& inst : g.instances) inst.jump_to_section(m, static_cast<int>(k));
    }
  }
  // Events: instants as yellow diamonds, branching points as red triangles, windows as bars.
  const char* hovered = nullptr;
  float hovered_time = 0.0f;
  if (const auto* notifies = fm.notifies()) {
    for (const fb::MontageNotify* n : *notifies) {
      const float x = time_to_x(n->time(), length, x0, width), r = 5.0f * ui_scale, y = top + 1.5f * row;
      if (n->kind() == fb::MontageNotifyKind::Window) {
        const float xe = time_to_x(n->time() + n->duration(), length, x0, width);
        dl->AddRectFilled(ImVec2(x, top + 2.2f * row), ImVec2(xe, bottom - 2.0f), IM_COL32(120, 200, 140, 170));
        if (mouse.x >= x && mouse.x <= xe && mouse.y >= top + 2.2f * row && mouse.y <= bottom)
          hovered = n->name()->c_str();
      } else if (n->kind() == fb::MontageNotifyKind::BranchingPoint) {
        dl->AddTriangleFilled(ImVec2(x - r, y - r), ImVec2(x + r, y - r), ImVec2(x, y + r), IM_COL32(240, 90, 80, 255));
      } else {
        dl->AddQuadFilled(ImVec2(x, y - r), ImVec2(x + r, y), ImVec2(x, y + r), ImVec2(x - r, y),
                          IM_COL32(250, 200, 60, 255));
      }
      if (std::fabs(mouse.x - x) <= r + 1.0f && std::fabs(mouse.y - y) <= r + 1.0f) hovered = n->name()->c_str();
      if (hovered == n->name()->c_str()) hovered_time = n->time();
    }
  }
  // The playhead and its weight.
  if (st.playing) {
    const float px = time_to_x(st.position, length, x0, width);
    dl->AddLine(ImVec2(px, top), ImVec2(px, bottom), IM_COL32(240, 80, 80, 255), 2.0f * ui_scale);
  }
  char readout[96];
  std::snprintf(readout, sizeof readout, "%s", str(d.montage_name(mu)).c_str());
  dl->AddText(ImVec2(strip.x + 6.0f * ui_scale, top), IM_COL32(220, 220, 220, 255), readout);
  if (st.playing) std::snprintf(readout, sizeof readout, "%.2f s  w %.2f", st.position, st.weight);
  else std::snprintf(readout, sizeof readout, "%.2f s (M plays)", length);
  dl->AddText(ImVec2(strip.x + 6.0f * ui_scale, top + row), IM_COL32(170, 170, 170, 255), readout);
  if (hovered) ImGui::SetTooltip("%s at %.3f s", hovered, hovered_time);
  ImGui::End();
  ImGui::PopStyleVar(2);
}

}  // namespace ossa::view
