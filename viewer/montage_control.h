// montage_control.h — the viewer as the host that plays montages (format v9, graph.h): the command
// line's timed calls, the M key, and the event log.
//
// Every crowd instance gets the same calls, so a crowd acts together. Montage calls on the command
// line are timed in graph seconds (--montage NAME@T, --montage-next SECTION=NEXT@T, --montage-jump
// SECTION@T): a graph cannot seek, so a headless render at --time reaches them on its way, and the
// same line gives the same image. Kept apart from the panel (montage_panel.h) so it is tested
// without a window.
#pragma once
#include <string>
#include <string_view>
#include <vector>

#include <ossa/format/result.h>
#include "viewer/graph_driver.h"

namespace ossa::view {

/// The montage calls of the command line, checked against the graph and queued on the driver.
/// `plays`: "NAME" or "NAME@T"; `nexts`: "SECTION=NEXT@T" (NEXT empty: the montage ends after
/// SECTION); `jumps`: "SECTION@T". Sections belong to the last montage of `plays` (an error when
/// there is none). T defaults to 0. Errors name the text at fault and list the montages or sections.
Status add_montage_commands(GraphDriver& driver, const std::vector<std::string>& plays,
                            const std::vector<std::string>& nexts, const std::vector<std::string>& jumps);

/// Makes the queued calls whose time the graph has reached (GraphDriver::time), on every instance.
void run_montage_commands(GraphDriver& driver);

/// Appends instance 0's montage events of the last update to GraphDriver::recent_events.
void log_montage_events(GraphDriver& driver);

/// The M key: plays the shown montage (the first one when none was shown yet) on every instance
/// when it is not playing; when it is, lets it finish: every section that loops to itself is
/// linked to the section after it (or to the end), so playback runs out to the montage's end.
/// Returns false when the graph has no montage.
bool toggle_montage(GraphDriver& driver);

/// Plays montage `m` on every instance and shows it.
void play_montage_everywhere(GraphDriver& driver, int m);

/// "play", "blending out", ... for the panel: what instance 0's montage `m` is doing.
std::string montage_state_text(const GraphDriver& driver, int m);

}  // namespace ossa::view
