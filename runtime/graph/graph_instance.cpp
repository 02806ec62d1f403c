// graph_instance.cpp — one character playing a graph: creation (every buffer reserved), the
// parameter setters the host calls, and update() (graph.h).
#include <algorithm>
#include <cmath>
#include <limits>

#include "graph/graph_internal.h"
#include "internal/float_env.h"
#include "internal/vector_clones.h"

#include <cstring>
#if defined(__SSE2__)
#include <immintrin.h>  // SSE2, and the AVX2 clone's 256-bit streams
#endif

namespace ossa {
using namespace graph_detail;

namespace {

constexpr float kMaxVector = 1e6f;  // coordinates kept where products stay finite

const fb::Parameter* parameter_at(const GraphDefinition::Impl& d, int i) {
  if (i < 0 || static_cast<size_t>(i) >= d.graph->parameters()->size()) return nullptr;
  return d.graph->parameters()->Get(static_cast<flatbuffers::uoffset_t>(i));
}

}  // namespace

GraphInstance::GraphInstance(std::unique_ptr<State> state) : state_(std::move(state)) {}
GraphInstance::GraphInstance(GraphInstance&&) noexcept = default;
GraphInstance& GraphInstance::operator=(GraphInstance&&) noexcept = default;
GraphInstance::~GraphInstance() = default;

namespace {

std::unique_ptr<GraphScratch::Buffers> make_buffers(const GraphDefinition::Impl& d) {
  auto b = std::make_unique<GraphScratch::Buffers>();
  b->poses.reserve(d.scratch_depth);
  for (uint32_t k = 0; k < d.scratch_depth; ++k) b->poses.emplace_back(d.joints);
  b->weights.assign(d.scratch_depth, std::vector<float>(d.channels.size(), 0.0f));
  b->model_base.resize(d.joints);
  b->model_layer.resize(d.joints);
  if (d.procedural) {
    b->model.resize(d.joints);
    b->moved.resize(d.joints);
  }
  return b;
}

}  // namespace

namespace graph_detail {

namespace {

using Lanes = std::pair<uint32_t, uint32_t>;

/// Streams the lanes [first, last) of `rows` rows `pitch` floats apart; the AVX2 copy in 256-bit
/// stores (half the instructions of the SSE2 loop, the same memory traffic). Both bases aligned
/// to the vector, pitch and lanes whole blocks of 8.
#if OSSA_HAVE_VECTOR_CLONES
__attribute__((target("avx2"))) void stream_avx2(const float* from, float* to, size_t pitch, size_t rows,
                                                 const Lanes* lanes, size_t count) {
  for (size_t k = 0; k < count; ++k) {
    const size_t first = lanes[k].first, last = lanes[k].second;
    for (size_t r = 0; r < rows * pitch; r += pitch)
      for (size_t i = r + first; i < r + last; i += 8) _mm256_stream_ps(to + i, _mm256_load_ps(from + i));
  }
}
#endif

/// stream_avx2's work for any x86-64: false (nothing written) when the bases are not 16-byte aligned.
bool stream(const float* from, float* to, size_t pitch, size_t rows, const Lanes* lanes, size_t count) {
#if defined(__SSE2__)
  const auto a = reinterpret_cast<uintptr_t>(from) | reinterpret_cast<uintptr_t>(to);
  if (a % 16 != 0) return false;
#if OSSA_HAVE_VECTOR_CLONES
  if (a % 32 == 0 && detail::vector_avx2_selected()) {
    stream_avx2(from, to, pitch, rows, lanes, count);
    return true;
  }
#endif
  for (size_t k = 0; k < count; ++k) {
    const size_t first = lanes[k].first, last = lanes[k].second;
    for (size_t r = 0; r < rows * pitch; r += pitch)
      for (size_t i = r + first; i < r + last; i += 4) _mm_stream_ps(to + i, _mm_load_ps(from + i));
  }
  return true;
#else
  (void)from, (void)to, (void)pitch, (void)rows, (void)lanes, (void)count;
  return false;
#endif
}

}  // namespace

void stream_pose(ConstPoseSpan from, PoseSpan to) {
  const Lanes all(0, kPoseComponents * to.stride);  // one row: the whole block of floats
  if (from.stride == to.stride && stream(from.base, to.base, all.second, 1, &all, 1))
    return;  // update() fences once, after every stream of the frame
  std::memcpy(to.base, from.base, sizeof(float) * kPoseComponents * to.stride);
}

void stream_lanes(ConstPoseSpan from, PoseSpan to, const std::vector<std::pair<uint32_t, uint32_t>>& lanes) {
  if (from.stride == to.stride && stream(from.base, to.base, to.stride, kPoseComponents, lanes.data(), lanes.size()))
    return;
  for (uint32_t k = 0; k < kPoseComponents; ++k)
    for (const auto& [first, last] : lanes)
      std::memcpy(to.base + size_t{k} * to.stride + first, from.base + size_t{k} * from.stride + first,
                  sizeof(float) * (last - first));
}

}  // namespace graph_detail

GraphScratch::GraphScratch(std::unique_ptr<Buffers> b) : buffers_(std::move(b)) {}
GraphScratch::GraphScratch(GraphScratch&&) noexcept = default;
GraphScratch& GraphScratch::operator=(GraphScratch&&) noexcept = default;
GraphScratch::~GraphScratch() = default;
GraphScratch GraphScratch::create(const GraphDefinition& definition) {
  return GraphScratch(make_buffers(definition.impl()));
}

Result<GraphInstance> GraphInstance::create(const GraphDefinition& definition, size_t event_capacity,
                                            bool own_scratch) {
  const GraphDefinition::Impl& d = definition.impl();
  auto s = std::make_unique<State>();
  s->def = &d;
  s->owner = &definition;
  const size_t param_count = d.graph->parameters()->size();
  s->values.assign(param_count + d.float_count + d.nodes.size(), 0.0f);
  s->params = std::span<float>(s->values.data(), param_count);
  s->floats = std::span<float>(s->values.data() + param_count, d.float_count);
  s->node_weights = std::span<float>(s->values.data() + param_count + d.float_count, d.nodes.size());
  s->caches.reserve(d.cache_count);
  for (size_t n = 0; n < d.nodes.size(); ++n) {
    const NodeInfo& info = d.nodes[n];
    if (info.kind == Kind::Clip && info.held >= 0) {
      s->caches.emplace_back();  // keeps cache indices; a held pose is never sampled
    } else if (info.kind == Kind::Clip) {
      const auto* c = static_cast<const fb::ClipNode*>(info.table);
      auto cache = make_sampling_cache(d.clips[c->clip()], d.skeleton, &d.prototypes[c->clip()]);
      if (!cache) return cache.error();
      s->caches.push_back(std::move(*cache));
    } else if (info.kind == Kind::Retarget) {
      const auto* r = static_cast<const fb::RetargetNode*>(info.table);
      const RetargetNodeData& data = d.retargets[info.aux];
      auto cache = make_sampling_cache(d.clips[r->clip()], data.source, &d.prototypes[r->clip()]);
      if (!cache) return cache.error();
      s->caches.push_back(std::move(*cache));
      auto buffers = make_retarget_instance(d, info);
      if (!buffers) return buffers.error();
      s->retargets.push_back(std::move(*buffers));
    } else if (info.kind == Kind::BlendSpace) {
      for (const fb::BlendSample* smp : *static_cast<const fb::BlendSpaceNode*>(info.table)->samples()) {
        auto cache = make_sampling_cache(d.clips[smp->clip()], d.skeleton, &d.prototypes[smp->clip()]);
        if (!cache) return cache.error();
        s->caches.push_back(std::move(*cache));
      }
    }
  }
  // Caches filtered to what a covering slot shows, for the nodes that may sample hidden.
  for (size_t n = 0; n < d.nodes.size(); ++n) {
    const NodeInfo& info = d.nodes[n];
    const int32_t h = d.node_hidden.empty() ? -1 : d.node_hidden[n];
    if (h < 0 || info.kind == Kind::Machine) continue;
    if (s->hidden_caches.empty()) s->hidden_caches.resize(d.cache_count);
    const std::vector<uint16_t> clips = sampled_clips(info);
    for (size_t k = 0; k < clips.size(); ++k) {
      auto cache = make_sampling_cache(d.clips[clips[k]], d.skeleton, &d.hidden_prototypes[clips[k]],
                                       d.slot_visible[static_cast<size_t>(h)]);
      if (!cache) return cache.error();
      s->hidden_caches[info.caches + k] = std::move(*cache);
    }
  }
  if (own_scratch) s->own_scratch = make_buffers(d);
  s->machines.resize(d.machines.size());
  for (size_t k = 0; k < s->machines.size(); ++k) {
    MachineState& m = s->machines[k];
    m.translation.resize(d.joints);
    m.rotation.resize(d.joints);
    m.last = Pose(d.joints);
    m.before_last = Pose(d.joints);
    m.last_weights = d.default_weights;
    m.weight_offset.assign(d.channels.size(), 0.0f);
    if (d.node_hidden.empty() || d.node_hidden[d.machines[k].node] < 0) continue;
    m.prev_translation.resize(d.joints);
    m.prev_rotation.resize(d.joints);
    for (MachineJournal& j : m.journal) j.values.assign(s->values.size(), 0.0f);
    m.replay_values.assign(s->values.size(), 0.0f);
    m.replay_weights = d.default_weights;
  }
  s->output = Pose(d.joints);
  s->morph = d.default_weights;
  s->vectors.assign(param_count, glm::vec3(0.0f));
  s->springs = d.springs;  // each instance its own chain state, copied from the checked prototypes
  s->event_capacity = event_capacity;
  s->events.reserve(event_capacity);
  if (!d.montages.empty()) {  // montages: fixed plays, their section links, a cache per track clip
    s->plays.resize(kMaxMontagePlays);
    s->montage_links.assign(size_t{kMaxMontagePlays} * d.max_sections, -1);
    for (size_t k = 0; k < s->plays.size(); ++k) s->plays[k].next = s->montage_links.data() + k * d.max_sections;
    for (size_t k = 0; k < d.montage_cache_clips.size(); ++k) {
      auto cache = make_sampling_cache(d.clips[d.montage_cache_clips[k]], d.skeleton, &d.montage_prototypes[k],
                                       d.montage_cache_joints[k]);
      if (!cache) return cache.error();
      s->montage_caches.push_back(std::move(*cache));
    }
    s->montage_events.reserve(event_capacity);
  }
  s->slot_inertia.resize(d.inertial_slots);
  for (MachineState& m : s->slot_inertia) {
    m.translation.resize(d.joints);
    m.rotation.resize(d.joints);
    m.last = Pose(d.joints);
    m.before_last = Pose(d.joints);
  }
  GraphInstance instance(std::move(s));
  instance.reset();
  return instance;
}

const GraphDefinition& GraphInstance::definition() const { return *state_->owner; }

bool GraphInstance::set_float(int parameter, float value) {
  const fb::Parameter* p = parameter_at(*state_->def, parameter);
  if (!p || p->type() != fb::ParameterType::Float || std::isnan(value)) return false;
  state_->params[static_cast<size_t>(parameter)] = std::clamp(value, p->min_value(), p->max_value());
  return true;
}

bool GraphInstance::set_int(int parameter, int value) {
  const fb::Parameter* p = parameter_at(*state_->def, parameter);
  if (!p || p->type() != fb::ParameterType::Int) return false;
  state_->params[static_cast<size_t>(parameter)] =
      std::clamp(static_cast<float>(value), std::ceil(p->min_value()), std::floor(p->max_value()));
  return true;
}

bool GraphInstance::set_bool(int parameter, bool value) {
  const fb::Parameter* p = parameter_at(*state_->def, parameter);
  if (!p || p->type() != fb::ParameterType::Bool) return false;
  state_->params[static_cast<size_t>(parameter)] = value ? 1.0f : 0.0f;
  return true;
}

bool GraphInstance::set_enum(int parameter, int value) {
  const fb::Parameter* p = parameter_at(*state_->def, parameter);
  if (!p || p->type() != fb::ParameterType::Enum || value < 0) return false;
  const size_t count = p->enum_values() ? p->enum_values()->size() : 0;
  if (static_cast<size_t>(value) >= count) return false;
  state_->params[static_cast<size_t>(parameter)] = static_cast<float>(value);
  return true;
}

bool GraphInstance::set_trigger(int parameter) {
  const fb::Parameter* p = parameter_at(*state_->def, parameter);
  if (!p || p->type() != fb::ParameterType::Trigger) return false;
  state_->params[static_cast<size_t>(parameter)] = 1.0f;
  return true;
}

bool GraphInstance::set_vector(int parameter, const glm::vec3& value) {
  const fb::Parameter* p = parameter_at(*state_->def, parameter);
  if (!p || p->type() != fb::ParameterType::Vector) return false;
  if (!std::isfinite(value.x) || !std::isfinite(value.y) || !std::isfinite(value.z)) return false;
  state_->vectors[static_cast<size_t>(parameter)] = glm::clamp(value, glm::vec3(-kMaxVector), glm::vec3(kMaxVector));
  return true;
}

glm::vec3 GraphInstance::vector(int parameter) const {
  if (!parameter_at(*state_->def, parameter)) return glm::vec3(std::numeric_limits<float>::quiet_NaN());
  return state_->vectors[static_cast<size_t>(parameter)];
}

bool GraphInstance::set_transform(const glm::mat4& model_to_world) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(model_to_world[c][r])) return false;
  const glm::mat4 inverse = glm::inverse(model_to_world);
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(inverse[c][r])) return false;  // singular
  state_->transform = model_to_world;
  state_->inverse_transform = inverse;
  return true;
}

