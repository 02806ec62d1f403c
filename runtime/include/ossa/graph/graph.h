// graph.h — the animation graph at runtime: a cooked Graph table (format/ossa.fbs) bound to its
// clips once, then evaluated per character without allocation.
//
// The seed thesis studies Unreal's Animation Blueprint: an event graph sets variables each frame,
// an anim graph of nodes turns them into a pose, and state machines (nested, with transition rules
// and blend times) choose what plays. Here the host plays the event graph's role through the
// parameter setters; GraphInstance::update(dt) runs the anim graph.
//
// Shape, after ozz-animation's split of immutable data from per-instance state:
//   - GraphDefinition: the graph plus everything derivable from it once (clip views resolved by
//     name, per-joint layer masks, 2D blend-space triangulations, the pose scratch depth). Read-only
//     after creation, shared by every character (and thread) playing the graph.
//   - GraphInstance: one character. Parameters, every node's state (clip times and sampling caches,
//     selection weights, state machines with their transition and inertialization buffers), the
//     scratch poses and the event buffer, all reserved when it is created. update() allocates
//     nothing and is deterministic: the same inputs give the same bits.
//
// Evaluation is one recursive walk from the root over the nodes that have weight; a node with zero
// weight is neither advanced nor sampled. Transitions:
//   - Crossfade: source and target both advance; weight = elapsed / duration (linear, exact).
//   - SyncCrossfade: the target starts at the source's normalized phase and both advance in
//     normalized time over a cycle blended from the two durations, so feet stay in step.
//   - Inertialize: the machine switches at once and the offset between the last output pose and
//     the target's pose (per joint translation and rotation) decays to zero over the duration along
//     a quintic that starts with the offset's own velocity (Bollo, "Inertialization", GDC 2018): no
//     pop and no velocity jump.
// An interruption (a transition out of a running transition's target) is handled the same way: the
// new transition starts from the target, and the pose the character had is kept by an inertialized
// offset, so the blend continues from the current blended pose without a pop.
//
// Morph weights ride beside every pose (one float per morph channel, GraphInstance::morph_weights):
// crossfades, blend spaces, selects and alpha blends mix them with the pose's weights, additives add
// their difference from the defaults, an inertialized switch decays the jump linearly, and a layer
// blends the channels its own clips drive.
//
// Procedural nodes (format v6) post-process their input's pose in model space: two-bone IK, aim
// over a chain, foot placement on per-foot ground planes, foot locking and spring chains (ossa/anim
// ik.h and spring.h do the solving). Vector parameters give their targets; set_transform gives
// where the character stands, so locks and springs act in world space. Their state (locked feet,
// spring tails) is per instance, reserved at creation. reset(), or a state restarting their
// subtree, puts them back on the animated pose; a spring node's teleport_distance does so when the
// character jumps further than that in one update.
//
// Montages (format v9) are one-shot actions the host plays over the graph (Unreal's Animation
// Montages): play_montage starts one, and it shows wherever a slot node names one of its tracks,
// replacing (or adding to) the slot's input on the slot's joints by its blend weight; with none
// playing a slot passes its input through bit for bit. A montage's timeline is cut into sections
// whose next-section links the host may change (set_next_section) or follow at once
// (jump_to_section); it blends in and out along a linear, cubic or inertialized curve, starts its
// blend out on its own so that it has blended out when it reaches its end, and reports its
// notifies over exactly the interval played, so none is lost or doubled across loops, jumps, rate
// changes or long frames. One montage per group plays: a new one blends the old one out with its
// own blend in. Everything is reserved when the instance is made; playing, stopping and updating
// allocate nothing.
//
// Events: a clip player reports the events its clip crosses in [previous time, new time) (wrapped
// across loops, reversed for negative rates), only when it lies on the dominant path: at every blend
// the child with the most weight (ties: the later child, i.e. a transition's target) passes dominance
// down; a layer or additive passes it to its input too when its weight is >= 0.5.
#pragma once
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <ossa/format/result.h>
#include <ossa/loader/asset.h>
#include <ossa/anim/pose.h>
#include <ossa/anim/root_motion.h>

