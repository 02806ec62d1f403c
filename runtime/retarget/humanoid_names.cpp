// humanoid_names.cpp — finding the humanoid profile in a rig from joint names and the hierarchy
// (humanoid.h, map_humanoid).
//
// A name is cut into words (at separators, case changes and digits: "mixamorig:LeftUpLeg" ->
// left up leg, "DEF-upper_arm.L.001" -> def upper arm l 001, "LHipJoint" -> l hip joint), its side
// read from a left / right / l / r word, words that carry no meaning dropped (def, bip, j, joint,
// base ...) and words that mark a helper remembered (end, nub, twist, ik, pole, ...): a helper is
// chosen only when nothing else fits (Quaternius' Cowboy has only "FootIK.L" for a foot). What is
// left ("upleg", "forearm", "toe") is looked up in a small synonym table per limb bone; among
// several candidates the closest to the root wins (Rigify's "upper_arm.L" over its twist segment
// "upper_arm.L.001"), each chosen below the bone before it (lower arm below upper arm, ...).
//
// The trunk is found by structure, because its names disagree most: the hips are the lowest
// common ancestor of the two upper legs, the neck and head are named (or, for Rigify's numbered
// "spine.004"..."spine.006", the single chain continuing above the arms), and spine / chest /
// upper chest are the joints between the hips and the neck.
#include <ossa/retarget/humanoid.h>

#include <algorithm>
#include <cctype>
#include <string>

