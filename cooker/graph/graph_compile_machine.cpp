// graph_compile_machine.cpp — the graph compiler's state machines: states, transitions and their
// conditions (the class is in graph_compiler.h). A file of its own because a machine reads a
// structure of its own (states by name, transitions between them) unlike any blend-tree node.
#include "cooker/graph/graph_compiler.h"
#include <ossa/anim/blend_space.h>
#include <ossa/loader/validate.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>
#include <unordered_set>

namespace ossa::cook::graph_detail {

// ---- state machines ------------------------------------------------------------------------
int GraphCompiler::machine_node(const Value& v, const std::string& name) {
  check_.expect_keys(v, {"state_machine", "name"}, "a state machine node");
  const Value& m = *v.find("state_machine");
  if (!check_.expect(m, Type::Object, "\"state_machine\"")) return -1;
  check_.expect_keys(m, {"name", "entry", "states", "transitions"}, "a state machine");
  if (g_.machines.size() >= 65535) return check_.error(m.pos, "more than 65535 state machines"), -1;
  const size_t machine_index = g_.machines.size();
  g_.machines.emplace_back();  // reserved now: machines are numbered in the order they are met
  StateMachineDef sm;
  bool ok = true;
  if (const Value* n = required(m, "name", "a state machine"))
    ok &= check_.expect_name(*n, "a state machine's \"name\"", &sm.name);
  else ok = false;
  const std::string label = sm.name.empty() ? std::string("the state machine") : "state machine '" + sm.name + "'";

  std::vector<Pos> state_pos;
  const Value* states = required(m, "states", "a state machine");
  if (states && check_.expect(*states, Type::Object, "\"states\" ({\"<state>\": {\"node\": ...}, ...})")) {
    if (states->members.empty()) ok = check_.error(states->pos, label + " has no states");
    // Transition.from is int16. Past that nothing in the machine can be compiled: say so alone.
    if (states->members.size() > 32767) return check_.error(states->pos, label + " has more than 32767 states"), -1;
    for (const Member& s : states->members) {
      StateDef st;
      st.name = s.key;
      if (s.key == "any")
        ok = check_.error(s.key_pos, "'any' is reserved for transitions from any state; rename the state");
      if (s.key.empty()) ok = check_.error(s.key_pos, "a state name must not be empty");
      if (check_.expect(s.value, Type::Object, "state '" + s.key + "' ({\"node\": ..., \"restart\": ...})")) {
        check_.expect_keys(s.value, {"node", "restart"}, "a state");
        const Value* n = required(s.value, "node", "state '" + s.key + "'");
        const int child = n ? node(*n, "") : -1;
        ok &= child >= 0;
        st.node = static_cast<uint16_t>(std::max(child, 0));
        if (const Value* r = s.value.find("restart")) ok &= read_bool(*r, "\"restart\"", &st.restart);
      } else {
        ok = false;
      }
      sm.states.push_back(std::move(st));
      state_pos.push_back(s.key_pos);
    }
  } else {
    ok = false;
  }
  std::unordered_map<std::string_view, int> states_by_name;
  for (size_t i = 0; i < sm.states.size(); ++i) states_by_name.emplace(sm.states[i].name, static_cast<int>(i));
  const auto state_index = [&](const std::string& s) {
    const auto found = states_by_name.find(s);
    return found == states_by_name.end() ? -1 : found->second;
  };
  const auto unknown_state = [&](const Value& at, const std::string& what) {
    if (check_.full()) return check_.error(at.pos, what + " '" + at.string + "' is not a state of " + label);
    std::vector<std::string> names;
    for (const StateDef& s : sm.states) names.push_back(s.name);
    const std::string hint = json::closest_name(at.string, names);
    return check_.error(at.pos, what + " '" + at.string + "' is not a state of " + label +
                                    (hint.empty() ? "" : " (did you mean '" + hint + "'?)") +
                                    "; states: " + quoted(names));
  };

  bool entry_ok = false;
  if (const Value* e = m.find("entry")) {
    if (check_.expect(*e, Type::String, "\"entry\" (a state name)")) {
      const int entry = state_index(e->string);
      if (entry < 0) ok = unknown_state(*e, "the entry state");
      else sm.entry = static_cast<uint16_t>(entry), entry_ok = true;
    } else {
      ok = false;
    }
  } else {
    ok = check_.error(m.pos, label + " needs an \"entry\" state");
  }

  std::vector<long long> priorities;
  bool transitions_ok = true;
  if (const Value* ts = m.find("transitions"); ts && check_.expect(*ts, Type::Array, "\"transitions\"")) {
    for (const Value& t : ts->items) {
      TransitionDef tr;
      long long priority = 0;
      if (transition(t, state_index, unknown_state, tr, priority)) {
        sm.transitions.push_back(std::move(tr));
        priorities.push_back(priority);
      } else {
        transitions_ok = false;
      }
    }
  } else if (ts) {
    transitions_ok = false;
  }
  ok &= transitions_ok;

  // Stable sort by priority: lower first, file order among equals.
  std::vector<size_t> order(sm.transitions.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return priorities[a] < priorities[b]; });
  std::vector<TransitionDef> sorted;
  for (size_t i : order) sorted.push_back(std::move(sm.transitions[i]));
  sm.transitions = std::move(sorted);

