// graph_internal.h — what the graph's .cpp files share: the bound definition (GraphDefinition::Impl)
// and one character's state (GraphInstance::State). Not a public header.
//
// The definition decodes each node once into a NodeInfo (its kind, its table, where its variable
// state lives), so evaluation switches on a small enum instead of re-reading unions, and per-joint
// data that depends only on the graph (layer masks, 2D triangulations, the bind pose an additive
// is measured against) is computed once and shared. Instance state is flat arrays indexed through
// NodeInfo offsets: no per-node allocations, nothing allocated by update().
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include <ossa/anim/blend_space.h>
#include <ossa/anim/spring.h>
#include <ossa/loader/validate.h>
#include <ossa/graph/graph.h>
#include <ossa/anim/sample.h>
#include <ossa/retarget/foot_contacts.h>
#include <ossa/retarget/retarget.h>

namespace ossa::graph_detail {

enum class Kind : uint8_t {
  Clip,
  BlendAlpha,
  Select,
  Layered,
  BlendSpace,
  Additive,
  Machine,
  Morph,
  TwoBoneIk,
  Aim,
  FootPlacement,
  FootLock,
  Spring,    // procedural: graph_procedural.cpp
  Slot,      // montages: graph_slot.cpp
  Retarget,  // graph_retarget.cpp (format v10)
};

struct NodeInfo {
  Kind kind = Kind::Clip;
  const void* table = nullptr;  // the fb::*Node table of this kind
  uint32_t floats = 0;          // offset of this node's variable state in State::floats
  uint32_t caches = 0;          // first sampling cache (clip: 1, blend space: one per sample)
  uint32_t aux = 0;             // layered: first mask (Impl::masks); blend space: 2D space index;
                                // slot: its SlotInfo (Impl::slots);
                                // morph: first drive channel (Impl::drive_channels);
                                // spring: first chain (State::springs), foot lock: first leg's
                                // events (Impl::leg_events); retarget: index into Impl::retargets
  uint32_t samples = 0;         // blend space: first entry in Impl::sample_x / sample_duration
  uint16_t machine = 0;         // Machine: index into Impl::machines
  int32_t held = -1;            // Clip with rate 0 and no rate parameter: index into Impl::held
  // Procedural nodes: their input and weight, decoded once so that a node at weight 0 costs a
  // parameter read, not table lookups.
  uint16_t input = 0;
  int16_t weight_parameter = -1;
  float weight = 1.0f;
};

/// A transition's condition and the triggers it consumes, decoded.
struct TransitionInfo {
  const fb::Transition* fb = nullptr;
  uint32_t first_trigger = 0, trigger_count = 0;  // into Impl::transition_triggers
};

struct MachineInfo {
  const fb::StateMachine* fb = nullptr;
  uint16_t node = 0;                        // the StateMachineNode that plays it
  std::vector<TransitionInfo> transitions;  // priority order
};

/// A retarget node's data made with the definition (graph_retarget.cpp): the source rig (another
/// file's skeleton), the retarget map, and the clip's foot contacts.
struct RetargetNodeData {
  SkeletonView source;
  RetargetMap map;
  std::vector<ContactSpan> contacts;
  float floor = 0.0f;
  float sample_rate = 30.0f;
};

/// A retarget node's per-instance buffers.
struct RetargetInstance {
  Pose source;
  RetargetScratch scratch;
};

/// A slot node, decoded (graph_slot.cpp).
struct SlotInfo {
  uint16_t input = 0;
  uint16_t slot = 0;     // index into Impl::slot_names
  uint16_t group = 0;    // index into Impl::groups
  int32_t mask = -1;     // index into Impl::slot_masks / slot_joints; -1: every joint
  int32_t inertia = -1;  // index into State::slot_inertia; -1: no montage of its group inertializes
  bool additive = false, mesh_space = false;
};

/// A montage segment placed on its montage's timeline (graph_montage.cpp).
struct SegmentInfo {
  uint16_t clip = 0;
  uint32_t cache = 0;  // index into State::montage_caches
  float clip_start = 0.0f, clip_end = 0.0f, rate = 1.0f;
  double begin = 0.0, end = 0.0;  // timeline seconds
};
struct TrackInfo {
  uint16_t slot = 0;  // index into Impl::slot_names
  uint32_t first_segment = 0, segment_count = 0;
  double length = 0.0;
};
/// A point where something happens on a montage's timeline: a notify, a window's begin or end, a
/// branching point. Sorted by time, ends before instants before branches before begins at one time.
enum class MarkerType : uint8_t { End = 0, Instant = 1, Branch = 2, Begin = 3 };
struct Marker {
  double time = 0.0;
  uint16_t notify = 0;  // index into the montage's notifies
  MarkerType type = MarkerType::Instant;
  uint8_t window = 0;  // Begin / End: the window's bit in MontagePlay::open
};
struct MontageInfo {
  const fb::Montage* fb = nullptr;
  uint16_t group = 0;
  double length = 0.0;  // the longest track
  uint32_t first_track = 0, track_count = 0;
  uint32_t first_marker = 0, marker_count = 0;
  std::vector<double> section_start;  // per section; section k ends where k + 1 starts (the last: length)
  std::vector<uint16_t> windows;      // per window bit: its notify
  bool inertial = false;              // a blend curve is Inertialize
};

/// Per-layer joint data for a mesh-space rotation blend: the mask roots (masked joints whose parent
/// is not masked) and their ancestors, ascending (parents first), whose model rotations the
/// blend needs.
struct LayerJoints {
  std::vector<uint16_t> chain;  // ancestors of mask roots and the roots, ascending
  std::vector<uint8_t> root;    // per chain entry: 1 when it is a mask root
};

}  // namespace ossa::graph_detail