const glm::mat4& GraphInstance::transform() const { return state_->transform; }

bool GraphInstance::reached(size_t node) const {
  const State& s = *state_;
  if (node >= s.def->nodes.size()) return false;
  const NodeInfo& info = s.def->nodes[node];
  if (info.kind != Kind::TwoBoneIk && info.kind != Kind::Aim) return false;
  return s.node_weights[node] > 0.0f && s.floats[info.floats] != 0.0f;
}

float GraphInstance::value(int parameter) const {
  if (!parameter_at(*state_->def, parameter)) return std::numeric_limits<float>::quiet_NaN();
  return state_->params[static_cast<size_t>(parameter)];
}

void GraphInstance::reset() {
  State& s = *state_;
  const auto& params = *s.def->graph->parameters();
  for (flatbuffers::uoffset_t i = 0; i < params.size(); ++i) {
    const fb::Parameter& p = *params.Get(i);
    s.params[i] = p.type() == fb::ParameterType::Trigger ? 0.0f : p.default_value();
    const fb::Vec3* v = p.type() == fb::ParameterType::Vector ? p.default_vector() : nullptr;
    s.vectors[i] = v ? glm::vec3(v->x(), v->y(), v->z()) : glm::vec3(0.0f);
  }
  for (size_t m = 0; m < s.machines.size(); ++m) restart_machine(s, static_cast<uint16_t>(m));
  clear_montages(s);
  restart(s, s.def->graph->root());
  std::fill(s.node_weights.begin(), s.node_weights.end(), 0.0f);
  s.events.clear();
  s.dropped = 0;
  copy_pose(s.def->bind, s.output);
  s.morph = s.def->default_weights;  // same size: no allocation
}