  // Every state must be reachable from the entry (only meaningful once every transition read).
  if (entry_ok && transitions_ok) {
    std::vector<bool> reached(sm.states.size(), false);
    std::vector<size_t> stack = {sm.entry};
    reached[sm.entry] = true;
    std::vector<std::vector<uint16_t>> leads_to(sm.states.size());  // per state, where its transitions go
    for (const TransitionDef& t : sm.transitions) {
      if (t.from < 0 && !reached[t.to]) reached[t.to] = true, stack.push_back(t.to);  // "any" leaves every state
      if (t.from >= 0) leads_to[static_cast<size_t>(t.from)].push_back(t.to);
    }
    while (!stack.empty()) {
      const size_t s = stack.back();
      stack.pop_back();
      for (const uint16_t to : leads_to[s])
        if (!reached[to]) reached[to] = true, stack.push_back(to);
    }
    for (size_t s = 0; s < sm.states.size(); ++s)
      if (!reached[s])
        ok = check_.error(state_pos[s], "state '" + sm.states[s].name + "' of " + label +
                                            " cannot be reached: no transition leads to it from the entry state '" +
                                            sm.states[sm.entry].name + "'");
  }
  if (!ok) return -1;
  g_.machines[machine_index] = std::move(sm);
  return emit(name, StateMachineRefDef{static_cast<uint16_t>(machine_index)});
}

template <class StateIndex, class UnknownState>
bool GraphCompiler::transition(const Value& t, const StateIndex& state_index, const UnknownState& unknown_state,
                               TransitionDef& out, long long& priority) {
  if (!check_.expect(t, Type::Object, "a transition")) return false;
  check_.expect_keys(t, {"from", "to", "when", "exit_time", "duration", "mode", "priority"}, "a transition");
  bool ok = true;
  if (const Value* from = required(t, "from", "a transition (a state name or \"any\")")) {
    if (!check_.expect(*from, Type::String, "\"from\"")) {
      ok = false;
    } else if (from->string == "any") {
      out.from = -1;
    } else {
      const int s = state_index(from->string);
      if (s < 0) ok = unknown_state(*from, "\"from\"");
      out.from = static_cast<int16_t>(s);
    }
  } else {
    ok = false;
  }
  if (const Value* to = required(t, "to", "a transition")) {
    if (!check_.expect(*to, Type::String, "\"to\"")) {
      ok = false;
    } else {
      const int s = state_index(to->string);
      if (s < 0) ok = unknown_state(*to, "\"to\"");
      out.to = static_cast<uint16_t>(std::max(s, 0));
    }
  } else {
    ok = false;
  }
  if (ok && out.from >= 0 && out.from == static_cast<int>(out.to))
    ok = check_.error(t.find("to")->pos, "a transition from state '" + t.find("to")->string +
                                             "' to itself: a state cannot transition to itself (\"restart\" on the "
                                             "state replays it when it is entered again)");
  if (const Value* when = t.find("when")) {
    if (check_.expect(*when, Type::String, "\"when\" (a condition)")) {
      ConditionResult c = compile_condition(when->string, g_.parameters, &param_index_, !check_.full());
      if (!c.ok) {
        ok = check_.error_in_string(*when, c.error_offset, c.error);
      } else {
        for (const CondInstr& instr : c.code)  // a parameter already reported wrong is not re-checked
          if (instr.op != CondOp::True && instr.op < CondOp::Not && param_bad_[instr.parameter]) ok = false;
        out.condition = std::move(c.code);
      }
    } else {
      ok = false;
    }
  }
  if (const Value* e = t.find("exit_time")) {
    ok &= read_float(*e, "\"exit_time\" (normalized time of the source state; leave it out for none)", &out.exit_time,
                     0.0, kMaxSeconds);
  }
  if (const Value* d = t.find("duration"))
    ok &= read_float(*d, "\"duration\" (seconds)", &out.duration, 0.0, kMaxSeconds);
  if (const Value* mode = t.find("mode")) {
    static const std::vector<std::string_view> kModes = {"crossfade", "sync_crossfade", "inertialize"};
    if (!check_.expect(*mode, Type::String, "\"mode\"")) {
      ok = false;
    } else if (const auto at = std::find(kModes.begin(), kModes.end(), mode->string); at != kModes.end()) {
      out.mode = static_cast<TransitionModeDef>(at - kModes.begin());
    } else {
      const std::string hint = json::closest_name(mode->string, kModes);
      ok = check_.error(mode->pos, "unknown transition mode '" + mode->string + "'" +
                                       (hint.empty() ? "" : " (did you mean '" + hint + "'?)") +
                                       "; modes: crossfade, sync_crossfade, inertialize");
    }
  }
  if (const Value* p = t.find("priority"))
    ok &= check_.expect_integer(*p, "\"priority\" (lower is checked first)", -1000000000, 1000000000, &priority);
  return ok;
}

}  // namespace ossa::cook::graph_detail
