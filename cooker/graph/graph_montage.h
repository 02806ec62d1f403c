// graph_montage.h — the montage half of the graph compiler (docs/GRAPH.md "Montages"): slot nodes
// and the top-level "montages" object, compiled into SlotDef and MontageDef (graph_def.h).
//
// The graph compiler (graph_compile.cpp) owns the document walk; it hands this part a context of
// callbacks for what it already knows how to do (compile a node, resolve a clip or a joint name), so
// both report problems the same way, `file:line:col: what`, through one json::Checker. Montages are
// compiled after the root, because their tracks name slots and a slot exists only once its node is
// compiled; a montage's checks against its slots (a known slot, the same group) then point at the
// track that names it.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "cooker/model/graph_def.h"
#include "cooker/json/json_check.h"

namespace ossa::cook {

/// Limits of the format and the runtime (internal/validate_montage.h says the same).
inline constexpr size_t kMaxGraphMontages = 65535;

struct MontageCompiler {
  json::Checker& check;
  GraphDef& graph;
  const std::vector<float>& clip_duration;  // per graph clip, seconds
  /// A clip named by the string v (marked played), or -1 reported.
  std::function<int(const json::Value& v, const std::string& role)> clip;
  /// A joint named by the string v, or -1 reported.
  std::function<int(const json::Value& v, const std::string& role)> joint;
  /// Compiles the node written at v; its index, or -1 reported.
  std::function<int(const json::Value& v, const std::string& default_name)> node;

  /// Each slot node compiled so far (the graph's, not an unused named node's): where it was written.
  struct SlotSeen {
    std::string slot, group;
    json::Pos pos;
    uint16_t node = 0;
  };
  std::vector<SlotSeen> slots;
  bool collecting = true;  // false while unused named nodes are checked (their slots do not count)

  /// {"slot": "upper_body", "input": NODE, "group": "actions", "mask": [{"joint": ..., "depth": ...}],
  ///  "mode": "override" | "additive", "mesh_space_rotation": bool, "name": ...}
  int slot_node(const json::Value& v, const std::string& name);

  /// The top-level "montages" (null: none), after the root: fills graph.montages.
  void montages(const json::Value* montages);

  /// A slot placed where its montages would play nothing while a weight is 0 (inside a layer or the
  /// added input of an additive node weighted by a parameter, or of weight 0): an error at the slot.
  void check_slot_placement();
};

}  // namespace ossa::cook
