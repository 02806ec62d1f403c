// panel_fit.h — how the panel's sections share its height, and the check that every widget of the
// panel lies inside it.
//
// The panel is a column of the window's full height (ui.h): the hide button at the top, the help
// and status lines pinned at the bottom, and between them the collapsible sections (Graph, Clips,
// View, Stats, Files, ...). Each open section's body is a child region whose height comes from
// share_heights: a section that needs less than an equal share of what is left gets all it needs,
// the others split the rest equally, so a short section (View, Stats) never scrolls while a long
// one (a graph's parameters and status) scrolls inside its own region; the lists (clips, files)
// take what their region leaves instead of a fixed row count (fill_list_height). What a section
// needs is measured on the previous frame (its content height, plus the rows its list could not
// show), so the split settles on the second frame after a section opens or its content changes.
// When even the minimum rows do not fit (a tiny window) the sections' column scrolls as a whole.
//
// Labels are drawn right of their widgets; each section's widgets are narrowed by the widest label
// (label_room), so no label runs past the panel's edge.
//
// The check (PanelAudit) reads Dear ImGui's own bookkeeping of each region (imgui_internal.h: the
// rectangle, the clip rectangle, and the furthest extent any item reached): a region whose items
// reach past its clip rectangle sideways, or downwards where it may not scroll, has a widget cut
// off. ossa-view -v prints it for the captured frame (--window-frames), which is how
// tests/viewer/viewer_test_window.cpp checks the panel at 1280x720 and 1600x1000.
#pragma once
#include <span>
#include <string>
#include <vector>

#include "viewer/layout.h"

namespace ossa::view {

/// Heights for sections that want `wanted` (a negative value: not measured yet, as much as it
/// can get) out of `available`, closed sections (open[i] false) getting 0. Water-filling: in
/// order of need, each open section gets min(wanted, an equal share of what is left), but at least
/// min(wanted, minimum). The sum exceeds `available` only when the minimums do.
std::vector<float> share_heights(float available, const std::vector<float>& wanted, const std::vector<bool>& open,
                                 float minimum);

/// One region of the panel as laid out this frame, in window coordinates.
struct PanelRegion {
  std::string name;
  Rect rect;                             // where the region is
  Rect clip;                             // what of it is visible (items are cut off outside)
  float reach_x = 0.0f, reach_y = 0.0f;  // the furthest right / bottom edge an item reached
  bool scrolls = false;                  // items below the clip rectangle are reached by scrolling: not cut off
};

struct PanelAudit {
  Rect panel;
  std::vector<PanelRegion> regions;
  /// One line per widget cut off: "REGION: items reach x 412 past its right edge 380".
  std::vector<std::string> problems() const;
};

/// Records the current ImGui window (between Begin / BeginChild and End / EndChild, after its
/// last item) into `audit` as region `name`.
void audit_current_window(PanelAudit& audit, const std::string& name, bool scrolls);

/// Bookkeeping of one frame's sections: what each wanted when last drawn.
struct SectionFit {
  std::string name;
  float wanted = -1.0f;
};

/// The height of a list of `rows` rows that fills what the current region has left above
/// `reserve_below` (window units), at least three rows (or all, when fewer) and at most all of
/// them; what it could not show is added to `*hidden` (so the section's need counts every row).
float fill_list_height(float rows, float reserve_below, float* hidden);

/// The widest of `labels` plus ImGui's inner spacing, at most `cap`: the room to keep right of
/// each widget for its label (ImGui::PushItemWidth(-label_room(...))).
float label_room(std::span<const std::string> labels, float cap);

}  // namespace ossa::view
