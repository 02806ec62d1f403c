// validate_montage.h — the loader's checks of a graph's slot nodes and montages (format v9), called
// by validate_graph.cpp. Internal to the runtime.
//
// Separate from validate_graph.cpp because montages are a table family of their own (tracks,
// segments, sections, notifies) with their own invariants; the graph checker only hands over what
// it knows (the clip and joint counts, the scan budget) and wraps the message with the graph's name.
#pragma once
#include <cstdint>
#include <string>

#include <ossa/format/ossa_generated.h>

namespace ossa::detail {

/// Limits the runtime sizes its per-character state by.
inline constexpr uint32_t kMaxMontageTracks = 64;
inline constexpr uint32_t kMaxMontageSegments = 4096;  // per track
inline constexpr uint32_t kMaxMontageSections = 256;
inline constexpr uint32_t kMaxMontageNotifies = 4096;
inline constexpr uint32_t kMaxMontageWindows = 64;  // window notifies per montage (a 64-bit open set)

/// "" when slot node `node` is sound; otherwise what is wrong, starting "node N (slot ...)".
/// `budget` is charged for the mask; *over_budget is set when it runs out.
std::string check_slot_node(const fb::SlotNode& slot, size_t node, uint32_t joint_count, uint64_t& budget,
                            bool* over_budget);

/// "" when every montage of the graph is sound; otherwise what is wrong, starting "montage N 'name'".
/// Checks: names and groups non-empty; 1..kMaxMontageTracks tracks, each naming a slot and laying
/// 1..kMaxMontageSegments segments of known clips, start >= 0, end > start, rate in (0, 1000],
/// timeline at most 1e6 s; 1..kMaxMontageSections sections, the first at 0, starts increasing and
/// before the timeline's end, next in [-1, sections); notifies sorted by time within the timeline,
/// known kinds, windows with a positive duration and at most kMaxMontageWindows of them; rate in
/// (0, 1000]; blend times in [0, 1e6] with known curves; a finite trigger time.
std::string check_montages(const fb::Graph& graph, uint64_t& budget, bool* over_budget);

/// A track's length on the timeline: the sum of (end - start) / rate over its segments.
double montage_track_length(const fb::MontageTrack& track);

}  // namespace ossa::detail