namespace ossa {
namespace {

using B = HumanoidBone;

enum class Kind : uint8_t {
  None,
  Shoulder,
  UpperArm,
  LowerArm,
  Hand,
  UpperLeg,
  LowerLeg,
  Foot,
  Toes,
  Neck,
  Head,
  Hips,
  Thumb,
  Index,
  Middle,
  Ring,
  Little,
};

struct Parsed {
  int side = 0;         // 0 none, 1 left, 2 right
  std::string core;     // meaningful words, joined
  bool helper = false;  // end, nub, twist, ik, ...
  bool weak = false;    // a synonym that other rigs use for another part ("hip", "palm")
  Kind kind = Kind::None;
};

bool any_of(const std::string& s, std::initializer_list<const char*> set) {
  for (const char* w : set)
    if (s == w) return true;
  return false;
}

std::vector<std::string> split_words(std::string_view name) {
  const size_t cut = name.find_last_of(":|");
  if (cut != std::string_view::npos) name = name.substr(cut + 1);
  std::vector<std::string> words;
  std::string cur;
  auto flush = [&] {
    if (!cur.empty()) words.push_back(cur);
    cur.clear();
  };
  for (size_t i = 0; i < name.size(); ++i) {
    const auto c = static_cast<unsigned char>(name[i]);
    if (!std::isalnum(c)) {
      flush();
      continue;
    }
    if (!cur.empty()) {
      const auto p = static_cast<unsigned char>(name[i - 1]);
      const bool next_lower = i + 1 < name.size() && std::islower(static_cast<unsigned char>(name[i + 1]));
      if ((std::islower(p) && std::isupper(c)) || (std::isdigit(p) != 0) != (std::isdigit(c) != 0) ||
          (std::isupper(p) && std::isupper(c) && next_lower))
        flush();
    }
    cur += static_cast<char>(std::tolower(c));
  }
  flush();
  // All-lowercase names glue the side on ("lefthand"): split it off.
  std::vector<std::string> out;
  for (std::string& w : words) {
    for (const char* side : {"left", "right"}) {
      const size_t n = std::char_traits<char>::length(side);
      if (w.size() > n && w.compare(0, n, side) == 0 && !std::isdigit(static_cast<unsigned char>(w[n]))) {
        out.emplace_back(side);
        w = w.substr(n);
        break;
      }
    }
    out.push_back(std::move(w));
  }
  return out;
}

Kind finger_kind(const std::vector<std::string>& words) {
  bool thumb = false, index = false, middle = false, ring = false, little = false;
  for (const std::string& w : words) {
    thumb |= w == "thumb";
    index |= w == "index" || w == "pointer";
    middle |= w == "middle";
    ring |= w == "ring";
    little |= w == "pinky" || w == "little" || w == "pinkie";
  }
  if (little) return Kind::Little;  // Pab's "LeftHandRingPinky1" is its little finger
  if (ring) return Kind::Ring;
  if (thumb) return Kind::Thumb;
  if (index) return Kind::Index;
  if (middle) return Kind::Middle;
  return Kind::None;
}

Parsed parse(std::string_view name) {
  Parsed p;
  const std::vector<std::string> all = split_words(name);
  std::vector<std::string> words;
  std::string digits;
  bool after_bip = false;
  for (const std::string& w : all) {
    const bool number = std::isdigit(static_cast<unsigned char>(w[0])) != 0;
    if (number) {
      if (!after_bip) digits = w;  // "Bip01": the 01 is the biped's, not an ordinal
      after_bip = false;
      continue;
    }
    after_bip = w == "bip";
    if (w == "l" || w == "left") p.side = 1;
    else if (w == "r" || w == "right") p.side = 2;
    else if (any_of(w, {"end",        "nub",    "site",   "tip",     "top",        "pole",   "target", "twist",
                        "roll",       "ik",     "ctrl",   "control", "helper",     "offset", "adj",    "sec",
                        "dummy",      "null",   "mch",    "socket",  "attach",     "prop",   "weapon", "bend",
                        "corrective", "jiggle", "breast", "bust",    "metacarpal", "share",  "hair",   "eye"}))
      p.helper = true;
    else if (!any_of(w, {"j", "bip", "def", "org", "mixamorig", "cc", "base", "skeleton", "joint", "jnt", "bone", "c",
                         "armature", "rig", "bn", "b", "f"}))
      words.push_back(w);
  }
  for (const std::string& w : words) p.core += w;
  const std::string& c = p.core;
  // Toes first: Pab's "LeftFootThumb1" is a toe, not a thumb.
  if (c.find("toe") != std::string::npos || c == "ball" ||
      (c.rfind("foot", 0) == 0 && (c.find("thumb") != std::string::npos || c.find("finger") != std::string::npos))) {
    p.kind = Kind::Toes;
    return p;
  }
  const Kind finger = finger_kind(words);
  if (finger != Kind::None) {
    p.kind = finger;
    return p;
  }
  // 3ds Max Biped numbers its fingers: Finger0 thumb ... Finger4 little, Finger12 index's third.
  if (c == "finger" && !digits.empty()) {
    static constexpr Kind kBiped[5] = {Kind::Thumb, Kind::Index, Kind::Middle, Kind::Ring, Kind::Little};
    const int f = digits[0] - '0';
    if (f >= 0 && f < 5) p.kind = kBiped[f];
    return p;
  }
  if (any_of(c, {"shoulder", "clavicle", "collar", "clav", "collarbone"})) p.kind = Kind::Shoulder;
  else if (any_of(c, {"upperarm", "arm", "uparm", "humerus"})) p.kind = Kind::UpperArm;
  else if (any_of(c, {"lowerarm", "forearm", "elbow", "lowarm"})) p.kind = Kind::LowerArm;
  else if (any_of(c, {"hand", "wrist"})) p.kind = Kind::Hand;
  else if (c == "palm") p.kind = Kind::Hand, p.weak = true;
  else if (any_of(c, {"upperleg", "upleg", "thigh", "femur"})) p.kind = Kind::UpperLeg;
  else if (c == "hip" && p.side != 0) p.kind = Kind::UpperLeg, p.weak = true;
  else if (any_of(c, {"lowerleg", "leg", "calf", "shin", "knee", "lowleg"})) p.kind = Kind::LowerLeg;
  else if (any_of(c, {"foot", "ankle"})) p.kind = Kind::Foot;
  else if (c == "neck") p.kind = Kind::Neck;
  else if (c == "head") p.kind = Kind::Head;
  else if (p.side == 0 && any_of(c, {"hips", "hip", "pelvis"})) p.kind = Kind::Hips;
  return p;
}

struct Rig {
  std::span<const int16_t> parents;
  std::vector<Parsed> parsed;
  std::vector<int> depth;
  std::vector<int> children;

  bool below(int ancestor, int joint) const {  // joint is a strict descendant of ancestor
    if (ancestor < 0 || joint < 0) return false;
    for (int j = parents[static_cast<size_t>(joint)]; j >= 0; j = parents[static_cast<size_t>(j)])
      if (j == ancestor) return true;
    return false;
  }

