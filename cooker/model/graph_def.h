// graph_def.h — an animation graph as plain data: what the graph compiler (graph_compile.h) makes
// from a JSON file and what the writer serializes into the .ossa Graph table (format/ossa.fbs).
//
// It mirrors the schema one to one, with indices already resolved (clips, parameters, joints,
// nodes, states), so serialization is a copy and tests can build graphs in C++ without JSON.
// Nodes are stored children first: every index a node refers to is smaller than its own.
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace ossa::cook {

enum class ParamType : uint8_t { Float = 0, Int = 1, Bool = 2, Enum = 3, Trigger = 4, Vector = 5 };

struct GraphParameter {
  std::string name;
  ParamType type = ParamType::Float;
  float default_value = 0.0f;
  float min_value = -3.4e38f, max_value = 3.4e38f;
  std::vector<std::string> enum_values;
  float default_vector[3] = {0.0f, 0.0f, 0.0f};  // Vector, in the rig's units
  bool world = false;                            // Vector: world space (else model space)
};

/// Same numbering as fb::ConditionOp.
enum class CondOp : uint8_t {
  True = 0,
  Less,
  LessEqual,
  Greater,
  GreaterEqual,
  Equal,
  NotEqual,
  Bool,
  Trigger,
  Not,
  And,
  Or
};

struct CondInstr {
  CondOp op = CondOp::True;
  uint16_t parameter = 0;
  float value = 0.0f;
};

struct ClipNodeDef {
  uint16_t clip = 0;
  float rate = 1.0f;
  int16_t rate_parameter = -1;
  bool loop = true;
  float start_offset = 0.0f;
};
struct BlendAlphaDef {
  uint16_t a = 0, b = 0;
  uint16_t alpha_parameter = 0;
};
struct SelectDef {
  uint16_t parameter = 0;
  std::vector<uint16_t> children;
  float blend_time = 0.0f;
};
struct MaskEntryDef {
  uint16_t joint = 0;
  int16_t depth = -1;
};
struct LayerDef {
  uint16_t node = 0;
  std::vector<MaskEntryDef> mask;
  float weight = 1.0f;
  int16_t weight_parameter = -1;
  float blend_time = 0.0f;
  bool mesh_space_rotation = false;
  std::optional<std::vector<std::string>> morph_targets;  // absent: what the layer's clips drive
};
struct LayeredDef {
  uint16_t base = 0;
  std::vector<LayerDef> layers;
};
struct BlendSampleDef {
  uint16_t clip = 0;
  float x = 0.0f, y = 0.0f;
};
struct BlendSpaceDef {
  uint16_t x_parameter = 0;
  int16_t y_parameter = -1;  // < 0: 1D
  std::vector<BlendSampleDef> samples;
  float rate = 1.0f;
  bool loop = true;
};
struct AdditiveDef {
  uint16_t base = 0, additive = 0;
  float weight = 1.0f;
  int16_t weight_parameter = -1;
};
struct StateMachineRefDef {
  uint16_t machine = 0;
};
struct MorphDriveDef {
  std::string target;
  uint16_t parameter = 0;
  float scale = 1.0f;
};
struct MorphWeightsDef {
  uint16_t input = 0;
  std::vector<MorphDriveDef> drives;
};

// Procedural nodes (format v6). Lengths in the rig's units, angles in radians (the compiler converts
// the graph file's metres and degrees).
using Vec3Def = std::array<float, 3>;
struct TwoBoneIkDef {
  uint16_t input = 0, start = 0, mid = 0, end = 0;
  uint16_t target_parameter = 0;
  int16_t pole_parameter = -1;
  Vec3Def pole{0.0f, 0.0f, 0.0f};
  Vec3Def mid_axis{0.0f, 0.0f, 1.0f};
  float twist = 0.0f, soften = 1.0f, weight = 1.0f;
  int16_t weight_parameter = -1;
};
struct AimJointDef {
  uint16_t joint = 0;
  float weight = 1.0f, max_angle = 3.14159265f;
};
struct AimDef {
  uint16_t input = 0;
  std::vector<AimJointDef> chain;
  uint16_t target_parameter = 0;
  Vec3Def forward{0.0f, 0.0f, 1.0f}, up{0.0f, 1.0f, 0.0f}, pole{0.0f, 0.0f, 0.0f};
  float weight = 1.0f;
  int16_t weight_parameter = -1;
};
struct FootLegDef {
  uint16_t hip = 0, knee = 0, ankle = 0;
  int16_t ground_parameter = -1, normal_parameter = -1, planted_parameter = -1;
  std::string plant_event, lift_event;
};
struct FootPlacementDef {
  uint16_t input = 0, pelvis = 0;
  std::vector<FootLegDef> legs;
  Vec3Def up{0.0f, 1.0f, 0.0f};
  float max_pelvis_drop = 0.0f, align = 1.0f, soften = 1.0f, weight = 1.0f;
  int16_t weight_parameter = -1;
};
struct FootLockDef {
  uint16_t input = 0;
  std::vector<FootLegDef> legs;
  float release_radius = 0.0f, blend_time = 0.0f, weight = 1.0f;
  int16_t weight_parameter = -1;
};
struct SpringChainDef {
  std::vector<uint16_t> joints;
  float stiffness = 4.0f, drag = 0.4f;
  Vec3Def gravity{0.0f, 0.0f, 0.0f};
  float radius = 0.0f, tail_length = 0.0f;
};
struct SpringColliderDef {
  uint16_t joint = 0;
  Vec3Def offset{0.0f, 0.0f, 0.0f}, tail{0.0f, 0.0f, 0.0f};
  float radius = 0.0f;
};
struct SpringDef {
  uint16_t input = 0;
  std::vector<SpringChainDef> chains;
  std::vector<SpringColliderDef> colliders;
  float step = 1.0f / 120.0f, teleport_distance = 0.0f, weight = 1.0f;
  int16_t weight_parameter = -1;
};

// Montages and the slots they play on (format v9): graph_montage.h compiles them.
struct SlotDef {
  uint16_t input = 0;
  std::string slot, group;
  std::vector<MaskEntryDef> mask;  // empty: every joint
  bool additive = false;
  bool mesh_space_rotation = false;
};

/// Format v10 (fb::RetargetNode): a clip of another humanoid rig, retargeted live.
struct RetargetRestRotationDef {
  uint16_t joint = 0;
  float rotation[4] = {0.0f, 0.0f, 0.0f, 1.0f};  // x y z w
};
struct RetargetNodeDef {
  uint16_t clip = 0;
  uint64_t source_skeleton_hash = 0;
  uint16_t source_joint_count = 0;
  std::vector<int16_t> source_bones, target_bones;  // one per humanoid profile bone, -1: none
  float rate = 1.0f;
  int16_t rate_parameter = -1;
  bool loop = true;
  float start_offset = 0.0f;
  bool contacts = true;
  uint8_t source_rest = 0, target_rest = 0;  // RestPose
  std::vector<RetargetRestRotationDef> source_rest_rotations, target_rest_rotations;
};

using NodeKind = std::variant<ClipNodeDef, BlendAlphaDef, SelectDef, LayeredDef, BlendSpaceDef, AdditiveDef,
                              StateMachineRefDef, MorphWeightsDef, TwoBoneIkDef, AimDef, FootPlacementDef, FootLockDef,
                              SpringDef, SlotDef, RetargetNodeDef>;

struct NodeDef {
  std::string name;
  NodeKind kind;
};

/// Same numbering as fb::TransitionMode.
enum class TransitionModeDef : uint8_t { Crossfade = 0, SyncCrossfade = 1, Inertialize = 2 };

struct StateDef {
  std::string name;
  uint16_t node = 0;
  bool restart = true;
};
struct TransitionDef {
  int16_t from = -1;  // -1: any state
  uint16_t to = 0;
  std::vector<CondInstr> condition;  // RPN; empty = true
  float exit_time = -1.0f;
  float duration = 0.0f;
  TransitionModeDef mode = TransitionModeDef::Crossfade;
};
struct StateMachineDef {
  std::string name;
  std::vector<StateDef> states;
  uint16_t entry = 0;
  std::vector<TransitionDef> transitions;  // priority order
};

/// Same numbering as fb::MontageCurve / fb::MontageNotifyKind.
enum class MontageCurveDef : uint8_t { Linear = 0, Cubic = 1, Inertialize = 2 };
enum class MontageNotifyKindDef : uint8_t { Instant = 0, Window = 1, BranchingPoint = 2 };

struct MontageSegmentDef {
  uint16_t clip = 0;
  float start = 0.0f, end = 0.0f;  // clip seconds
  float rate = 1.0f;
};
struct MontageTrackDef {
  std::string slot;
  std::vector<MontageSegmentDef> segments;
};
struct MontageSectionDef {
  std::string name;
  float start = 0.0f;  // timeline seconds
  int16_t next = -1;   // -1: the montage ends after it
};
struct MontageNotifyDef {
  std::string name;
  float time = 0.0f, duration = 0.0f;
  MontageNotifyKindDef kind = MontageNotifyKindDef::Instant;
};
struct MontageDef {
  std::string name, group;
  std::vector<MontageTrackDef> tracks;
  std::vector<MontageSectionDef> sections;  // by start time
  std::vector<MontageNotifyDef> notifies;   // by time
  float rate = 1.0f;
  float blend_in = 0.0f, blend_out = 0.0f;
  MontageCurveDef blend_in_curve = MontageCurveDef::Linear, blend_out_curve = MontageCurveDef::Linear;
  float blend_out_trigger = -1.0f;
  bool root_motion = false;
};

struct GraphDef {
  std::string name;
  uint64_t skeleton_hash = 0;
  uint16_t joint_count = 0;
  std::vector<GraphParameter> parameters;
  std::vector<std::string> clips;
  std::vector<NodeDef> nodes;  // children first
  std::vector<StateMachineDef> machines;
  uint16_t root = 0;
  std::vector<MontageDef> montages;  // format v9
};

}  // namespace ossa::cook
