// retarget_fixture.cpp — synthetic humanoid rigs (retarget_fixture.h).
#include "retarget_fixture.h"

#include <cmath>
#include <random>

#include <ossa/anim/pose_ops.h>

namespace ossa::test {
namespace {

using B = HumanoidBone;

/// The right side's bone for a left one: right bones follow left ones at a fixed distance within
/// each group of the profile.
B right_of(B left) {
  const auto l = static_cast<int>(left);
  if (left >= B::LeftShoulder && left <= B::LeftHand) return static_cast<B>(l + 4);
  if (left >= B::LeftUpperLeg && left <= B::LeftToes) return static_cast<B>(l + 4);
  if (left >= B::LeftThumbMetacarpal && left <= B::LeftLittleDistal) return static_cast<B>(l + 15);
  return left;
}

/// Fills `expected` with every named slot's profile bone (the trunk by its structural meaning).
void expect_slots(HumanoidNames& n) {
  auto put = [&](B b, const std::string& name) {
    if (!name.empty()) n.expected.emplace_back(b, name);
  };
  put(B::Head, n.head);
  put(B::Neck, n.neck);
  for (int s = 0; s < 2; ++s) {
    auto b = [&](B left) { return s == 0 ? left : right_of(left); };
    put(b(B::LeftShoulder), n.shoulder[s]);
    put(b(B::LeftUpperArm), n.upper_arm[s]);
    put(b(B::LeftLowerArm), n.lower_arm[s]);
    put(b(B::LeftHand), n.hand[s]);
    put(b(B::LeftUpperLeg), n.upper_leg[s]);
    put(b(B::LeftLowerLeg), n.lower_leg[s]);
    put(b(B::LeftFoot), n.foot[s]);
    put(b(B::LeftToes), n.toes[s]);
    for (size_t f = 0; f < 5; ++f)
      for (size_t k = 0; k < 3; ++k)
        put(b(static_cast<B>(static_cast<size_t>(B::LeftThumbMetacarpal) + f * 3 + k)), n.fingers[s][f][k]);
  }
}

/// Fingers named by a pattern: `{finger}`, `{n}` (1-based segment) and `{side}` replaced.
void name_fingers(HumanoidNames& n, const std::array<std::string, 5>& fingers, const std::array<std::string, 2>& sides,
                  const std::string& pattern, int first = 1) {
  for (size_t s = 0; s < 2; ++s)
    for (size_t f = 0; f < 5; ++f)
      for (size_t k = 0; k < 3; ++k) {
        std::string name = pattern;
        for (const auto& [key, value] : {std::pair<std::string, std::string>{"{finger}", fingers[f]},
                                         {"{n}", std::to_string(static_cast<int>(k) + first)},
                                         {"{side}", sides[s]}}) {
          for (size_t at = name.find(key); at != std::string::npos; at = name.find(key))
            name.replace(at, key.size(), value);
        }
        n.fingers[s][f][k] = name;
      }
}

}  // namespace

HumanoidNames mixamo_names() {
  HumanoidNames n;
  n.convention = "Mixamo";
  n.hips = "mixamorig:Hips";
  n.spine = {"mixamorig:Spine", "mixamorig:Spine1", "mixamorig:Spine2"};
  n.neck = "mixamorig:Neck";
  n.head = "mixamorig:Head";
  n.head_end = "mixamorig:HeadTop_End";
  const std::array<std::string, 2> side{"Left", "Right"};
  for (size_t s = 0; s < 2; ++s) {
    const std::string p = "mixamorig:" + side[s];
    n.shoulder[s] = p + "Shoulder";
    n.upper_arm[s] = p + "Arm";
    n.lower_arm[s] = p + "ForeArm";
    n.hand[s] = p + "Hand";
    n.upper_leg[s] = p + "UpLeg";
    n.lower_leg[s] = p + "Leg";
    n.foot[s] = p + "Foot";
    n.toes[s] = p + "ToeBase";
    n.extras.emplace_back(p + "Toe_End", n.toes[s]);
    n.extras.emplace_back(p + "HandThumb4", p + "HandThumb3");
  }
  name_fingers(n, {"Thumb", "Index", "Middle", "Ring", "Pinky"}, {"Left", "Right"}, "mixamorig:{side}Hand{finger}{n}");
  expect_slots(n);
  n.expected.emplace_back(B::Hips, n.hips);
  n.expected.emplace_back(B::Spine, "mixamorig:Spine");
  n.expected.emplace_back(B::Chest, "mixamorig:Spine1");
  n.expected.emplace_back(B::UpperChest, "mixamorig:Spine2");
  return n;
}

HumanoidNames unreal_names() {
  HumanoidNames n;
  n.convention = "Unreal mannequin";
  n.root = "root";
  n.hips = "pelvis";
  n.spine = {"spine_01", "spine_02", "spine_03"};
  n.neck = "neck_01";
  n.head = "head";
  const std::array<std::string, 2> s{"l", "r"};
  for (size_t i = 0; i < 2; ++i) {
    n.shoulder[i] = "clavicle_" + s[i];
    n.upper_arm[i] = "upperarm_" + s[i];
    n.lower_arm[i] = "lowerarm_" + s[i];
    n.hand[i] = "hand_" + s[i];
    n.upper_leg[i] = "thigh_" + s[i];
    n.lower_leg[i] = "calf_" + s[i];
    n.foot[i] = "foot_" + s[i];
    n.toes[i] = "ball_" + s[i];
    n.extras.emplace_back("upperarm_twist_01_" + s[i], n.upper_arm[i]);
    n.extras.emplace_back("lowerarm_twist_01_" + s[i], n.lower_arm[i]);
    n.extras.emplace_back("calf_twist_01_" + s[i], n.lower_leg[i]);
    n.extras.emplace_back("thigh_twist_01_" + s[i], n.upper_leg[i]);
    n.extras.emplace_back("ik_foot_" + s[i], "root");
    n.extras.emplace_back("ik_hand_" + s[i], "root");
  }
  name_fingers(n, {"thumb", "index", "middle", "ring", "pinky"}, {"l", "r"}, "{finger}_0{n}_{side}");
  expect_slots(n);
  n.expected.emplace_back(B::Hips, "pelvis");
  n.expected.emplace_back(B::Spine, "spine_01");
  return n;
}

HumanoidNames unity_names() {
  HumanoidNames n;
  n.convention = "Unity";
  n.hips = "Hips";
  n.spine = {"Spine", "Chest", "UpperChest"};
  n.neck = "Neck";
  n.head = "Head";
  const std::array<std::string, 2> side{"Left", "Right"};
  for (size_t s = 0; s < 2; ++s) {
    n.shoulder[s] = side[s] + "Shoulder";
    n.upper_arm[s] = side[s] + "UpperArm";
    n.lower_arm[s] = side[s] + "LowerArm";
    n.hand[s] = side[s] + "Hand";
    n.upper_leg[s] = side[s] + "UpperLeg";
    n.lower_leg[s] = side[s] + "LowerLeg";
    n.foot[s] = side[s] + "Foot";
    n.toes[s] = side[s] + "Toes";
    const std::array<std::string, 5> f{"Thumb", "Index", "Middle", "Ring", "Little"};
    const std::array<std::string, 3> seg{"Proximal", "Intermediate", "Distal"};
    for (size_t i = 0; i < 5; ++i)
      for (size_t k = 0; k < 3; ++k) n.fingers[s][i][k] = side[s] + f[i] + seg[k];
  }
  expect_slots(n);
  n.expected.emplace_back(B::Hips, "Hips");
  n.expected.emplace_back(B::Chest, "Chest");
  n.expected.emplace_back(B::UpperChest, "UpperChest");
  return n;
}

HumanoidNames vroid_names() {
  HumanoidNames n;
  n.convention = "VRoid";
  n.root = "Root";
  n.hips = "J_Bip_C_Hips";
  n.spine = {"J_Bip_C_Spine", "J_Bip_C_Chest", "J_Bip_C_UpperChest"};
  n.neck = "J_Bip_C_Neck";
  n.head = "J_Bip_C_Head";
  const std::array<std::string, 2> s{"L", "R"};
  for (size_t i = 0; i < 2; ++i) {
    const std::string p = "J_Bip_" + s[i] + "_";
    n.shoulder[i] = p + "Shoulder";
    n.upper_arm[i] = p + "UpperArm";
    n.lower_arm[i] = p + "LowerArm";
    n.hand[i] = p + "Hand";
    n.upper_leg[i] = p + "UpperLeg";
    n.lower_leg[i] = p + "LowerLeg";
    n.foot[i] = p + "Foot";
    n.toes[i] = p + "ToeBase";
    n.extras.emplace_back("J_Sec_" + s[i] + "_Bust1", "J_Bip_C_UpperChest");
    n.extras.emplace_back("J_Adj_" + s[i] + "_FaceEye", "J_Bip_C_Head");
  }
  name_fingers(n, {"Thumb", "Index", "Middle", "Ring", "Little"}, {"L", "R"}, "J_Bip_{side}_{finger}{n}");
  expect_slots(n);
  n.expected.emplace_back(B::Hips, n.hips);
  return n;
}

HumanoidNames rigify_names() {
  HumanoidNames n;
  n.convention = "Rigify";
  n.root = "root";
  n.hips = "DEF-spine";
  n.spine = {"DEF-spine.001", "DEF-spine.002", "DEF-spine.003"};
  n.neck = "DEF-spine.004";
  n.head = "DEF-spine.006";
  const std::array<std::string, 2> s{".L", ".R"};
  for (size_t i = 0; i < 2; ++i) {
    n.shoulder[i] = "DEF-shoulder" + s[i];
    n.upper_arm[i] = "DEF-upper_arm" + s[i];
    n.lower_arm[i] = "DEF-forearm" + s[i];
    n.hand[i] = "DEF-hand" + s[i];
    n.upper_leg[i] = "DEF-thigh" + s[i];
    n.lower_leg[i] = "DEF-shin" + s[i];
    n.foot[i] = "DEF-foot" + s[i];
    n.toes[i] = "DEF-toe" + s[i];
    n.extras.emplace_back("DEF-upper_arm" + s[i] + ".001", n.upper_arm[i]);  // its twist segment
    n.extras.emplace_back("DEF-thigh" + s[i] + ".001", n.upper_leg[i]);
  }
  name_fingers(n, {"thumb", "f_index", "f_middle", "f_ring", "f_pinky"}, {".L", ".R"}, "DEF-{finger}.0{n}{side}");
  n.neck2 = "DEF-spine.005";
  expect_slots(n);
  n.expected.emplace_back(B::Hips, n.hips);
  return n;
}

HumanoidNames metarig_names() {
  HumanoidNames n = rigify_names();
  n.convention = "metarig";
  auto strip = [](std::string& s) {
    if (s.rfind("DEF-", 0) == 0) s = s.substr(4);
  };
  for (std::string* s : {&n.root, &n.hips, &n.neck, &n.head}) strip(*s);
  n.root.clear();
  for (std::string& s : n.spine) strip(s);
  for (auto* arr : {&n.shoulder, &n.upper_arm, &n.lower_arm, &n.hand, &n.upper_leg, &n.lower_leg, &n.foot, &n.toes})
    for (std::string& s : *arr) strip(s);
  for (auto& side : n.fingers)
    for (auto& f : side)
      for (std::string& s : f) strip(s);
  strip(n.neck2);
  n.extras.clear();
  n.extras.emplace_back("heel.02.L", "foot.L");
  n.extras.emplace_back("heel.02.R", "foot.R");
  n.expected.clear();
  expect_slots(n);
  n.expected.emplace_back(B::Hips, "spine");
  return n;
}

HumanoidNames cmu_names() {
  HumanoidNames n;
  n.convention = "CMU BVH";
  n.hips = "Hips";
  n.spine = {"LowerBack", "Spine", "Spine1"};
  n.neck = "Neck";
  n.head = "Head";
  n.head_end = "EndSite_Head";
  const std::array<std::string, 2> side{"Left", "Right"}, s{"L", "R"};
  for (size_t i = 0; i < 2; ++i) {
    n.hip_joint[i] = s[i] + "HipJoint";
    n.shoulder[i] = side[i] + "Shoulder";
    n.upper_arm[i] = side[i] + "Arm";
    n.lower_arm[i] = side[i] + "ForeArm";
    n.hand[i] = side[i] + "Hand";
    n.upper_leg[i] = side[i] + "UpLeg";
    n.lower_leg[i] = side[i] + "Leg";
    n.foot[i] = side[i] + "Foot";
    n.toes[i] = side[i] + "ToeBase";
    n.fingers[i][0][0] = s[i] + "Thumb";
    n.extras.emplace_back(side[i] + "FingerBase", n.hand[i]);
    n.extras.emplace_back(s[i] + "Fingers", side[i] + "FingerBase");
    n.extras.emplace_back("EndSite_" + s[i] + "Thumb", n.fingers[i][0][0]);
  }
  n.neck2 = "Neck1";
  expect_slots(n);
  n.expected.emplace_back(B::Hips, "Hips");
  n.expected.emplace_back(B::Spine, "LowerBack");
  return n;
}

HumanoidNames biped_names() {
  HumanoidNames n;
  n.convention = "3ds Max Biped";
  n.root = "Bip01";
  n.hips = "Bip01 Pelvis";
  n.spine = {"Bip01 Spine", "Bip01 Spine1", "Bip01 Spine2"};
  n.neck = "Bip01 Neck";
  n.head = "Bip01 Head";
  n.head_end = "Bip01 HeadNub";
  const std::array<std::string, 2> s{"L", "R"};
  for (size_t i = 0; i < 2; ++i) {
    const std::string p = "Bip01 " + s[i] + " ";
    n.shoulder[i] = p + "Clavicle";
    n.upper_arm[i] = p + "UpperArm";
    n.lower_arm[i] = p + "Forearm";
    n.hand[i] = p + "Hand";
    n.upper_leg[i] = p + "Thigh";
    n.lower_leg[i] = p + "Calf";
    n.foot[i] = p + "Foot";
    n.toes[i] = p + "Toe0";
    for (size_t f = 0; f < 5; ++f)
      for (size_t k = 0; k < 3; ++k)
        n.fingers[i][f][k] = p + "Finger" + std::to_string(f) + (k == 0 ? std::string() : std::to_string(k));
    n.extras.emplace_back(p + "Toe0Nub", n.toes[i]);
    n.extras.emplace_back(p + "Finger0Nub", n.fingers[i][0][2]);
  }
  expect_slots(n);
  n.expected.emplace_back(B::Hips, "Bip01 Pelvis");
  return n;
}

HumanoidNames quaternius_names() {
  HumanoidNames n;
  n.convention = "Quaternius";
  n.root = "Bone";
  n.hips = "Body";
  n.spine = {"Hips", "Abdomen", "Torso"};  // Quaternius' "Hips" is its lower spine
  n.neck = "Neck";
  n.head = "Head";
  n.head_end = "Head_end";
  const std::array<std::string, 2> s{".L", ".R"};
  for (size_t i = 0; i < 2; ++i) {
    n.shoulder[i] = "Shoulder" + s[i];
    n.upper_arm[i] = "UpperArm" + s[i];
    n.lower_arm[i] = "LowerArm" + s[i];
    n.hand[i] = "Palm" + s[i];
    n.upper_leg[i] = "UpperLeg" + s[i];
    n.lower_leg[i] = "LowerLeg" + s[i];
    n.foot[i] = "Foot" + s[i];
    n.fingers[i][0] = {"Thumb1" + s[i], "Thumb2" + s[i], "Thumb3" + s[i]};
    n.fingers[i][1] = {"Index1" + s[i], "Index2" + s[i], "Index3" + s[i]};
    n.fingers[i][4] = {"PinkyFinger1" + s[i], "PinkyFinger2" + s[i], "PinkyFinger3" + s[i]};
    n.extras.emplace_back("LowerLeg" + s[i] + "_end", n.lower_leg[i]);
    n.extras.emplace_back("Foot" + s[i] + "_end", n.foot[i]);
    n.extras.emplace_back("PoleTarget" + s[i], "Bone");
  }
  expect_slots(n);
  n.expected.emplace_back(B::Hips, "Body");
  n.expected.emplace_back(B::Spine, "Hips");
  return n;
}

int SyntheticRig::joint(const std::string& name) const {
  const auto it = index.find(name);
  return it == index.end() ? -1 : it->second;
}

RetargetRig SyntheticRig::rig(std::string_view name) const {
  RetargetRig r;
  r.name = name;
  r.parents = parents;
  r.bind = bind;
  r.names = views;
  r.humanoid = map_humanoid(views, parents);
  return r;
}

SyntheticRig make_humanoid(const HumanoidNames& n, const RigShape& shape) {
  struct J {
    std::string name;
    int parent;
    glm::vec3 pos;
  };
  std::vector<J> js;
  std::map<std::string, int> at;
  auto add = [&](const std::string& name, int parent, glm::vec3 pos) {
    if (name.empty()) return parent;
    js.push_back({name, parent, pos});
    at[name] = static_cast<int>(js.size()) - 1;
    return static_cast<int>(js.size()) - 1;
  };
  const float hips_y = 0.08f + shape.shin + shape.thigh + 0.05f;
  const int root = add(n.root, -1, glm::vec3(0.0f));
  const int hips = add(n.hips, root, {0.0f, hips_y, 0.0f});
  int chest = hips;
  for (size_t k = 0; k < n.spine.size(); ++k) {
    const float u = n.spine.size() == 1 ? 0.5f : static_cast<float>(k) / static_cast<float>(n.spine.size() - 1);
    chest = add(n.spine[k], chest, {0.0f, hips_y + 0.1f + 0.35f * u, -0.01f});
  }
  const int neck = add(n.neck, chest, {0.0f, hips_y + 0.5f, 0.0f});
  const int neck2 = add(n.neck2, neck, {0.0f, hips_y + 0.56f, 0.01f});
  const int head = add(n.head, neck2, {0.0f, hips_y + 0.62f, 0.02f});
  add(n.head_end, head, {0.0f, hips_y + 0.82f, 0.02f});
  const float a = glm::radians(shape.arm_down_degrees);
  for (int s = 0; s < 2; ++s) {
    const float x = s == 0 ? 1.0f : -1.0f;
    const int hip_joint =
        add(n.hip_joint[static_cast<size_t>(s)], hips, {x * shape.hip_width * 0.5f, hips_y - 0.03f, 0.0f});
    const int upper_leg =
        add(n.upper_leg[static_cast<size_t>(s)], hip_joint, {x * shape.hip_width, hips_y - 0.05f, 0.0f});
    const int lower_leg =
        add(n.lower_leg[static_cast<size_t>(s)], upper_leg, {x * shape.hip_width, hips_y - 0.05f - shape.thigh, 0.01f});
    const int foot =
        add(n.foot[static_cast<size_t>(s)], shape.ik_feet ? root : lower_leg, {x * shape.hip_width, 0.08f, 0.0f});
    add(n.toes[static_cast<size_t>(s)], foot, {x * shape.hip_width, 0.02f, 0.12f});
    const glm::vec3 d(x * std::cos(a), -std::sin(a), 0.0f);
    const int shoulder = add(n.shoulder[static_cast<size_t>(s)], chest, {x * 0.03f, hips_y + 0.45f, 0.0f});
    const glm::vec3 ua(x * shape.shoulder_width, hips_y + 0.45f, -0.01f);
    const int upper_arm = add(n.upper_arm[static_cast<size_t>(s)], shoulder, ua);
    const int lower_arm = add(n.lower_arm[static_cast<size_t>(s)], upper_arm, ua + d * shape.upper_arm);
    const glm::vec3 wrist = ua + d * (shape.upper_arm + shape.forearm);
    const int hand = add(n.hand[static_cast<size_t>(s)], lower_arm, wrist);
    for (size_t f = 0; f < 5; ++f) {
      glm::vec3 p = wrist + d * (f == 0 ? 0.03f : 0.09f) +
                    glm::vec3(0.0f, f == 0 ? -0.01f : 0.0f, 0.04f - 0.02f * static_cast<float>(f));
      int parent = hand;
      for (size_t k = 0; k < 3; ++k) {
        parent = add(n.fingers[static_cast<size_t>(s)][f][k], parent, p);
        p += d * (0.04f - 0.005f * static_cast<float>(k));
      }
    }
  }
  for (const auto& [name, parent] : n.extras) {
    const auto it = at.find(parent);
    const int p = it == at.end() ? root : it->second;
    add(name, p, (p >= 0 ? js[static_cast<size_t>(p)].pos : glm::vec3(0.0f)) + glm::vec3(0.0f, 0.01f, 0.01f));
  }

  SyntheticRig rig;
  std::mt19937 random(shape.frame_seed);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  std::vector<glm::quat> frame(js.size());
  for (size_t j = 0; j < js.size(); ++j) {
    glm::quat q(1.0f, 0.0f, 0.0f, 0.0f);
    if (shape.frame_seed != 0) q = glm::normalize(glm::quat(unit(random), unit(random), unit(random), unit(random)));
    frame[j] = shape.orientation * q;
  }
  for (size_t j = 0; j < js.size(); ++j) {
    const glm::vec3 p = shape.orientation * js[j].pos * shape.units_per_metre;
    const int parent = js[j].parent;
    Transform t;
    if (parent < 0) {
      t.rotation = frame[j];
      t.translation = p;
    } else {
      const glm::vec3 pp = shape.orientation * js[static_cast<size_t>(parent)].pos * shape.units_per_metre;
      t.rotation = glm::normalize(glm::inverse(frame[static_cast<size_t>(parent)]) * frame[j]);
      t.translation = glm::inverse(frame[static_cast<size_t>(parent)]) * (p - pp);
    }
    rig.names.push_back(js[j].name);
    rig.parents.push_back(static_cast<int16_t>(parent));
    rig.bind.push_back(t);
  }
  for (size_t j = 0; j < rig.names.size(); ++j) {
    rig.index[rig.names[j]] = static_cast<int>(j);
  }
  for (const std::string& name : rig.names) rig.views.emplace_back(name);
  if (shape.ik_feet) {
    Pose bind(static_cast<uint32_t>(rig.names.size()));
    bind_pose(rig, bind);
    std::vector<glm::mat4> model(rig.names.size());
    local_to_model(rig.parents, bind, model);
    for (size_t s = 0; s < 2; ++s) {
      const int foot = rig.joint(n.foot[s]), shin = rig.joint(n.lower_leg[s]);
      if (foot < 0 || shin < 0) continue;
      const glm::vec3 offset(glm::inverse(model[static_cast<size_t>(shin)]) * model[static_cast<size_t>(foot)][3]);
      rig.ik_feet.push_back({{foot, shin}, offset});
    }
  }
  return rig;
}

void bind_pose(const SyntheticRig& rig, PoseSpan out) {
  for (size_t j = 0; j < rig.bind.size(); ++j) set_transform(out, static_cast<uint32_t>(j), rig.bind[j]);
}

void synthetic_motion(const SyntheticRig& rig, uint32_t frame, float degrees, PoseSpan out) {
  const float t = static_cast<float>(frame) / 30.0f;
  for (size_t j = 0; j < rig.bind.size(); ++j) {
    Transform x = rig.bind[j];
    const float fj = static_cast<float>(j);
    const glm::vec3 axis =
        glm::normalize(glm::vec3(std::sin(fj * 1.3f), std::cos(fj * 0.7f), std::sin(fj * 2.1f) + 0.5f));
    const float angle = glm::radians(degrees) * std::sin(6.2831853f * (0.7f * t + 0.13f * fj));
    x.rotation = glm::normalize(x.rotation * glm::angleAxis(angle, axis));
    if (rig.parents[j] < 0) x.translation += glm::vec3(0.0f, 0.0f, 0.02f * t);  // travels
    set_transform(out, static_cast<uint32_t>(j), x);
  }
  if (rig.ik_feet.empty()) return;
  std::vector<glm::mat4> model(rig.names.size());
  local_to_model(rig.parents, out, model);
  for (const auto& [joints, offset] : rig.ik_feet) {
    const auto [foot, shin] = joints;
    const int parent = rig.parents[static_cast<size_t>(foot)];
    const glm::vec4 at = model[static_cast<size_t>(shin)] * glm::vec4(offset, 1.0f);
    Transform x = get_transform(out, static_cast<uint32_t>(foot));
    x.translation = glm::vec3(parent >= 0 ? glm::inverse(model[static_cast<size_t>(parent)]) * at : at);
    set_transform(out, static_cast<uint32_t>(foot), x);
  }
}

}  // namespace ossa::test
