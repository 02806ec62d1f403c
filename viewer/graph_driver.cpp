// graph_driver.cpp — see graph_driver.h.
#include "viewer/graph_driver.h"
#include "viewer/montage_control.h"

#include <algorithm>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <utility>

namespace ossa::view {
namespace {

std::string graph_names(const Scene& scene) {
  std::string names;
  for (size_t a = 0; a < scene.assets.size(); ++a) {
    const auto* graphs = scene.assets[a].file().graphs();
    if (graphs == nullptr) continue;
    for (const fb::Graph* g : *graphs) {
      names += (names.empty() ? "'" : ", '") + g->name()->str() + "' (" +
               std::filesystem::path(scene.paths[a]).filename().string() + ")";
    }
  }
  return names.empty() ? "none" : names;
}

}  // namespace

const char* parameter_type_name(fb::ParameterType type) {
  switch (type) {
    case fb::ParameterType::Float: return "float";
    case fb::ParameterType::Int: return "int";
    case fb::ParameterType::Bool: return "bool";
    case fb::ParameterType::Enum: return "enum";
    case fb::ParameterType::Trigger: return "trigger";
    case fb::ParameterType::Vector: return "vector";
  }
  return "?";
}

Result<GraphDriver> make_graph_driver(const Scene& scene, std::string_view name, size_t instances) {
  GraphDriver d;
  d.name = std::string(name);
  size_t holder = scene.assets.size();
  for (size_t a = 0; a < scene.assets.size() && holder == scene.assets.size(); ++a) {
    if (find_graph(scene.assets[a], name) != nullptr) holder = a;
  }
  if (holder == scene.assets.size()) {
    return Error{scene.paths.front() + ": no graph named '" + std::string(name) +
                 "' in the files given (graphs: " + graph_names(scene) + ")"};
  }
  d.asset = holder;
  const fb::Graph* g = find_graph(scene.assets[holder], name);
  if (g->skeleton_hash() != scene.skeleton().hash()) {
    return Error{scene.paths[holder] + ": graph '" + std::string(name) + "' animates another skeleton than " +
                 scene.paths.front() + "'s"};
  }
  std::vector<const Asset*> others;
  for (size_t a = 0; a < scene.assets.size(); ++a) {
    if (a != holder) others.push_back(&scene.assets[a]);
  }
  Result<GraphDefinition> def = GraphDefinition::create(scene.assets[holder], name, others);
  if (!def) return def.error();
  if (def->joint_count() != scene.joint_count()) {
    return Error{scene.paths[holder] + ": graph '" + std::string(name) + "' has " + std::to_string(def->joint_count()) +
                 " joints, the character " + std::to_string(scene.joint_count())};
  }
  d.definition = std::make_unique<GraphDefinition>(std::move(*def));
  d.procedural = describe_procedural(*d.definition);
  const std::span<const std::string_view> graph_channels = d.definition->morph_channels();
  for (const std::string_view channel : scene.morph_channels) {
    const auto it = std::find(graph_channels.begin(), graph_channels.end(), channel);
    d.morph_map.push_back(it == graph_channels.end() ? -1 : static_cast<int32_t>(it - graph_channels.begin()));
  }
  for (size_t i = 0; i < (instances == 0 ? 1 : instances); ++i) {
    Result<GraphInstance> inst = GraphInstance::create(*d.definition);
    if (!inst) return inst.error();
    // Phase spread for crowds: pre-roll by a fraction of a second (golden-ratio steps).
    const double phase = static_cast<double>(i) * 0.6180339887;
    const float preroll = static_cast<float>(phase - std::floor(phase));
    for (float t = 0.0f; t < preroll; t += 1.0f / 30.0f) inst->update(1.0f / 30.0f);
    d.instances.push_back(std::move(*inst));
  }
  return d;
}

int graph_parameter(const GraphDriver& driver, std::string_view name) {
  return driver.definition->find_parameter(name);
}

void set_graph_value(GraphDriver& driver, int index, float value) {
  const fb::ParameterType type = driver.definition->parameter_type(static_cast<size_t>(index));
  for (GraphInstance& g : driver.instances) {
    switch (type) {
      case fb::ParameterType::Float: g.set_float(index, value); break;
      case fb::ParameterType::Int: g.set_int(index, static_cast<int>(std::lround(value))); break;
      case fb::ParameterType::Bool: g.set_bool(index, value != 0.0f); break;
      case fb::ParameterType::Enum: g.set_enum(index, static_cast<int>(std::lround(value))); break;
      case fb::ParameterType::Trigger:
        if (value != 0.0f) g.set_trigger(index);
        break;
      case fb::ParameterType::Vector: break;  // three numbers: set_graph_vector
    }
  }
}

void fire_graph_trigger(GraphDriver& driver, int index) { set_graph_value(driver, index, 1.0f); }

bool set_graph_vector(GraphDriver& driver, int index, const glm::vec3& value) {
  bool all = true;
  for (GraphInstance& g : driver.instances) all = g.set_vector(index, value) && all;
  return all;
}

std::optional<glm::vec3> parse_vector(std::string_view text) {
  glm::vec3 v(0.0f);
  const char* p = text.data();
  const char* const end = text.data() + text.size();
  for (int k = 0; k < 3; ++k) {
    if (k > 0) {
      if (p == end || *p != ',') return std::nullopt;
      ++p;
    }
    const auto r = std::from_chars(p, end, v[k]);
    if (r.ec != std::errc() || !std::isfinite(v[k])) return std::nullopt;
    p = r.ptr;
  }
  if (p != end) return std::nullopt;
  return v;
}

Status set_graph_parameter(GraphDriver& driver, std::string_view name, std::string_view text) {
  const GraphDefinition& def = *driver.definition;
  const int p = def.find_parameter(name);
  if (p < 0) {
    std::string names;
    for (size_t i = 0; i < def.parameter_count(); ++i) names += (i ? ", " : "") + std::string(def.parameter_name(i));
    return Error{"graph '" + driver.name + "' has no parameter '" + std::string(name) + "' (parameters: " + names +
                 ")"};
  }
  const fb::ParameterType type = def.parameter_type(static_cast<size_t>(p));
  const std::string where =
      "graph '" + driver.name + "' parameter '" + std::string(name) + "' (" + parameter_type_name(type) + ")";
  if (type == fb::ParameterType::Vector) {
    const auto v = parse_vector(text);
    if (!v) return Error{where + ": cannot read '" + std::string(text) + "' as three finite numbers x,y,z"};
    if (!set_graph_vector(driver, p, *v)) return Error{where + ": value " + std::string(text) + " refused"};
    return {};
  }
  float value = 0.0f;
  if (type == fb::ParameterType::Trigger) {
    value = 1.0f;
  } else if (type == fb::ParameterType::Bool && (text == "true" || text == "false")) {
    value = text == "true" ? 1.0f : 0.0f;
  } else {
    bool named = false;
    if (type == fb::ParameterType::Enum) {
      const fb::Parameter* param = def.graph().parameters()->Get(static_cast<flatbuffers::uoffset_t>(p));
      if (param->enum_values() != nullptr) {
        for (flatbuffers::uoffset_t v = 0; v < param->enum_values()->size(); ++v) {
          if (param->enum_values()->Get(v)->string_view() == text) {
            value = static_cast<float>(v);
            named = true;
          }
        }
      }
    }
    if (!named) {
      const auto r = std::from_chars(text.data(), text.data() + text.size(), value);
      if (r.ec != std::errc() || r.ptr != text.data() + text.size()) {
        return Error{where + ": cannot read '" + std::string(text) + "' as a value"};
      }
    }
  }
  set_graph_value(driver, p, value);
  if (type != fb::ParameterType::Trigger && !driver.instances.empty() &&
      std::isnan(driver.instances.front().value(p))) {
    return Error{where + ": value " + std::string(text) + " refused"};
  }
  return {};
}

void update_graph(GraphDriver& driver, float dt) {
  run_montage_commands(driver);
  for (GraphInstance& g : driver.instances) g.update(dt);
  driver.time += dt;
  if (driver.instances.empty()) return;
  log_montage_events(driver);
  for (const GraphEvent& e : driver.instances.front().events()) {
    char line[160];
    std::snprintf(line, sizeof line, "%8.2f s  %.*s  (%.*s @ %.2f s)", driver.time, static_cast<int>(e.name.size()),
                  e.name.data(), static_cast<int>(driver.definition->clip(e.clip).name().size()),
                  driver.definition->clip(e.clip).name().data(), e.time);
    driver.recent_events.emplace_front(line);
    if (driver.recent_events.size() > kGraphEventLog) driver.recent_events.pop_back();
  }
}

}  // namespace ossa::view
