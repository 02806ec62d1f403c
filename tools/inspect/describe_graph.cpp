// describe_graph.cpp — the "graphs" part of ossa-inspect's description (describe_parts.h): what a
// cooked animation graph holds, its transition conditions turned back into infix text. Everything
// read comes through a verified Asset (the loader checked every index used here).
#include <algorithm>
#include <string>
#include <vector>

#include "common/message.h"
#include "tools/inspect/describe.h"
#include "tools/inspect/describe_parts.h"

namespace ossa::inspect::parts {
namespace {

using detail::format;

/// A montage track's length on its timeline: the sum of (end - start) / rate over its segments
/// (the loader has checked that every rate is positive).
double track_length(const fb::MontageTrack& track) {
  double length = 0.0;
  if (track.segments() == nullptr) return length;
  for (const fb::MontageSegment* s : *track.segments())
    length += (static_cast<double>(s->end()) - static_cast<double>(s->start())) / static_cast<double>(s->rate());
  return length;
}

/// A condition program back in infix form, for reading: "speed > 4.5 && !crossed".
std::string condition_text(const fb::Graph& g, const fb::Transition& t) {
  const auto* cond = t.condition();
  if (!cond || cond->size() == 0) return "true";
  std::vector<std::string> stack;
  const auto param = [&](uint16_t p) { return str(g.parameters()->Get(p)->name()); };
  static const char* const kOps[] = {"", "<", "<=", ">", ">=", "==", "!="};
  for (const fb::ConditionInstr* c : *cond) {
    const auto op = c->op();
    if (op == fb::ConditionOp::True) {
      stack.push_back("true");
    } else if (op >= fb::ConditionOp::Less && op <= fb::ConditionOp::NotEqual) {
      const fb::Parameter& p = *g.parameters()->Get(c->parameter());
      std::string value = format("%g", static_cast<double>(c->value()));
      if (p.type() == fb::ParameterType::Enum && p.enum_values() && c->value() >= 0.0f &&
          c->value() < static_cast<float>(p.enum_values()->size()))
        value = str(p.enum_values()->Get(static_cast<flatbuffers::uoffset_t>(c->value())));
      stack.push_back(param(c->parameter()) + " " + kOps[static_cast<int>(op)] + " " + value);
    } else if (op == fb::ConditionOp::Bool || op == fb::ConditionOp::Trigger) {
      stack.push_back(param(c->parameter()));
    } else if (op == fb::ConditionOp::Not && !stack.empty()) {
      stack.back() = "!(" + stack.back() + ")";
    } else if (stack.size() >= 2) {
      const std::string b = stack.back();
      stack.pop_back();
      stack.back() = "(" + stack.back() + (op == fb::ConditionOp::And ? " && " : " || ") + b + ")";
    }
  }
  return stack.empty() ? "?" : stack.back();
}

}  // namespace

json describe_graph(const fb::Graph& g) {
  json params = json::array(), machines = json::array();
  for (const fb::Parameter* p : *g.parameters()) {
    json item{{"name", str(p->name())},
              {"type", fb::EnumNameParameterType(p->type())},
              {"default", round6(p->default_value())}};
    if (p->type() == fb::ParameterType::Vector) {
      const fb::Vec3* v = p->default_vector();
      item["default"] = v ? json::array({round6(v->x()), round6(v->y()), round6(v->z())}) : json::array({0, 0, 0});
      item["space"] = fb::EnumNameParameterSpace(p->space());
    }
    if (p->enum_values()) {
      json values = json::array();
      for (const flatbuffers::String* v : *p->enum_values()) values.push_back(str(v));
      item["values"] = std::move(values);
    }
    params.push_back(std::move(item));
  }
  json kinds = json::object();
  for (const fb::Node* n : *g.nodes()) {
    const std::string kind = fb::EnumNameNodeData(n->data_type());
    kinds[kind] = kinds.value(kind, 0) + 1;
  }
  if (const auto* ms = g.machines()) {
    for (const fb::StateMachine* m : *ms) {
      json states = json::array(), transitions = json::array();
      for (const fb::State* st : *m->states()) states.push_back(str(st->name()));
      if (const auto* ts = m->transitions()) {
        for (const fb::Transition* t : *ts) {
          const auto state = [&](int i) { return i < 0 ? std::string("any") : str(m->states()->Get(i)->name()); };
          json item{{"from", state(t->from())},
                    {"to", state(t->to())},
                    {"when", condition_text(g, *t)},
                    {"duration", round6(t->duration())},
                    {"mode", fb::EnumNameTransitionMode(t->mode())}};
          if (t->exit_time() >= 0.0f) item["exit_time"] = round6(t->exit_time());
          transitions.push_back(std::move(item));
        }
      }
      machines.push_back(json{{"name", str(m->name())},
                              {"entry", str(m->states()->Get(m->entry())->name())},
                              {"states", std::move(states)},
                              {"transitions", std::move(transitions)}});
    }
  }
  json clips = json::array();
  for (const flatbuffers::String* c : *g.clips()) clips.push_back(str(c));
  json out{{"name", str(g.name())},           {"skeleton_hash", hex16(g.skeleton_hash())},
           {"parameters", std::move(params)}, {"clips", std::move(clips)},
           {"node_count", g.nodes()->size()}, {"nodes", std::move(kinds)},
           {"machines", std::move(machines)}};
  if (const auto* ms = g.montages(); ms && ms->size() > 0) {  // format v9
    json montages = json::array();
    for (const fb::Montage* m : *ms) {
      json tracks = json::array(), sections = json::array();
      double length = 0.0;
      for (const fb::MontageTrack* t : *m->tracks()) {
        length = std::max(length, track_length(*t));
        tracks.push_back(json{{"slot", str(t->slot())}, {"segments", t->segments()->size()}});
      }
      for (const fb::MontageSection* sec : *m->sections()) {
        const int next = sec->next();
        sections.push_back(
            json{{"name", str(sec->name())},
                 {"start", round6(sec->start())},
                 {"next", next >= 0 && next < static_cast<int>(m->sections()->size())
                              ? str(m->sections()->Get(static_cast<flatbuffers::uoffset_t>(next))->name())
                              : std::string()}});
      }
      const auto blend = [](float t, fb::MontageCurve c) {
        return format("%g s ", static_cast<double>(t)) + fb::EnumNameMontageCurve(c);
      };
      montages.push_back(json{{"name", str(m->name())},
                              {"group", str(m->group())},
                              {"length", round6(static_cast<float>(length))},
                              {"tracks", std::move(tracks)},
                              {"sections", std::move(sections)},
                              {"notifies", m->notifies() ? m->notifies()->size() : 0u},
                              {"blend_in", blend(m->blend_in(), m->blend_in_curve())},
                              {"blend_out", blend(m->blend_out(), m->blend_out_curve())},
                              {"rate", round6(m->rate())},
                              {"root_motion", m->root_motion()}});
    }
    out["montages"] = std::move(montages);
  }
  return out;
}

}  // namespace ossa::inspect::parts