namespace ossa {

class GraphInstance;

/// Graphs in a file.
size_t graph_count(const Asset& asset);
/// The graph named `name`, or null.
const fb::Graph* find_graph(const Asset& asset, std::string_view name);

/// An event crossed during the last update.
struct GraphEvent {
  std::string_view name;  // points into the file
  uint16_t clip = 0;      // index into the graph's clips
  uint16_t node = 0;      // the clip player or blend space that played it
  float time = 0.0f;      // the event's time in the clip, seconds
};

/// What happened to a montage (GraphInstance::montage_events, MontageListener).
enum class MontageEventType : uint8_t {
  Started,         // play_montage
  BlendingOut,     // its blend out began (interrupted: stopped or replaced before its end)
  Ended,           // it has blended out and no longer plays (interrupted as for BlendingOut)
  Notify,          // an instant notify was passed
  NotifyBegin,     // playback entered a window notify
  NotifyEnd,       // ... and left it (or the montage ended)
  BranchingPoint,  // a branching point was reached: the montage is exactly at its time
};

struct MontageEvent {
  MontageEventType type = MontageEventType::Started;
  uint16_t montage = 0;      // index into the graph's montages
  std::string_view name;     // the notify's (points into the file); empty for Started / BlendingOut / Ended
  float position = 0.0f;     // the montage's timeline position when it happened, seconds
  bool interrupted = false;  // BlendingOut, Ended
};

/// Called as a montage event happens, during update() or the host call that caused it. At a
/// branching point the montage stands exactly at the point's time, and what the listener does
/// (jump_to_section, set_next_section, stop_montage) takes effect from there, within the same update.
using MontageListener = void (*)(GraphInstance& instance, const MontageEvent& event, void* user);

/// A montage's state, for the host and for tests.
struct MontageStatus {
  bool playing = false;  // it plays (blending in, at full weight or blending out)
  bool blending_out = false;
  float position = 0.0f;     // timeline seconds
  int section = -1;          // the section playing
  float weight = 0.0f;       // its blend weight, [0, 1]
  float rate = 0.0f;         // host rate times the montage's rate
  float slot_weight = 0.0f;  // the most weight a slot node showed it with in the last update (0: no
                             // slot played it, e.g. every slot of its group lies in an inactive state)
};

/// Where a state machine is: for the host's UI and for tests.
struct MachineStatus {
  int current = -1;                 // the state being entered (a transition's target while one runs)
  int previous = -1;                // a running crossfade's source state, -1 when none
  float weight = 1.0f;              // the current state's blend weight (1 when no crossfade runs)
  float elapsed = 0.0f;             // seconds since the last transition started
  float duration = 0.0f;            // that transition's duration (0 when none ever ran)
  int transition = -1;              // index of the running transition, -1 when none
  float inertial_remaining = 0.0f;  // seconds left on an inertialization offset (0: none)
  // Joints the machine left unevaluated in the last update because a slot above it showed its
  // montages over them at full weight (0: it evaluated every joint). What is seen stays bit for bit.
  uint32_t skipped_joints = 0;
};

/// The immutable, shared part. Build once per (graph, clip sources); it must outlive its instances
/// and stay where it is while they live (they point at it), and the Assets it was made from must
/// outlive it (moving an Asset is fine: its bytes stay put).
class GraphDefinition {
 public:
  /// Binds `graph_name` of `asset` (the file's skeleton is the rig) to its clips, looked up by name
  /// in `asset` and then in `more_clips` (clip-only files cooked against the same rig). Errors name
  /// the file and graph: missing graph, no skeleton, a clip not found or bound to another rig.
  /// O(nodes + joints * layers + clips * names).
  static Result<GraphDefinition> create(const Asset& asset, std::string_view graph_name,
                                        std::span<const Asset* const> more_clips = {});

  GraphDefinition(GraphDefinition&&) noexcept;
  GraphDefinition& operator=(GraphDefinition&&) noexcept;
  ~GraphDefinition();

