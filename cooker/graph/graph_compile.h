// graph_compile.h — a graph JSON file (docs/GRAPH.md) compiled into a GraphDef.
//
// Two steps, because the cooker must import before it can check: read_graph_manifest says what
// the file asks to import (the rig, mesh sources, a source per clip), the cooker imports them, and
// compile_graph then checks the whole file against what was imported (joint names, clip names
// and durations) and builds the GraphDef with every name resolved to an index.
//
// Every problem is reported, not only the first, each as `file:line:col: what is wrong`, one per
// line of the Error's message, pointing at the value at fault (for a condition, at the character
// inside the "when" string). Checks that depend on a value already found wrong are skipped, so one
// mistake gives one message. Nothing here throws or crashes on any input.
//
// Output shape: nodes children first (post-order), the root last; a {"use": name} expands a copy
// of the named node each time (the graph is a tree: each copy keeps its own state); machines in
// the order their "state_machine" nodes are met (outer before inner); each machine's transitions
// stably sorted by priority.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "cooker/model/graph_def.h"
#include "cooker/json/json_source.h"
#include "cooker/model/source_scene.h"
#include <ossa/format/result.h>

namespace ossa::cook {

/// Limits set by the format's 16-bit indices.
inline constexpr size_t kMaxGraphNodes = 65535;
inline constexpr size_t kMaxGraphParameters = 32767;  // rate/weight parameter fields are int16
inline constexpr size_t kMaxGraphClips = 65535;
inline constexpr uint32_t kMaxNodeDepth = 256;

/// One entry of "clips": the graph's name for a clip and where it comes from.
struct GraphClipSource {
  std::string name;
  std::string source;       // path relative to the graph file
  std::string source_clip;  // the clip's name in the source; empty: the source's first clip
  json::Pos pos;            // the entry's value (for messages about the source)
};

/// What a graph file asks the cooker to import.
struct GraphManifest {
  std::string name;
  std::string skeleton;  // path relative to the graph file
  json::Pos skeleton_pos;
  bool skeleton_meshes = true;  // false: {"source": ..., "meshes": false} keeps only the rig
  std::vector<std::string> meshes;
  std::vector<json::Pos> mesh_pos;
  std::vector<GraphClipSource> clips;  // Graph.clips order
};

/// Checks the top level and the "name", "skeleton", "meshes" and "clips" entries (their shape
/// only: clips' event times are checked by compile_graph, which knows the durations).
Result<GraphManifest> read_graph_manifest(const json::Document& doc);

/// A clip the graph can play, as imported (renamed to its graph name).
struct GraphClipInfo {
  std::string name;
  float duration = 0.0f;            // cooked duration (clip_events.h, event_duration)
  std::vector<SourceEvent> events;  // events it already has (its source's sidecar)
};

/// A retarget node's rigs as the cooker loaded them (format v10): the source rig's identity and
/// both rigs' humanoid bones (kHumanoidBoneCount entries each, -1: none) and rest settings.
struct GraphRetargetRigs {
  uint64_t source_skeleton_hash = 0;
  uint16_t source_joint_count = 0;
  std::vector<int16_t> source_bones, target_bones;
  uint8_t source_rest = 0, target_rest = 0;  // RestPose
  std::vector<RetargetRestRotationDef> source_rest_rotations, target_rest_rotations;
};

struct GraphContext {
  const SourceSkeleton* skeleton = nullptr;  // the rig: joint names for masks, hash, joint count
  std::vector<GraphClipInfo> clips;          // found by graph clip name
  /// Loads a retarget node's source rig (a cooked .ossa, relative to the graph file) and optional
  /// map file and maps both rigs (cook_graph.cpp); its error message is reported at the node.
  /// Unset: retarget nodes are an error.
  std::function<Result<GraphRetargetRigs>(const std::string& rig, const std::string& map)> retarget_rigs;
};

struct CompiledGraph {
  GraphDef graph;
  /// Per graph clip (graph.clips order): the context's events merged with the graph file's,
  /// sorted (clip_events.h, sort_events).
  std::vector<std::vector<SourceEvent>> clip_events;
  std::vector<std::string> warnings;  // `file:line:col: ...`: declared clips no node plays,
                                      // named nodes never used
};

/// Compiles a parsed graph file. O(file size + nodes * (parameters + clips + joints)).
Result<CompiledGraph> compile_graph(const json::Document& doc, const GraphContext& context);
/// Parses `text` (named `file` in messages) and compiles it.
Result<CompiledGraph> compile_graph(std::string_view text, std::string file, const GraphContext& context);

}  // namespace ossa::cook