void GraphInstance::update(float dt) {
  if (!state_->own_scratch) return;  // made to share scratch: update(dt, scratch) only
  update(dt, *state_->own_scratch);
}

void GraphInstance::update(float dt, GraphScratch& scratch) { update(dt, scratch.buffers()); }

void GraphInstance::update(float dt, GraphScratch::Buffers& buffers) {
  // One guard for the whole update: the kernels it calls find FTZ/DAZ set and leave MXCSR alone.
  const detail::FlushDenormals flush;
  State& s = *state_;
  s.scratch = &buffers;
  if (!(dt >= 0.0f) || !std::isfinite(dt)) dt = 0.0f;
  s.events.clear();
  s.dropped = 0;
  ++s.update_counter;
  s.self = this;
  if (!s.plays.empty()) advance_montages(s, dt);
  std::fill(s.node_weights.begin(), s.node_weights.end(), 0.0f);
  Advance advance;
  advance.dt = dt;
  // The root evaluates into scratch (hot) and the result streams into the instance's output.
  PoseSpan root = buffers.poses[0].span();
  const std::span<float> root_weights = buffers.weights[0];
  evaluate(s, s.def->graph->root(), advance, 1.0f, true, root, root_weights, 1);
  if (!s.plays.empty()) finish_montages(s);
  stream_pose(root, s.output);
  std::copy(root_weights.begin(), root_weights.end(), s.morph.begin());
#if defined(__SSE2__)
  // Streaming stores are weakly ordered: fence them so that whatever the host uses to hand this
  // character to another thread (even a plain release store) publishes the pose and histories.
  _mm_sfence();
#endif
  s.scratch = nullptr;
}

ConstPoseSpan GraphInstance::pose() const { return state_->output.span(); }
std::span<const float> GraphInstance::morph_weights() const { return state_->morph; }
std::span<const GraphEvent> GraphInstance::events() const { return state_->events; }
size_t GraphInstance::dropped_events() const { return state_->dropped; }
float GraphInstance::node_weight(size_t node) const {
  return node < state_->node_weights.size() ? state_->node_weights[node] : 0.0f;
}

float GraphInstance::node_phase(size_t node) const {
  if (node >= state_->def->nodes.size()) return 0.0f;
  return cycle(*state_, static_cast<uint16_t>(node)).phase;
}

}  // namespace ossa