  const fb::Graph& graph() const;
  const SkeletonView& skeleton() const;
  uint32_t joint_count() const;
  size_t parameter_count() const;
  std::string_view parameter_name(size_t i) const;
  fb::ParameterType parameter_type(size_t i) const;
  /// Index of the parameter, or -1. O(parameters).
  int find_parameter(std::string_view name) const;
  size_t machine_count() const;
  std::string_view machine_name(size_t i) const;
  std::string_view state_name(size_t machine, size_t state) const;
  size_t state_count(size_t machine) const;
  size_t node_count() const;
  size_t clip_count() const;
  const ClipView& clip(size_t i) const;
  /// Morph channels: the distinct morph target names of the asset's meshes, in mesh order
  /// (ossa/anim/morph.h). GraphInstance::morph_weights() has one weight per channel.
  std::span<const std::string_view> morph_channels() const;

  // Montages (format v9). Indices follow Graph.montages and each montage's sections.
  size_t montage_count() const;
  std::string_view montage_name(size_t montage) const;
  /// Index of the montage, or -1. O(montages).
  int find_montage(std::string_view name) const;
  std::string_view montage_group(size_t montage) const;
  /// The timeline's length in seconds (its longest track).
  float montage_length(size_t montage) const;
  size_t section_count(size_t montage) const;
  std::string_view section_name(size_t montage, size_t section) const;
  float section_start(size_t montage, size_t section) const;
  /// The authored next section (-1: the montage ends after it).
  int section_next(size_t montage, size_t section) const;
  /// Index of the section, or -1. O(sections).
  int find_section(size_t montage, std::string_view name) const;

  struct Impl;
  const Impl& impl() const { return *impl_; }

