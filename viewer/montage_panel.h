// montage_panel.h — montages in the viewer's window (format v9): the panel's list of the graph's
// montages with play / stop / section buttons, and the timeline strip under the scene, which shows
// the montage playing while a graph drives the character (the clip timeline shows clips otherwise).
//
// The strip is the montage's timeline: its sections as labelled spans (a loop marked so), its
// events as markers (instants, windows as bars, branching points), the playhead at instance 0's
// position and its blend weight. It is drawn like the clip timeline (layout.h), with ImGui draw
// lists in an undecorated window pinned to SceneLayout::timeline; a click on a section jumps there.
#pragma once
#include "viewer/app.h"
#include "viewer/layout.h"

namespace ossa::view {

/// The montage part of the graph panel (nothing when the graph has none).
void montage_panel(GraphDriver& graph);

/// The strip's height while a graph drives the character: a strip when its graph has montages, else 0.
float montage_timeline_height(const App& app, float ui_scale);

/// Draws the shown montage's timeline (the first montage before any was played) into `strip`.
void montage_timeline(App& app, const Rect& strip, float ui_scale);

}  // namespace ossa::view