  /// The best joint of this kind and side below `above` (any joint when above < 0), or -1:
  /// non-helpers first, strong synonyms first, then the shallowest, then the first in order.
  int pick(Kind kind, int side, int above, const std::vector<bool>& taken, bool allow_elsewhere = false) const {
    int best = -1;
    auto rank = [&](int j) {
      const Parsed& p = parsed[static_cast<size_t>(j)];
      const bool outside = above >= 0 && !below(above, j);
      return std::make_tuple(outside, p.helper, p.weak, depth[static_cast<size_t>(j)], j);
    };
    for (int j = 0; j < static_cast<int>(parsed.size()); ++j) {
      const Parsed& p = parsed[static_cast<size_t>(j)];
      if (p.kind != kind || p.side != side || taken[static_cast<size_t>(j)]) continue;
      if (above >= 0 && !below(above, j) && !allow_elsewhere) continue;
      if (best < 0 || rank(j) < rank(best)) best = j;
    }
    return best;
  }

  int lca(int a, int b) const {
    for (int x = a; x >= 0; x = parents[static_cast<size_t>(x)])
      if (x == b || below(x, b)) return x;
    return -1;
  }
};

void set(HumanoidMap& map, B bone, int joint, std::vector<bool>& taken) {
  if (joint < 0) return;
  map[bone] = static_cast<int16_t>(joint);
  taken[static_cast<size_t>(joint)] = true;
}

void map_limbs(const Rig& rig, HumanoidMap& map, std::vector<bool>& taken) {
  for (int side = 1; side <= 2; ++side) {
    const bool left = side == 1;
    const int upper_arm = rig.pick(Kind::UpperArm, side, -1, taken);
    set(map, left ? B::LeftUpperArm : B::RightUpperArm, upper_arm, taken);
    const int lower_arm = rig.pick(Kind::LowerArm, side, upper_arm, taken);
    set(map, left ? B::LeftLowerArm : B::RightLowerArm, lower_arm, taken);
    set(map, left ? B::LeftHand : B::RightHand, rig.pick(Kind::Hand, side, lower_arm, taken), taken);
    // A shoulder is an ancestor of the upper arm.
    int shoulder = -1;
    for (int j = upper_arm >= 0 ? rig.parents[static_cast<size_t>(upper_arm)] : -1; j >= 0;
         j = rig.parents[static_cast<size_t>(j)]) {
      const Parsed& p = rig.parsed[static_cast<size_t>(j)];
      if (p.kind == Kind::Shoulder && p.side == side && !taken[static_cast<size_t>(j)]) {
        shoulder = j;
        break;
      }
    }
    set(map, left ? B::LeftShoulder : B::RightShoulder, shoulder, taken);

    const int upper_leg = rig.pick(Kind::UpperLeg, side, -1, taken);
    set(map, left ? B::LeftUpperLeg : B::RightUpperLeg, upper_leg, taken);
    const int lower_leg = rig.pick(Kind::LowerLeg, side, upper_leg, taken);
    set(map, left ? B::LeftLowerLeg : B::RightLowerLeg, lower_leg, taken);
    // Feet below the lower leg first; an IK rig's foot may hang from the root.
    const int foot = lower_leg >= 0 ? rig.pick(Kind::Foot, side, lower_leg, taken, true) : -1;
    set(map, left ? B::LeftFoot : B::RightFoot, foot, taken);
    set(map, left ? B::LeftToes : B::RightToes, foot >= 0 ? rig.pick(Kind::Toes, side, foot, taken) : -1, taken);
  }
}

void map_fingers(const Rig& rig, HumanoidMap& map, std::vector<bool>& taken) {
  static constexpr Kind kFingers[5] = {Kind::Thumb, Kind::Index, Kind::Middle, Kind::Ring, Kind::Little};
  for (int side = 1; side <= 2; ++side) {
    const int hand = map[side == 1 ? B::LeftHand : B::RightHand];
    if (hand < 0) continue;
    const auto first = static_cast<size_t>(side == 1 ? B::LeftThumbMetacarpal : B::RightThumbMetacarpal);
    for (size_t f = 0; f < 5; ++f) {
      int above = hand;
      for (size_t k = 0; k < 3; ++k) {
        int j = -1;
        for (int c = 0; c < static_cast<int>(rig.parsed.size()); ++c) {
          const Parsed& p = rig.parsed[static_cast<size_t>(c)];
          if (p.kind != kFingers[f] || p.side != side || p.helper || taken[static_cast<size_t>(c)] ||
              !rig.below(above, c))
            continue;
          if (j < 0 || rig.depth[static_cast<size_t>(c)] < rig.depth[static_cast<size_t>(j)]) j = c;
        }
        if (j < 0) break;
        set(map, static_cast<B>(first + f * 3 + k), j, taken);
        above = j;
      }
    }
  }
}

void map_trunk(const Rig& rig, HumanoidMap& map, std::vector<bool>& taken) {
  const int legs = rig.lca(map[B::LeftUpperLeg], map[B::RightUpperLeg]);
  int hips = legs >= 0 && legs != map[B::LeftUpperLeg] && legs != map[B::RightUpperLeg] ? legs : -1;
  if (hips < 0) hips = rig.pick(Kind::Hips, 0, -1, taken);
  if (hips < 0) return;
  set(map, B::Hips, hips, taken);
  int neck = rig.pick(Kind::Neck, 0, hips, taken);
  int head = rig.pick(Kind::Head, 0, neck >= 0 ? neck : hips, taken);
  if (head < 0) {
    // No joint is called head (Rigify's spine.004 ... spine.006): the chain continuing above the
    // joint the arms hang from, up to where it ends or branches (the face).
    const int chest = rig.lca(map[B::LeftUpperArm], map[B::RightUpperArm]);
    if (chest >= 0 && (chest == hips || rig.below(hips, chest))) {
      int next = -1, best = -1;
      for (int c = chest + 1; c < static_cast<int>(rig.parsed.size()); ++c) {
        if (rig.parents[static_cast<size_t>(c)] != chest || rig.parsed[static_cast<size_t>(c)].helper) continue;
        if (rig.below(c, map[B::LeftUpperArm]) || rig.below(c, map[B::RightUpperArm])) continue;
        if (rig.parsed[static_cast<size_t>(c)].kind != Kind::None &&
            rig.parsed[static_cast<size_t>(c)].kind != Kind::Neck)
          continue;
        if (best < 0 || rig.children[static_cast<size_t>(c)] > best)
          best = rig.children[static_cast<size_t>(c)], next = c;
      }
      int chain = next, first = next;
      while (chain >= 0) {
        int only = -1, count = 0;
        for (int c = chain + 1; c < static_cast<int>(rig.parsed.size()); ++c)
          if (rig.parents[static_cast<size_t>(c)] == chain && !rig.parsed[static_cast<size_t>(c)].helper)
            ++count, only = c;
        if (count != 1) break;
        chain = only;
      }
      if (chain >= 0 && !taken[static_cast<size_t>(chain)]) {
        head = chain;
        if (neck < 0 && first != chain) neck = first;
      }
    }
  }
  if (head < 0) return;
  if (neck >= 0 && !rig.below(neck, head)) neck = -1;
  set(map, B::Neck, neck, taken);
  set(map, B::Head, head, taken);
  // Spine, chest, upper chest: the joints strictly between the hips and the neck (or head).
  std::vector<int> path;
  for (int j = rig.parents[static_cast<size_t>(neck >= 0 ? neck : head)]; j >= 0 && j != hips;
       j = rig.parents[static_cast<size_t>(j)])
    path.insert(path.begin(), j);
  if (path.empty() || rig.parents[static_cast<size_t>(path.front())] != hips) return;
  set(map, B::Spine, path[0], taken);
  if (path.size() >= 2) set(map, B::Chest, path[1], taken);
  if (path.size() >= 3) set(map, B::UpperChest, path.back(), taken);
}

}  // namespace

HumanoidMap map_humanoid(std::span<const std::string_view> names, std::span<const int16_t> parents) {
  HumanoidMap map;
  const size_t n = std::min(names.size(), parents.size());
  Rig rig;
  rig.parents = parents.first(n);
  rig.parsed.resize(n);
  rig.depth.assign(n, 0);
  rig.children.assign(n, 0);
  for (size_t j = 0; j < n; ++j) {
    const int p = parents[j];
    if (p >= static_cast<int>(j) || p < -1) return map;  // not parents-first: nothing is safe to infer
    rig.parsed[j] = parse(names[j]);
    rig.depth[j] = p >= 0 ? rig.depth[static_cast<size_t>(p)] + 1 : 0;
  }
  for (size_t j = n; j-- > 0;) {
    const int p = parents[j];
    if (p >= 0) rig.children[static_cast<size_t>(p)] += rig.children[j] + 1;
  }
  std::vector<bool> taken(n, false);
  map_limbs(rig, map, taken);
  map_trunk(rig, map, taken);
  map_fingers(rig, map, taken);
  return map;
}

HumanoidMap map_humanoid(const SkeletonView& skeleton) {
  if (skeleton.empty()) return {};
  std::vector<std::string_view> names(skeleton.joint_count());
  for (size_t j = 0; j < names.size(); ++j) names[j] = skeleton.joint_name(j);
  return map_humanoid(names, skeleton.parents());
}

}  // namespace ossa