namespace ossa {

struct GraphDefinition::Impl {
  const fb::Graph* graph = nullptr;
  SkeletonView skeleton;
  uint32_t joints = 0;
  std::vector<ClipView> clips;
  std::vector<SamplingCache> prototypes;  // one per clip: the fixed values instances share
  std::vector<graph_detail::NodeInfo> nodes;
  std::vector<graph_detail::MachineInfo> machines;
  std::vector<uint16_t> transition_triggers;
  std::vector<std::vector<float>> masks;                // one per layer (joint weights)
  std::vector<graph_detail::LayerJoints> layer_joints;  // parallel to masks
  std::vector<BlendSpace2D> spaces;
  std::vector<float> sample_x;         // blend-space sample positions (1D: sorted), per node in order
  std::vector<float> sample_duration;  // their clips' durations
  Pose bind;                           // the rig's bind pose, for additive deltas
  /// Poses of held clips (rate 0, no rate parameter: a pose that never moves), sampled once here
  /// and shared by every instance instead of being sampled by each, every frame.
  std::vector<Pose> held;
  uint32_t float_count = 0;    // size of State::floats
  uint32_t cache_count = 0;    // sampling caches per instance
  uint32_t scratch_depth = 0;  // scratch poses one evaluation needs at most, plus the root's
  // Morph weights (ossa/anim/morph.h): the channels are the distinct target names of the asset's
  // meshes; every pose the graph makes carries one weight per channel beside it.
  std::vector<std::string_view> channels;
  std::vector<float> default_weights;               // per channel
  std::vector<std::vector<int32_t>> clip_channels;  // per clip: each weight track's channel, or -1
  std::vector<std::vector<float>> layer_morphs;     // parallel to masks: 1 on channels the layer drives
  std::vector<int32_t> drive_channels;              // morph nodes' drives, in order: channel or -1
  // Procedural nodes: spring chains made (and checked) once, copied into each instance; each spring
  // node's colliders; each foot lock leg's plant and lift event names.
  std::vector<SpringChain> springs;                       // every spring node's chains, in node order
  std::vector<std::vector<SpringCollider>> colliders;     // per spring node, indexed by NodeInfo::samples
  std::vector<std::string_view> leg_events;               // per foot lock leg: plant, lift ("" none)
  bool procedural = false;                                // any procedural node: model matrices needed
  std::vector<graph_detail::RetargetNodeData> retargets;  // one per retarget node, in node order
  // Montages and slots (format v9).
  std::vector<graph_detail::SlotInfo> slots;  // per slot node, indexed by NodeInfo::aux
  std::vector<std::vector<float>> slot_masks;
  std::vector<graph_detail::LayerJoints> slot_joints;  // parallel to slot_masks
  /// Parallel to slot_masks: the masked joints as ranges [first, last) (a subtree is contiguous in
  /// depth-first order), so a slot writes exactly those and leaves every other joint's bits alone.
  std::vector<std::vector<std::pair<uint32_t, uint32_t>>> slot_ranges;
  std::vector<std::string_view> slot_names, groups;  // distinct names
  /// Parallel to slot_masks: the lanes [first, last), whole blocks of kPoseLanes, that hold a joint
  /// the mask leaves out: what a slot showing a montage at full weight shows of its input.
  std::vector<std::vector<std::pair<uint32_t, uint32_t>>> slot_shown_lanes;
  /// Per layer (parallel to masks), per slot mask: 1 when the slot mask covers every joint the
  /// layer weighs and the layer lies under that slot with no node keeping poses or reading model
  /// space on any way there (its blend is then seen only on the slot's shown lanes).
  std::vector<std::vector<uint8_t>> layer_covered;
  /// Parallel to slot_masks: 1 on the joints the mask leaves out (what the slot shows of its input at
  /// full weight): the joint filter of the sampling caches its input samples with while hidden.
  std::vector<std::vector<uint8_t>> slot_visible;
  /// Per node: the slot mask under which it may leave the mask's joints out (-1: never). A clip or a
  /// blend space then samples with State::hidden_caches; a machine evaluates its states on the shown
  /// lanes and keeps its history by replaying them (graph_machine.cpp). Set for nodes a masked
  /// override slot reaches with nothing on the way that keeps poses or reads model space, but for
  /// machines whose states hold only clips, blend spaces and blends (hidden_machine).
  std::vector<int32_t> node_hidden;
  /// Per clip: the prototype of its caches filtered by slot_visible[hidden_prototype_mask[clip]]
  /// (-1: none; one mask per clip, the first that needs one).
  std::vector<SamplingCache> hidden_prototypes;
  std::vector<int32_t> hidden_prototype_mask;
  std::vector<graph_detail::MontageInfo> montages;
  std::vector<graph_detail::TrackInfo> tracks;
  std::vector<graph_detail::SegmentInfo> segments;
  std::vector<graph_detail::Marker> markers;
  std::vector<uint16_t> montage_cache_clips;  // per montage sampling cache: its clip
  // Parallel to montage_cache_clips: the joints its track's slots show (empty: all; ossa/anim/sample.h's
  // joint filter), and the prototype of that clip and filter the instances' caches share.
  std::vector<std::vector<uint8_t>> montage_cache_joints;
  std::vector<SamplingCache> montage_prototypes;
  std::vector<Pose> track_reference;  // per track: its first frame (additive slots)
  Pose identity;                      // every joint at identity (masked additives)
  uint32_t max_sections = 0;          // sections of the largest montage
  uint32_t inertial_slots = 0;        // slots with an inertialization state
};

namespace graph_detail {

/// Per joint inertialization of one channel (translation or rotation): offset = direction * x(t),
/// x the quintic through (x0, v0, a0) reaching 0 with zero velocity and acceleration at t1:
/// x = k5 t^5 + k4 t^4 + k3 t^3 + k2 t^2 + v0 t + x0 (k2 = a0 / 2). The coefficients are fixed when
/// the offset is captured (init_channel), so that a frame evaluates the polynomial without the
/// three divisions they take.
struct InertialChannel {
  glm::vec3 direction{0.0f};
  float x0 = 0.0f, v0 = 0.0f, t1 = 0.0f;
  float k5 = 0.0f, k4 = 0.0f, k3 = 0.0f, k2 = 0.0f;
};

/// A machine's scalars that its update changes: the state played, the transition, the clocks.
/// Kept apart (MachineState's base) so a hidden update can journal them in one copy (MachineJournal).
struct MachineClock {
  int current = 0;      // the state being entered / played
  int source = -1;      // a running crossfade's source state
  int transition = -1;  // running transition index
  fb::TransitionMode mode = fb::TransitionMode::Crossfade;
  float elapsed = 0.0f, duration = 0.0f;
  double normalized = 0.0;         // the current state's normalized time since it was entered
  double normalized_before = 0.0;  // ... at the start of the last update
  bool looping = true;             // whether the current state's leader loops
  // Inertialization: the offset kept when the machine switched discontinuously.
  bool inertial = false;
  float inertial_elapsed = 0.0f, inertial_duration = 0.0f;
};

/// One update a machine evaluated on a covering slot's shown lanes only: the instance's scalars and
/// the machine's clock as its states were evaluated, and how it advanced.
struct MachineJournal {
  uint64_t update = 0;  // 0: empty
  float dt = 0.0f, phase = 0.0f, weight = 0.0f;
  bool synced = false;
  MachineClock clock;
  std::vector<float> values;  // State::values
};

struct MachineState : MachineClock {
  std::vector<InertialChannel> translation, rotation;  // per joint: the inertialization's offset
  // The last two outputs (for the offset and its velocity) and when they were made.
  Pose last, before_last;
  // Morph weights: the last output's, and the offset an inertialization decays (linearly).
  std::vector<float> last_weights, weight_offset;
  float last_dt = 0.0f;
  uint64_t last_update = 0, before_last_update = 0;  // update counter stamps; 0 = never
  bool entered = false;                              // false: enter the entry state at the next evaluation
  // A machine a covering slot may hide joints of (Impl::node_hidden): which history buffers hold
  // shown lanes only, the journals of those updates, the offset channels before the last capture
  // (and its update), and the buffers a replay uses. Empty for other machines.
  bool last_partial = false, before_last_partial = false;
  uint32_t skipped_joints = 0;  // joints left out in the last update
  uint64_t capture_update = 0;
  MachineJournal journal[2];
  std::vector<InertialChannel> prev_translation, prev_rotation;
  std::vector<float> replay_values, replay_weights;
};

}  // namespace graph_detail

/// Memory an update uses only while it runs: shareable by every instance updated on one thread.
struct GraphScratch::Buffers {
  std::vector<Pose> poses;
  std::vector<std::vector<float>> weights;  // parallel to poses: morph channel weights
  // Mesh-space layering: model rotations of base and layer along a mask's chain, one per joint.
  std::vector<glm::quat> model_base, model_layer;
  // Procedural nodes: the pose's model matrices, and which joints a correction moved.
  std::vector<glm::mat4> model;
  std::vector<uint8_t> moved;
  const float* model_pose = nullptr;  // the pose `model` matches (set by the procedural node that
                                      // built it; null when partly stale)
};

namespace graph_detail {

/// Montage plays per character: the playing montage of each group and those still blending out.
inline constexpr uint32_t kMaxMontagePlays = 8;

/// One montage being played (graph_montage.cpp).
struct MontagePlay {
  int32_t montage = -1;   // -1: free
  uint64_t serial = 0;    // play order (later plays are blended over earlier ones)
  uint32_t revision = 0;  // bumped by jumps, so an advance notices a listener's jump
  uint16_t section = 0;
  double position = 0.0;                      // timeline seconds
  float rate = 1.0f;                          // the host's rate times the montage's
  float weight = 0.0f, weight_before = 0.0f;  // now, and at the start of the update
  float blend_from = 0.0f, blend_to = 1.0f, blend_time = 0.0f;
  double blend_elapsed = 0.0;  // seconds (double: a blend's end lands on the frame it should, not one later)
  fb::MontageCurve curve = fb::MontageCurve::Linear;
  bool blend_fresh = false;  // the blend began inside this update with blend_elapsed already set
  bool blending_out = false, interrupted = false, at_end = false, ended = false;
  uint64_t open = 0;           // open window notifies (bit per window)
  uint64_t switch_update = 0;  // the update in which an inertialized blend switched it (0: none)
  float switch_time = 0.0f;    // that blend's time
  float slot_weight = 0.0f;    // the most weight a slot applied it with in the last update
  int16_t* next = nullptr;     // per section: the section after it (State::montage_links)
};

}  // namespace graph_detail

struct GraphInstance::State {
  const GraphDefinition::Impl* def = nullptr;
  const GraphDefinition* owner = nullptr;
  // One allocation for the per-frame scalars (a crowd pays one cache miss for them, not three):
  std::vector<float> values;
  std::span<float> params;        // parameter values
  std::span<float> floats;        // node variable state
  std::span<float> node_weights;  // per node, last update
  std::vector<SamplingCache> caches;
  std::unique_ptr<GraphScratch::Buffers> own_scratch;  // null when made to share a GraphScratch
  GraphScratch::Buffers* scratch = nullptr;            // during update(): the buffers in use
  std::vector<graph_detail::MachineState> machines;
  Pose output;
  std::vector<float> morph;        // output morph channel weights
  std::vector<GraphEvent> events;  // capacity reserved; size() = events of the last update
  size_t event_capacity = 0;
  size_t dropped = 0;
  uint64_t update_counter = 0;
  // Procedural nodes only, last so that the fields every update reads stay on the lines they had:
  std::vector<glm::vec3> vectors;  // Vector parameters' values (one slot per parameter)
  glm::mat4 transform{1.0f};       // model to world, set by the host (set_transform)
  glm::mat4 inverse_transform{1.0f};
  std::vector<SpringChain> springs;                       // every spring node's chains' state
  std::vector<graph_detail::RetargetInstance> retargets;  // one per retarget node
  // Montages (graph_montage.cpp), last for the same reason: a graph without them reads none of it.
  std::vector<graph_detail::MontagePlay> plays;  // kMaxMontagePlays when the graph has montages
  std::vector<int16_t> montage_links;            // plays * max_sections
  std::vector<SamplingCache> montage_caches;
  std::vector<graph_detail::MachineState> slot_inertia;  // inertialized montage switches per slot
  std::vector<MontageEvent> montage_events;              // capacity event_capacity
  size_t montage_events_old = 0;                         // events before this index are dropped by the next update
  uint64_t play_serial = 0;
  bool montages_active = false;  // some play is in use (else updates skip montages)
  MontageListener listener = nullptr;
  void* listener_user = nullptr;
  GraphInstance* self = nullptr;  // handed to the listener
  RootMotionDelta root_motion;    // the last update's, from root-motion montages
  // While a masked override slot that shows its montages at full weight evaluates its input: its
  // mask (Impl::slot_masks), whose joints nothing will see of that input; -1 otherwise. Layers
  // marked in Impl::layer_covered for it leave those joints unblended (graph_slot.cpp).
  int32_t hidden = -1;
  glm::vec3 root_motion_up{0.0f, 1.0f, 0.0f};
  // Parallel to caches: for the clips and blend spaces of Impl::node_hidden, a cache filtered to
  // what their slot shows, sampled with while State::hidden is that slot's mask (else empty).
  std::vector<SamplingCache> hidden_caches;
};

namespace graph_detail {

/// How a subtree advances this frame: by seconds, or (synchronized) by a normalized phase delta.
struct Advance {
  float dt = 0.0f;
  float phase = 0.0f;
  bool synced = false;
};

/// Evaluates node `n` into out, advancing it. weight: its contribution to the output (recorded for
/// node_weight); dominant: whether its clips may fire events; depth: first free scratch pose.
/// ow: the output's morph channel weights (empty when the character has none), written beside out.
void evaluate(GraphInstance::State& s, uint16_t n, const Advance& advance, float weight, bool dominant, PoseSpan out,
              std::span<float> ow, uint32_t depth);
/// Puts a subtree back to its start (clip times to start offsets, machines to entry, selection and
/// layer weights to their targets).
void restart(GraphInstance::State& s, uint16_t n);
/// The subtree's leading cycle: duration in seconds (> 0) and normalized phase in [0, 1].
struct Cycle {
  float duration = 1.0f;
  float phase = 0.0f;
  bool loop = true;
};
Cycle cycle(const GraphInstance::State& s, uint16_t n);
/// Moves every clip of the subtree to normalized phase p.
void set_phase(GraphInstance::State& s, uint16_t n, float p);

/// Procedural nodes (graph_procedural.cpp): evaluate the input, then correct the pose in model space.
void evaluate_procedural(GraphInstance::State& s, uint16_t n, const Advance& advance, float weight, bool dominant,
                         PoseSpan out, std::span<float> ow, uint32_t depth);
/// The node's input (every procedural node has exactly one).
uint16_t procedural_input(const NodeInfo& info);
/// Back to the animated pose: foot locks released, spring chains restarted at the next update.
void restart_procedural(GraphInstance::State& s, uint16_t n);

/// Retarget node (graph_retarget.cpp). The rig a graph clip binds to: the graph's, or the source
/// rig of the first retarget node playing it, found by hash in `asset` or `more` (an error names
/// the clip when none holds it).
Result<SkeletonView> retarget_clip_rig(const GraphDefinition::Impl& d, uint16_t clip, const Asset& asset,
                                       std::span<const Asset* const> more, const std::string& where);
/// Builds the node's RetargetNodeData (its rig checked against the clip, the map, the contacts)
/// and points info.aux at it.
Status bind_retarget_node(GraphDefinition::Impl& d, NodeInfo& info, const fb::RetargetNode& node, const Asset& asset,
                          std::span<const Asset* const> more, const std::string& where);
Result<RetargetInstance> make_retarget_instance(const GraphDefinition::Impl& d, const NodeInfo& info);
void evaluate_retarget(GraphInstance::State& s, uint16_t n, const Advance& advance, PoseSpan out, std::span<float> ow);
void restart_retarget(GraphInstance::State& s, const NodeInfo& info);
Cycle retarget_cycle(const GraphInstance::State& s, const NodeInfo& info);
void set_retarget_phase(GraphInstance::State& s, const NodeInfo& info, float p);

/// Slot node (graph_slot.cpp) and montage playback (graph_montage.cpp).
void evaluate_slot(GraphInstance::State& s, uint16_t n, const Advance& advance, float weight, bool dominant,
                   PoseSpan out, std::span<float> ow, uint32_t depth);
/// Decodes the slot nodes and montages of a definition (tracks, segments, markers, masks, reference
/// poses); errors name the montage (a segment past its clip's end, a clip bound to no sampler).
Status bind_montages(GraphDefinition::Impl& d, const std::string& where);
/// Decodes the slot nodes (graph_slot.cpp): their names, groups, masks, mask ranges and chains.
void bind_slots(GraphDefinition::Impl& d);
/// The clips a clip node (one) or a blend space (one per sample, in order) samples, with a cache each.
std::vector<uint16_t> sampled_clips(const NodeInfo& info);
/// The joints the slot nodes named `slot` read from a montage's pose (ossa/anim/sample.h's joint
/// filter): their masks and mesh-space chains; empty (every joint) when one of them has no mask.
std::vector<uint8_t> slot_shown_joints(const GraphDefinition::Impl& d, uint16_t slot);
/// `name`'s index in `names`, appended when absent.
uint16_t intern_name(std::vector<std::string_view>& names, std::string_view name);
/// Advances every playing montage by dt: blend weights, positions, sections, notifies, root motion.
void advance_montages(GraphInstance::State& s, float dt);
/// After the graph is evaluated: montages blended out are ended and their plays freed.
void finish_montages(GraphInstance::State& s);
/// Back to no montage playing (reset()): plays freed without events.
void clear_montages(GraphInstance::State& s);
/// Samples a montage track at timeline `position` into out; *clip and *time say what was sampled.
void sample_track(GraphInstance::State& s, const TrackInfo& track, double position, PoseSpan out, uint16_t* clip,
                  float* time);
/// The montage's track for slot `slot`, or null.
const TrackInfo* track_for(const GraphDefinition::Impl& d, const MontageInfo& m, uint16_t slot);

/// A mesh-space rotation blend of a layer over `out` on a mask (graph_eval.cpp).
void blend_mesh_space(GraphInstance::State& s, const LayerJoints& lj, std::span<const float> mask, float w,
                      ConstPoseSpan layer, PoseSpan out);

/// Inertialization pieces shared by the machine and the slot (graph_machine.cpp).
void init_channel(InertialChannel& c, const glm::vec3& offset, const glm::vec3& velocity, float duration);
glm::vec3 rotation_vector(glm::quat q);
void apply_offset(const GraphInstance::State& s, const MachineState& m, PoseSpan out);

/// State machine node (graph_machine.cpp).
void evaluate_machine(GraphInstance::State& s, uint16_t n, const Advance& advance, float weight, bool dominant,
                      PoseSpan out, std::span<float> ow, uint32_t depth);

/// The scratch weights at `depth` (parallel to the scratch pose there).
inline std::span<float> scratch_weights(GraphInstance::State& s, uint32_t depth) { return s.scratch->weights[depth]; }
void restart_machine(GraphInstance::State& s, uint16_t machine);
Cycle machine_cycle(const GraphInstance::State& s, uint16_t machine);
void set_machine_phase(GraphInstance::State& s, uint16_t machine, float p);

inline glm::quat rotation_at(ConstPoseSpan p, uint32_t j) {
  return glm::quat(p[kRw][j], p[kRx][j], p[kRy][j], p[kRz][j]);
}
inline void set_rotation(PoseSpan p, uint32_t j, const glm::quat& q) {
  p[kRx][j] = q.x;
  p[kRy][j] = q.y;
  p[kRz][j] = q.z;
  p[kRw][j] = q.w;
}

/// Copies a pose with streaming stores (graph_instance.cpp): for destinations that are written
/// every frame but read later or rarely (an instance's output, a machine's history). With a crowd
/// those lines are not in cache; writing around the cache saves reading each line first and
/// leaves the cache to what the next character reads. The caller fences (update() does, once).
/// O(stride).
void stream_pose(ConstPoseSpan from, PoseSpan to);
/// stream_pose for the lanes [first, last) of each range (whole blocks of kPoseLanes) only.
/// O(lanes copied).
void stream_lanes(ConstPoseSpan from, PoseSpan to, const std::vector<std::pair<uint32_t, uint32_t>>& lanes);

/// Scratch needed by a subtree beyond `out` (graph_definition.cpp computes it once).
uint32_t scratch_needed(const GraphDefinition::Impl& def, uint16_t n);

}  // namespace graph_detail
}  // namespace ossa