 private:
  explicit GraphDefinition(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

/// The memory an update needs only while it runs (scratch poses, model rotations for mesh-space
/// layers): about three poses for the Pab sample. Every instance owns one by default; a host with
/// thousands of characters makes instances without (GraphInstance::create(..., false)) and gives
/// one GraphScratch per thread to update(), so each character's own state stays small and the
/// scratch stays hot in cache. One scratch serves every instance of the definition it was made for.
class GraphScratch {
 public:
  static GraphScratch create(const GraphDefinition& definition);
  GraphScratch(GraphScratch&&) noexcept;
  GraphScratch& operator=(GraphScratch&&) noexcept;
  ~GraphScratch();
  struct Buffers;
  Buffers& buffers() { return *buffers_; }

 private:
  explicit GraphScratch(std::unique_ptr<Buffers> b);
  std::unique_ptr<Buffers> buffers_;
};

/// One character playing a graph.
class GraphInstance {
 public:
  /// Reserves everything update() will use. `event_capacity` bounds the events kept per update
  /// (more are counted in dropped_events()). own_scratch = false: update(dt, scratch) only.
  /// O(joints * (scratch poses + machines) + clip channels).
  static Result<GraphInstance> create(const GraphDefinition& definition, size_t event_capacity = 64,
                                      bool own_scratch = true);

  GraphInstance(GraphInstance&&) noexcept;
  GraphInstance& operator=(GraphInstance&&) noexcept;
  ~GraphInstance();

  const GraphDefinition& definition() const;

  // ---- parameters (the event graph's side). Setters return false, and change nothing, for an
  // index out of range or a parameter of another type. Floats and ints are clamped to the
  // parameter's range; enums must be < the value count. O(1).
  bool set_float(int parameter, float value);
  bool set_int(int parameter, int value);
  bool set_bool(int parameter, bool value);
  bool set_enum(int parameter, int value);
  /// Sets a trigger; it stays set until a transition whose condition reads it fires.
  bool set_trigger(int parameter);
  /// Sets a Vector parameter (a point or direction, in the space the parameter declares: the
  /// character's model space, or world space carried through set_transform). Non-finite values
  /// are refused; coordinates are clamped to +-1e6.
  bool set_vector(int parameter, const glm::vec3& value);
  /// A Vector parameter's value as set (zero for other types; NaN for a bad index).
  glm::vec3 vector(int parameter) const;
  /// Any parameter's current value as stored (bools and triggers 0 / 1; 0 for vectors). NaN for a
  /// bad index.
  float value(int parameter) const;

  /// The character's model-to-world transform, set by the host before update() whenever the
  /// character moves: world-space Vector parameters, foot locks and spring chains go through it.
  /// Refuses (false) a matrix with a non-finite entry or no inverse. Identity until set.
  bool set_transform(const glm::mat4& model_to_world);
  const glm::mat4& transform() const;

  /// Advances by dt seconds (>= 0) and evaluates the output pose. Allocation-free. The first form
  /// uses the instance's own scratch (it must have one); the second a shared one.
  void update(float dt);
  void update(float dt, GraphScratch& scratch);
  /// Back to the state a fresh instance has (parameters to defaults, machines to entry, times to
  /// start offsets). Allocation-free.
  void reset();

  /// The output local pose of the last update (the bind pose before the first).
  ConstPoseSpan pose() const;
  /// The output's morph weights, one per GraphDefinition::morph_channels() entry: clips set the
  /// channels they have tracks for (the defaults elsewhere), and every blend, crossfade, layer and
  /// additive treats them as it treats joints. A layer blends the targets its Layer.morph_targets
  /// names, or by default the channels its own clips (or morph nodes) drive, so a face layer over a
  /// body changes the face and an upper-body layer leaves it.
  std::span<const float> morph_weights() const;
  /// Events crossed in the last update, in the order they were reached.
  std::span<const GraphEvent> events() const;
  size_t dropped_events() const;

  MachineStatus machine_status(size_t machine) const;
  /// The weight a node contributed to the output in the last update (0 when it was not evaluated).
  float node_weight(size_t node) const;
  /// Whether a two-bone IK or aim node reached its target at full weight in the last update
  /// (false for other nodes, and for one not evaluated).
  bool reached(size_t node) const;
  /// A node's normalized phase in [0, 1] (its leading clip's time / duration), for tools and tests.
  float node_phase(size_t node) const;

  // ---- montages (format v9). Calls with an unknown montage or section, or a rate outside
  // [0, 1000], return false and change nothing. O(plays + sections); allocation-free.

  /// Starts `montage` at `start_section` (-1: its first) at rate `rate` (times the montage's own).
  /// A montage of the same group still playing blends out (interrupted) over this one's blend in.
  bool play_montage(int montage, float rate = 1.0f, int start_section = -1);
  bool play_montage(std::string_view montage, float rate = 1.0f, std::string_view start_section = {});
  /// Blends `montage` out (-1: every montage playing) over `blend_out` seconds (< 0: its own blend
  /// out, with its curve); it reports BlendingOut and later Ended, both interrupted. False when
  /// nothing was playing.
  bool stop_montage(int montage = -1, float blend_out = -1.0f);
  bool stop_montage(std::string_view montage, float blend_out = -1.0f);
  /// While `montage` plays: the section after `section` becomes `next` (-1: the montage ends after it).
  bool set_next_section(int montage, int section, int next);
  bool set_next_section(std::string_view montage, std::string_view section, std::string_view next);
  /// While `montage` plays: playback moves to the start of `section` now.
  bool jump_to_section(int montage, int section);
  bool jump_to_section(std::string_view montage, std::string_view section);
  /// While `montage` plays: its rate (times the montage's own) from the next update on.
  bool set_montage_rate(int montage, float rate);
  /// The montage's latest play (the one not blending out when there is one).
  MontageStatus montage_status(int montage) const;
  bool montage_playing(int montage) const { return montage_status(montage).playing; }
  /// Montage events since the update before last ended: those of the last update, and those host
  /// calls raised after it, in the order they happened.
  std::span<const MontageEvent> montage_events() const;
  /// Called for every montage event as it happens (null: none).
  void set_montage_listener(MontageListener listener, void* user = nullptr);
  /// The root motion of the last update: what montages with root_motion that were not interrupted
  /// played of their first track's clips (their Clip.root_motion), at full strength; zero otherwise.
  /// In the character's frame at the start of the update (ossa/anim/root_motion.h).
  RootMotionDelta root_motion() const;

  struct State;

 private:
  explicit GraphInstance(std::unique_ptr<State> state);
  void update(float dt, GraphScratch::Buffers& buffers);
  std::unique_ptr<State> state_;
};

}  // namespace ossa
