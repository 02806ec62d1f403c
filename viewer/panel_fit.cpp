// panel_fit.cpp — see panel_fit.h.
#include "viewer/panel_fit.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>

#include <imgui.h>
#include <imgui_internal.h>

namespace ossa::view {

std::vector<float> share_heights(float available, const std::vector<float>& wanted, const std::vector<bool>& open,
                                 float minimum) {
  const size_t n = std::min(wanted.size(), open.size());
  std::vector<float> out(wanted.size(), 0.0f);
  const auto need = [&](size_t i) { return wanted[i] < 0.0f ? std::numeric_limits<float>::max() : wanted[i]; };
  std::vector<size_t> order;
  for (size_t i = 0; i < n; ++i)
    if (open[i]) order.push_back(i);
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return need(a) < need(b); });
  float left = std::max(available, 0.0f);
  for (size_t k = 0; k < order.size(); ++k) {
    const size_t i = order[k];
    const float fair = left / static_cast<float>(order.size() - k);
    const float floor = std::min(need(i), std::max(minimum, 0.0f));
    out[i] = std::max(std::min(need(i), fair), floor);
    left = std::max(left - out[i], 0.0f);
  }
  return out;
}

std::vector<std::string> PanelAudit::problems() const {
  std::vector<std::string> out;
  char line[256];
  constexpr float kSlack = 1.0f;  // sub-pixel rounding of ImGui's positions
  for (const PanelRegion& r : regions) {
    if (r.reach_x > r.clip.x + r.clip.width + kSlack) {
      std::snprintf(line, sizeof line, "%s: items reach x %.0f past its right edge %.0f", r.name.c_str(), r.reach_x,
                    r.clip.x + r.clip.width);
      out.emplace_back(line);
    }
    if (!r.scrolls && r.reach_y > r.clip.y + r.clip.height + kSlack) {
      std::snprintf(line, sizeof line, "%s: items reach y %.0f below its bottom edge %.0f", r.name.c_str(), r.reach_y,
                    r.clip.y + r.clip.height);
      out.emplace_back(line);
    }
    const float right = panel.x + panel.width, bottom = panel.y + panel.height;
    if (r.rect.x < panel.x - kSlack || r.rect.y < panel.y - kSlack ||
        std::min(r.rect.x + r.rect.width, r.clip.x + r.clip.width) > right + kSlack ||
        std::min(r.rect.y + r.rect.height, r.clip.y + r.clip.height) > bottom + kSlack) {
      std::snprintf(line, sizeof line, "%s: region %.0f %.0f %.0f %.0f is not inside the panel %.0f %.0f %.0f %.0f",
                    r.name.c_str(), r.rect.x, r.rect.y, r.rect.width, r.rect.height, panel.x, panel.y, panel.width,
                    panel.height);
      out.emplace_back(line);
    }
  }
  return out;
}

void audit_current_window(PanelAudit& audit, const std::string& name, bool scrolls) {
  const ImGuiWindow* w = ImGui::GetCurrentWindow();
  PanelRegion r;
  r.name = name;
  r.rect = Rect{w->Pos.x, w->Pos.y, w->Size.x, w->Size.y};
  const ImRect& c = w->InnerClipRect;
  r.clip = Rect{c.Min.x, c.Min.y, c.GetWidth(), c.GetHeight()};
  r.reach_x = w->DC.CursorMaxPos.x;
  r.reach_y = w->DC.CursorMaxPos.y;
  r.scrolls = scrolls;
  audit.regions.push_back(std::move(r));
}

float fill_list_height(float rows, float reserve_below, float* hidden) {
  const float line = ImGui::GetTextLineHeightWithSpacing();
  const float full = std::max(rows, 1.0f) * line;
  const float left = ImGui::GetContentRegionAvail().y - reserve_below;
  const float h = std::clamp(std::floor(left), std::min(full, 3.0f * line), full);
  if (hidden != nullptr) *hidden += full - h;
  return h;
}

float label_room(std::span<const std::string> labels, float cap) {
  float widest = 0.0f;
  for (const std::string& l : labels) {
    const std::string shown = l.substr(0, l.find("##"));
    widest = std::max(widest, ImGui::CalcTextSize(shown.c_str()).x);
  }
  return std::min(widest + ImGui::GetStyle().ItemInnerSpacing.x + 2.0f, cap);
}

}  // namespace ossa::view
