// validate_graph.cpp — the semantic checks of a cooked animation graph (validate.h), so that the
// evaluator (graph_eval.cpp, graph_machine.cpp) can index without a single check.
//
// What the evaluator relies on, proven here: parameter, clip, joint, node, machine and state
// indices in range; each node kind's parameters of a type that means something there; the node
// tree stored children first (a child index below its parent's), every node with at most one
// referrer (a parent or a state) and the root with none, so per-node state is never advanced
// twice in a frame; the tree at most kMaxGraphDepth deep (the evaluator recurses); each machine
// played by exactly one node; conditions in reverse Polish form that never underflow or exceed 16
// entries and leave one value; finite numbers; 1D blend-space samples strictly increasing. Clip
// names are resolved, and 2D blend spaces triangulated, when a GraphDefinition is made.
#include <cmath>
#include <string>
#include <vector>

#include "common/message.h"
#include "internal/validate_montage.h"
#include "internal/retarget_bones.h"
#include <ossa/loader/validate.h>

namespace ossa {
namespace {

using detail::format;

class GraphChecker {
 public:
  GraphChecker(const fb::Graph& g, size_t index, std::string_view name, uint64_t& budget) : g_(g), budget_(budget) {
    where_ = std::string(name) + ": " + format("graph %zu", index);
    if (!flatbuffers::GetStringView(g.name()).empty())
      where_ += " '" + detail::printable(flatbuffers::GetStringView(g.name())) + "'";
  }

  Status run() {
    param_count_ = g_.parameters()->size();
    clip_count_ = g_.clips()->size();
    node_count_ = g_.nodes()->size();
    machine_count_ = g_.machines() ? g_.machines()->size() : 0;
    if (!spend(uint64_t(param_count_) * 16 + uint64_t(clip_count_) * 4 + uint64_t(node_count_) * 16 +
               uint64_t(machine_count_) * 16))
      return over_budget();
    if (node_count_ == 0) return fail("has no nodes");
    if (node_count_ > 65535) return fail(format("has %zu nodes, more than 65535", node_count_));
    if (g_.root() >= node_count_) return fail(format("root %u is not a node (%zu nodes)", g_.root(), node_count_));
    for (size_t i = 0; i < param_count_; ++i)
      if (Status st = check_parameter(i); !st) return st;
    for (size_t i = 0; i < clip_count_; ++i)
      if (flatbuffers::GetStringView(g_.clips()->Get(static_cast<flatbuffers::uoffset_t>(i))).empty())
        return fail(format("clip %zu has an empty name", i));
    referrers_.assign(node_count_, 0);
    // Clips played by retarget nodes are bound to another rig: no other node or montage may play
    // them on the graph's (their indices are checked with each node).
    retarget_clip_.assign(clip_count_, 0);
    for (const fb::Node* node : *g_.nodes())
      if (const fb::RetargetNode* r = node->data_as_RetargetNode(); r != nullptr && r->clip() < clip_count_)
        retarget_clip_[r->clip()] = 1;
    depth_.assign(node_count_, 1);
    machine_player_.assign(machine_count_, -1);
    for (size_t i = 0; i < node_count_; ++i)
      if (Status st = check_node(i); !st) return st;
    if (referrers_[g_.root()] != 0) return fail(format("root node %u is also used inside the graph", g_.root()));
    for (size_t m = 0; m < machine_count_; ++m) {
      if (machine_player_[m] < 0) return fail(format("state machine %zu is not played by any node", m));
      if (Status st = check_machine(m); !st) return st;
    }
    bool over = false;
    if (const std::string e = detail::check_montages(g_, budget_, &over); over) return over_budget();
    else if (!e.empty()) return fail(e);
    if (const auto* montages = g_.montages())
      for (flatbuffers::uoffset_t m = 0; m < montages->size(); ++m)
        for (const fb::MontageTrack* track : *montages->Get(m)->tracks())
          for (const fb::MontageSegment* seg : *track->segments())
            if (retarget_clip_[seg->clip()])
              return fail(
                  format("montage %u: clip %u is played by a retarget node (bound to another rig)", m, seg->clip()));
    return {};
  }

 private:
  Error fail(const std::string& what) const { return Error{where_ + ": " + what}; }
  Error over_budget() const {
    return fail(
        "tables reference far more data than the file holds (vectors shared between tables); refusing to scan it");
  }
  bool spend(uint64_t bytes) {
    if (bytes > budget_) return false;
    budget_ -= bytes;
    return true;
  }

  fb::ParameterType type_of(size_t p) const {
    return g_.parameters()->Get(static_cast<flatbuffers::uoffset_t>(p))->type();
  }
  std::string param_label(size_t p) const {
    return format("parameter %zu '%s'", p,
                  detail::printable(
                      flatbuffers::GetStringView(g_.parameters()->Get(static_cast<flatbuffers::uoffset_t>(p))->name()))
                      .c_str());
  }

  /// A parameter reference of one of the allowed types (optional: -1 allowed).
  Status check_param_ref(const std::string& at, int p, bool optional, std::initializer_list<fb::ParameterType> types) {
    if (p < 0 && optional) return {};
    if (p < 0 || static_cast<size_t>(p) >= param_count_)
      return fail(at + format(": parameter %d is out of range (%zu parameters)", p, param_count_));
    const fb::ParameterType t = type_of(static_cast<size_t>(p));
    for (fb::ParameterType allowed : types)
      if (t == allowed) return {};
    return fail(at + ": " + param_label(static_cast<size_t>(p)) + " has type " + fb::EnumNameParameterType(t) +
                ", which cannot be used here");
  }

  Status check_parameter(size_t i) {
    const fb::Parameter& p = *g_.parameters()->Get(static_cast<flatbuffers::uoffset_t>(i));
    const std::string at = param_label(i);
    if (flatbuffers::GetStringView(p.name()).empty()) return fail(format("parameter %zu has an empty name", i));
    if (static_cast<unsigned>(p.type()) > static_cast<unsigned>(fb::ParameterType::MAX))
      return fail(at + format(" has unknown type %u", static_cast<unsigned>(p.type())));
    const float v = p.default_value(), lo = p.min_value(), hi = p.max_value();
    if (!std::isfinite(v) || std::isnan(lo) || std::isnan(hi) || lo > hi)
      return fail(at + format(": default %g, range [%g, %g] must be finite and ordered", v, lo, hi));
    switch (p.type()) {
      case fb::ParameterType::Float:
      case fb::ParameterType::Int:
        if (v < lo || v > hi) return fail(at + format(": default %g lies outside [%g, %g]", v, lo, hi));
        if (p.type() == fb::ParameterType::Int && v != std::floor(v))
          return fail(at + format(": integer default %g is not a whole number", v));
        break;
      case fb::ParameterType::Bool:
      case fb::ParameterType::Trigger:
        if (v != 0.0f && v != 1.0f) return fail(at + format(": default %g must be 0 or 1", v));
        break;
      case fb::ParameterType::Vector:
        if (const fb::Vec3* d = p.default_vector(); d && !(vector_ok(*d)))
          return fail(at + ": default vector must be finite and within +-1e6");
        if (static_cast<unsigned>(p.space()) > static_cast<unsigned>(fb::ParameterSpace::MAX))
          return fail(at + format(" has unknown space %u", static_cast<unsigned>(p.space())));
        break;
      case fb::ParameterType::Enum: {
        const size_t n = p.enum_values() ? p.enum_values()->size() : 0;
        if (n == 0) return fail(at + ": an enum needs at least one value");
        if (!spend(uint64_t(n) * 4)) return over_budget();
        if (v < 0.0f || v != std::floor(v) || v >= static_cast<float>(n))
          return fail(at + format(": default %g is not a value index (< %zu)", v, n));
        break;
      }
    }
    return {};
  }

  /// Node n refers to child c: children first, one referrer each; depth follows.
  Status child(size_t n, uint32_t c, const char* what) {
    if (c >= n)
      return fail(format("node %zu: %s %u must be an earlier node (nodes are stored children first)", n, what, c));
    if (++referrers_[c] > 1)
      return fail(format("node %zu: %s %u is already used by another node or state", n, what, c));
    if (depth_[c] + 1 > depth_[n]) depth_[n] = depth_[c] + 1;
    if (depth_[n] > kMaxGraphDepth)
      return fail(format("node %zu: the graph is nested more than %u levels deep", n, kMaxGraphDepth));
    return {};
  }

  static bool finite(float v) { return std::isfinite(v); }
  /// Magnitudes the evaluator can multiply together without overflowing a float: rates, weights,
  /// times and blend-space coordinates of real graphs are far inside these.
  static bool rate_ok(float v) { return std::isfinite(v) && std::fabs(v) <= kMaxRate; }
  static bool weight_ok(float v) { return std::isfinite(v) && std::fabs(v) <= kMaxWeight; }
  static bool time_ok(float v) { return std::isfinite(v) && v >= 0.0f && v <= kMaxSeconds; }
  static bool coordinate_ok(float v) { return std::isfinite(v) && std::fabs(v) <= kMaxCoordinate; }
  static bool vector_ok(const fb::Vec3& v) {
    return coordinate_ok(v.x()) && coordinate_ok(v.y()) && coordinate_ok(v.z());
  }
  static bool vector_ok(const fb::Vec3* v) { return !v || vector_ok(*v); }
  Status check_joint(const std::string& at, const char* what, uint32_t j) const {
    if (j >= g_.joint_count())
      return fail(at + format(": %s joint %u is out of range (%u joints)", what, j, g_.joint_count()));
    return {};
  }
  Status check_weight(const std::string& at, float weight, int16_t parameter) {
    if (!std::isfinite(weight) || weight < 0.0f || weight > 1.0f) return fail(at + ": weight must be within [0, 1]");
    return check_param_ref(at + " weight", parameter, true, {fb::ParameterType::Float, fb::ParameterType::Bool});
  }
  Status check_legs(const std::string& at, const flatbuffers::Vector<flatbuffers::Offset<fb::FootLeg>>& legs) {
    if (legs.size() == 0 || legs.size() > kMaxFootLegs)
      return fail(at + format(": %u legs; a foot node needs 1 to %u", legs.size(), kMaxFootLegs));
    for (flatbuffers::uoffset_t k = 0; k < legs.size(); ++k) {
      const fb::FootLeg& leg = *legs.Get(k);
      const std::string lat = at + format(" leg %u", k);
      if (Status st = check_joint(lat, "hip", leg.hip()); !st) return st;
      if (Status st = check_joint(lat, "knee", leg.knee()); !st) return st;
      if (Status st = check_joint(lat, "ankle", leg.ankle()); !st) return st;
      if (Status st = check_param_ref(lat + " ground", leg.ground_parameter(), true, {fb::ParameterType::Float}); !st)
        return st;
      if (Status st = check_param_ref(lat + " normal", leg.normal_parameter(), true, {fb::ParameterType::Vector}); !st)
        return st;
      if (Status st = check_param_ref(lat + " planted", leg.planted_parameter(), true,
                                      {fb::ParameterType::Float, fb::ParameterType::Bool});
          !st)
        return st;
    }
    return {};
  }
  /// Format v10: the source rig is another file's; its bones are checked against its joint count
  /// here and the skeleton itself when a definition binds the clip (graph_retarget.cpp).
  Status check_retarget(const std::string& at, const fb::RetargetNode& r) {
    if (r.clip() >= clip_count_)
      return fail(at + format(": retarget clip %u is out of range (%zu clips)", r.clip(), clip_count_));
    if (!rate_ok(r.rate()))
      return fail(at + format(": retarget rate %g must be finite and within +-%g", r.rate(), kMaxRate));
    if (!time_ok(r.start_offset())) return fail(at + ": retarget start offset must be finite and in [0, 1e6] s");
    if (r.source_joint_count() == 0) return fail(at + ": retarget source rig has no joints");
    struct Side {
      const flatbuffers::Vector<int16_t>* bones;
      const flatbuffers::Vector<const fb::RetargetRestRotation*>* rotations;
      uint8_t rest;
      uint32_t joints;
      const char* which;
    };
    const Side sides[] = {
        {r.source_bones(), r.source_rest_rotations(), r.source_rest(), r.source_joint_count(), "source"},
        {r.target_bones(), r.target_rest_rotations(), r.target_rest(), g_.joint_count(), "target"}};
    for (const Side& side : sides) {
      if (side.bones->size() != detail::kRetargetBoneCount)
        return fail(at + format(": retarget %s bones: %u entries, not one per humanoid bone (%zu)", side.which,
                                side.bones->size(), detail::kRetargetBoneCount));
      for (flatbuffers::uoffset_t b = 0; b < side.bones->size(); ++b) {
        const int16_t j = side.bones->Get(b);
        if (j < -1 || (j >= 0 && uint32_t(j) >= side.joints))
          return fail(at + format(": retarget %s bone %u names joint %d, out of range (%u joints)", side.which, b, j,
                                  side.joints));
      }
      if (side.rest > 1)
        return fail(at + format(": retarget %s rest mode %u is unknown (0 straighten, 1 bind)", side.which, side.rest));
      if (side.rotations == nullptr) continue;
      if (!spend(uint64_t(side.rotations->size()) * 20)) return over_budget();
      if (side.rotations->size() > side.joints)
        return fail(at + format(": retarget %s rest rotations: %u, more than the rig's %u joints", side.which,
                                side.rotations->size(), side.joints));
      for (const fb::RetargetRestRotation* x : *side.rotations) {
        const fb::Quat& q = x->rotation();
        const float len = std::sqrt(q.x() * q.x() + q.y() * q.y() + q.z() * q.z() + q.w() * q.w());
        if (x->joint() >= side.joints)
          return fail(at + format(": retarget %s rest rotation joint %u is out of range (%u joints)", side.which,
                                  x->joint(), side.joints));
        if (!std::isfinite(len) || std::fabs(len - 1.0f) > 1e-3f)
          return fail(
              at + format(": retarget %s rest rotation of joint %u is not a unit quaternion", side.which, x->joint()));
      }
    }
    return check_param_ref(at + " rate", r.rate_parameter(), true, {fb::ParameterType::Float, fb::ParameterType::Int});
  }
  static constexpr float kMaxRate = 1000.0f, kMaxWeight = 100.0f, kMaxSeconds = 1e6f, kMaxCoordinate = 1e6f;

  Status check_node(size_t n) {
    const fb::Node& node = *g_.nodes()->Get(static_cast<flatbuffers::uoffset_t>(n));
    const std::string at = format("node %zu", n);
    switch (node.data_type()) {
      case fb::NodeData::ClipNode: {
        const auto& c = *node.data_as_ClipNode();
        if (c.clip() >= clip_count_)
          return fail(at + format(": clip %u is out of range (%zu clips)", c.clip(), clip_count_));
        if (retarget_clip_[c.clip()])
          return fail(at + format(": clip %u is played by a retarget node (bound to another rig)", c.clip()));
        if (!rate_ok(c.rate()))
          return fail(at + format(": rate %g must be finite and within +-%g", c.rate(), kMaxRate));
        if (!time_ok(c.start_offset())) return fail(at + ": start offset must be finite and in [0, 1e6] s");
        return check_param_ref(at + " rate", c.rate_parameter(), true,
                               {fb::ParameterType::Float, fb::ParameterType::Int});
      }
      case fb::NodeData::RetargetNode: return check_retarget(at, *node.data_as_RetargetNode());
      case fb::NodeData::BlendAlphaNode: {
        const auto& a = *node.data_as_BlendAlphaNode();
        if (Status st = child(n, a.a(), "input a"); !st) return st;
        if (Status st = child(n, a.b(), "input b"); !st) return st;
        return check_param_ref(at + " alpha", a.alpha_parameter(), false, {fb::ParameterType::Float});
      }
      case fb::NodeData::SelectNode: {
        const auto& sel = *node.data_as_SelectNode();
        const size_t count = sel.children()->size();
        if (!spend(uint64_t(count) * 2)) return over_budget();
        if (count == 0) return fail(at + ": a select node needs children");
        if (!time_ok(sel.blend_time())) return fail(at + ": blend time must be finite and in [0, 1e6] s");
        if (Status st = check_param_ref(at + " selector", sel.parameter(), false,
                                        {fb::ParameterType::Bool, fb::ParameterType::Int, fb::ParameterType::Enum});
            !st)
          return st;
        if (type_of(sel.parameter()) == fb::ParameterType::Bool && count != 2)
          return fail(at + format(": a bool selects between 2 children, not %zu", count));
        for (uint16_t c : *sel.children())
          if (Status st = child(n, c, "child"); !st) return st;
        return {};
      }
      case fb::NodeData::LayeredBlendNode: {
        const auto& l = *node.data_as_LayeredBlendNode();
        if (Status st = child(n, l.base(), "base"); !st) return st;
        if (!spend(uint64_t(l.layers()->size()) * 8)) return over_budget();
        for (flatbuffers::uoffset_t k = 0; k < l.layers()->size(); ++k) {
          const fb::Layer& layer = *l.layers()->Get(k);
          const std::string lat = at + format(" layer %u", k);
          if (Status st = child(n, layer.node(), "layer"); !st) return st;
          if (!weight_ok(layer.weight()))
            return fail(lat + format(": weight must be finite and within +-%g", kMaxWeight));
          if (!time_ok(layer.blend_time())) return fail(lat + ": blend time must be finite and in [0, 1e6] s");
          if (Status st = check_param_ref(lat + " weight", layer.weight_parameter(), true,
                                          {fb::ParameterType::Float, fb::ParameterType::Bool});
              !st)
            return st;
          if (const auto* targets = layer.morph_targets()) {
            if (!spend(uint64_t(targets->size()) * 8)) return over_budget();
            for (flatbuffers::uoffset_t t = 0; t < targets->size(); ++t)
              if (flatbuffers::GetStringView(targets->Get(t)).empty())
                return fail(lat + format(": morph target name %u is empty", t));
          }
          if (!spend(uint64_t(layer.mask()->size()) * 4)) return over_budget();
          for (const fb::MaskEntry* e : *layer.mask())
            if (e->joint() >= g_.joint_count())
              return fail(lat + format(": mask joint %u is out of range (%u joints)", e->joint(), g_.joint_count()));
        }
        return {};
      }
      case fb::NodeData::BlendSpaceNode: {
        const auto& b = *node.data_as_BlendSpaceNode();
        const auto& samples = *b.samples();
        if (!spend(uint64_t(samples.size()) * 12)) return over_budget();
        const bool two_d = b.y_parameter() >= 0;
        if (samples.size() == 0 || (two_d && samples.size() < 3))
          return fail(at + format(": a %s blend space needs at least %d samples", two_d ? "2D" : "1D", two_d ? 3 : 1));
        if (samples.size() > 1024) return fail(at + ": more than 1024 blend-space samples");
        if (!rate_ok(b.rate()))
          return fail(at + format(": rate %g must be finite and within +-%g", b.rate(), kMaxRate));
        if (Status st =
                check_param_ref(at + " x", b.x_parameter(), false, {fb::ParameterType::Float, fb::ParameterType::Int});
            !st)
          return st;
        if (Status st =
                check_param_ref(at + " y", b.y_parameter(), true, {fb::ParameterType::Float, fb::ParameterType::Int});
            !st)
          return st;
        for (flatbuffers::uoffset_t k = 0; k < samples.size(); ++k) {
          const fb::BlendSample& smp = *samples.Get(k);
          if (smp.clip() >= clip_count_) return fail(at + format(": sample %u clip %u is out of range", k, smp.clip()));
          if (retarget_clip_[smp.clip()])
            return fail(
                at + format(": sample %u clip %u is played by a retarget node (bound to another rig)", k, smp.clip()));
          if (!coordinate_ok(smp.x()) || !coordinate_ok(smp.y()))
            return fail(at + format(": sample %u position must be finite and within +-%g", k, kMaxCoordinate));
          if (!two_d && k > 0 && !(smp.x() > samples.Get(k - 1)->x()))
            return fail(at + format(": 1D samples must have strictly increasing x (sample %u)", k));
        }
        return {};
      }
      case fb::NodeData::AdditiveNode: {
        const auto& a = *node.data_as_AdditiveNode();
        if (Status st = child(n, a.base(), "base"); !st) return st;
        if (Status st = child(n, a.additive(), "additive input"); !st) return st;
        if (!weight_ok(a.weight())) return fail(at + format(": weight must be finite and within +-%g", kMaxWeight));
        return check_param_ref(at + " weight", a.weight_parameter(), true,
                               {fb::ParameterType::Float, fb::ParameterType::Bool});
      }
      case fb::NodeData::SlotNode: {  // format v9 (validate_montage.cpp)
        const auto& slot = *node.data_as_SlotNode();
        if (Status st = child(n, slot.input(), "input"); !st) return st;
        bool over = false;
        const std::string e = detail::check_slot_node(slot, n, g_.joint_count(), budget_, &over);
        if (over) return over_budget();
        return e.empty() ? Status{} : fail(e);
      }
      case fb::NodeData::MorphWeightsNode: {
        const auto& m = *node.data_as_MorphWeightsNode();
        if (Status st = child(n, m.input(), "input"); !st) return st;
        const auto& drives = *m.drives();
        if (!spend(uint64_t(drives.size()) * 12)) return over_budget();
        if (drives.size() == 0) return fail(at + ": a morph node has no drives");
        for (flatbuffers::uoffset_t k = 0; k < drives.size(); ++k) {
          const fb::MorphDrive& d = *drives.Get(k);
          const std::string dat = at + format(" drive %u", k);
          if (flatbuffers::GetStringView(d.target()).empty()) return fail(dat + ": empty target name");
          if (!weight_ok(d.scale())) return fail(dat + format(": scale must be finite and within +-%g", kMaxWeight));
          if (Status st =
                  check_param_ref(dat, d.parameter(), false, {fb::ParameterType::Float, fb::ParameterType::Bool});
              !st)
            return st;
        }
        return {};
      }
      case fb::NodeData::TwoBoneIkNode: {
        const auto& t = *node.data_as_TwoBoneIkNode();
        if (Status st = child(n, t.input(), "input"); !st) return st;
        if (Status st = check_joint(at, "start", t.start()); !st) return st;
        if (Status st = check_joint(at, "mid", t.mid()); !st) return st;
        if (Status st = check_joint(at, "end", t.end()); !st) return st;
        if (Status st = check_param_ref(at + " target", t.target_parameter(), false, {fb::ParameterType::Vector}); !st)
          return st;
        if (Status st = check_param_ref(at + " pole", t.pole_parameter(), true, {fb::ParameterType::Vector}); !st)
          return st;
        if (!vector_ok(t.pole()) || !vector_ok(t.mid_axis()) || !finite(t.twist()) || std::fabs(t.twist()) > 100.0f)
          return fail(at + ": pole, mid axis and twist must be finite and within bounds");
        if (!(t.soften() > 0.0f && t.soften() <= 1.0f)) return fail(at + ": soften must be within (0, 1]");
        return check_weight(at, t.weight(), t.weight_parameter());
      }
      case fb::NodeData::AimNode: {
        const auto& a = *node.data_as_AimNode();
        if (Status st = child(n, a.input(), "input"); !st) return st;
        const auto& chain = *a.chain();
        if (!spend(uint64_t(chain.size()) * 12)) return over_budget();
        if (chain.size() == 0 || chain.size() > kMaxSpringJoints)
          return fail(at + format(": an aim chain has %u joints; it needs 1 to %u", chain.size(), kMaxSpringJoints));
        for (flatbuffers::uoffset_t k = 0; k < chain.size(); ++k) {
          const fb::AimJoint& j = *chain.Get(k);
          if (Status st = check_joint(at, "aim", j.joint()); !st) return st;
          if (!(j.weight() >= 0.0f && j.weight() <= 1.0f) || !(j.max_angle() >= 0.0f && j.max_angle() <= 100.0f))
            return fail(at + format(": aim joint %u: weight must be within [0, 1] and max angle within [0, 100]", k));
        }
        if (Status st = check_param_ref(at + " target", a.target_parameter(), false, {fb::ParameterType::Vector}); !st)
          return st;
        if (!vector_ok(a.forward()) || !vector_ok(a.up()) || !vector_ok(a.pole()))
          return fail(at + ": forward, up and pole must be finite and within +-1e6");
        return check_weight(at, a.weight(), a.weight_parameter());
      }
      case fb::NodeData::FootPlacementNode: {
        const auto& f = *node.data_as_FootPlacementNode();
        if (Status st = child(n, f.input(), "input"); !st) return st;
        if (Status st = check_joint(at, "pelvis", f.pelvis()); !st) return st;
        if (!spend(uint64_t(f.legs()->size()) * 32)) return over_budget();
        if (Status st = check_legs(at, *f.legs()); !st) return st;
        if (!vector_ok(f.up()) || !coordinate_ok(f.max_pelvis_drop()) || !(f.align() >= 0.0f && f.align() <= 1.0f))
          return fail(at + ": up, pelvis drop and align must be finite (align within [0, 1])");
        if (!(f.soften() > 0.0f && f.soften() <= 1.0f)) return fail(at + ": soften must be within (0, 1]");
        return check_weight(at, f.weight(), f.weight_parameter());
      }
      case fb::NodeData::FootLockNode: {
        const auto& f = *node.data_as_FootLockNode();
        if (Status st = child(n, f.input(), "input"); !st) return st;
        if (!spend(uint64_t(f.legs()->size()) * 32)) return over_budget();
        if (Status st = check_legs(at, *f.legs()); !st) return st;
        if (!(f.release_radius() > 0.0f) || !coordinate_ok(f.release_radius()) || !time_ok(f.blend_time()))
          return fail(at + ": release radius must be positive and finite, blend time within [0, 1e6] s");
        return check_weight(at, f.weight(), f.weight_parameter());
      }
      case fb::NodeData::SpringNode: {
        const auto& sp = *node.data_as_SpringNode();
        if (Status st = child(n, sp.input(), "input"); !st) return st;
        const auto& chains = *sp.chains();
        if (chains.size() == 0) return fail(at + ": a spring node has no chains");
        if (!spend(uint64_t(chains.size()) * 32)) return over_budget();
        for (flatbuffers::uoffset_t k = 0; k < chains.size(); ++k) {
          const fb::SpringChainSettings& c = *chains.Get(k);
          const std::string cat = at + format(" chain %u", k);
          if (!spend(uint64_t(c.joints()->size()) * 2)) return over_budget();
          if (c.joints()->size() == 0 || c.joints()->size() > kMaxSpringJoints)
            return fail(cat + format(": %u joints; a chain needs 1 to %u", c.joints()->size(), kMaxSpringJoints));
          for (uint16_t j : *c.joints())
            if (Status st = check_joint(cat, "chain", j); !st) return st;
          if (!(c.stiffness() >= 0.0f && c.stiffness() <= 1e4f) || !(c.drag() >= 0.0f && c.drag() <= 1.0f) ||
              !vector_ok(c.gravity()) || !(c.radius() >= 0.0f) || !coordinate_ok(c.radius()) ||
              !(c.tail_length() >= 0.0f) || !coordinate_ok(c.tail_length()))
            return fail(cat +
                        ": stiffness within [0, 1e4], drag within [0, 1], gravity, radius and tail length finite and "
                        "not negative");
        }
        if (const auto* colliders = sp.colliders()) {
          if (!spend(uint64_t(colliders->size()) * 32)) return over_budget();
          for (flatbuffers::uoffset_t k = 0; k < colliders->size(); ++k) {
            const fb::SpringColliderShape& c = *colliders->Get(k);
            if (Status st = check_joint(at + format(" collider %u", k), "its", c.joint()); !st) return st;
            if (!vector_ok(c.offset()) || !vector_ok(c.tail()) || !(c.radius() >= 0.0f) || !coordinate_ok(c.radius()))
              return fail(at + format(" collider %u: offset, tail and radius must be finite (radius not negative)", k));
          }
        }
        if (!(sp.step() >= 1e-4f && sp.step() <= 1.0f)) return fail(at + ": step must be within [1e-4, 1] s");
        if (!(sp.teleport_distance() >= 0.0f) || !coordinate_ok(sp.teleport_distance()))
          return fail(at + ": teleport distance must be finite and not negative");
        return check_weight(at, sp.weight(), sp.weight_parameter());
      }
      case fb::NodeData::StateMachineNode: {
        const uint16_t m = node.data_as_StateMachineNode()->machine();
        if (m >= machine_count_)
          return fail(at + format(": state machine %u is out of range (%zu machines)", m, machine_count_));
        if (machine_player_[m] >= 0)
          return fail(at + format(": state machine %u is already played by node %d", m, machine_player_[m]));
        machine_player_[m] = static_cast<int>(n);
        const fb::StateMachine& sm = *g_.machines()->Get(m);
        if (!spend(uint64_t(sm.states()->size()) * 8)) return over_budget();
        if (sm.states()->size() == 0) return fail(at + format(": state machine %u has no states", m));
        for (flatbuffers::uoffset_t k = 0; k < sm.states()->size(); ++k)
          if (Status st = child(n, sm.states()->Get(k)->node(), "state"); !st) return st;
        return {};
      }
      default: return fail(at + format(": unknown node kind %u", static_cast<unsigned>(node.data_type())));
    }
  }

  Status check_machine(size_t m) {
    const fb::StateMachine& sm = *g_.machines()->Get(static_cast<flatbuffers::uoffset_t>(m));
    std::string at = format("state machine %zu", m);
    if (!flatbuffers::GetStringView(sm.name()).empty())
      at += " '" + detail::printable(flatbuffers::GetStringView(sm.name())) + "'";
    const size_t states = sm.states()->size();
    for (size_t k = 0; k < states; ++k)
      if (flatbuffers::GetStringView(sm.states()->Get(static_cast<flatbuffers::uoffset_t>(k))->name()).empty())
        return fail(at + format(": state %zu has an empty name", k));
    if (sm.entry() >= states)
      return fail(at + format(": entry state %u is out of range (%zu states)", sm.entry(), states));
    const auto* transitions = sm.transitions();
    if (!transitions) return {};
    if (!spend(uint64_t(transitions->size()) * 16)) return over_budget();
    for (flatbuffers::uoffset_t k = 0; k < transitions->size(); ++k) {
      const fb::Transition& t = *transitions->Get(k);
      const std::string tat = at + format(" transition %u", k);
      if (t.from() < -1 || (t.from() >= 0 && static_cast<size_t>(t.from()) >= states))
        return fail(tat + format(": source state %d is out of range", t.from()));
      if (t.to() >= states) return fail(tat + format(": target state %u is out of range", t.to()));
      if (t.from() == t.to()) return fail(tat + ": a state cannot transition to itself");
      if (!time_ok(t.duration())) return fail(tat + ": duration must be finite and in [0, 1e6] s");
      if (!finite(t.exit_time()) || t.exit_time() > kMaxSeconds)
        return fail(tat + ": exit time must be finite and <= 1e6");
      if (static_cast<unsigned>(t.mode()) > static_cast<unsigned>(fb::TransitionMode::MAX))
        return fail(tat + format(": unknown blend mode %u", static_cast<unsigned>(t.mode())));
      if (Status st = check_condition(t, tat); !st) return st;
    }
    return {};
  }

  Status check_condition(const fb::Transition& t, const std::string& at) {
    const auto* cond = t.condition();
    if (!cond || cond->size() == 0) return {};
    if (!spend(uint64_t(cond->size()) * 8)) return over_budget();
    int depth = 0;
    for (flatbuffers::uoffset_t i = 0; i < cond->size(); ++i) {
      const fb::ConditionInstr& c = *cond->Get(i);
      const std::string iat = at + format(" condition %u", i);
      switch (c.op()) {
        case fb::ConditionOp::True: ++depth; break;
        case fb::ConditionOp::Less:
        case fb::ConditionOp::LessEqual:
        case fb::ConditionOp::Greater:
        case fb::ConditionOp::GreaterEqual:
        case fb::ConditionOp::Equal:
        case fb::ConditionOp::NotEqual:
          if (!finite(c.value())) return fail(iat + ": comparison value is not finite");
          if (Status st = check_param_ref(
                  iat, c.parameter(), false,
                  {fb::ParameterType::Float, fb::ParameterType::Int, fb::ParameterType::Bool, fb::ParameterType::Enum});
              !st)
            return st;
          ++depth;
          break;
        case fb::ConditionOp::Bool:
          if (Status st = check_param_ref(iat, c.parameter(), false, {fb::ParameterType::Bool}); !st) return st;
          ++depth;
          break;
        case fb::ConditionOp::Trigger:
          if (Status st = check_param_ref(iat, c.parameter(), false, {fb::ParameterType::Trigger}); !st) return st;
          ++depth;
          break;
        case fb::ConditionOp::Not:
          if (depth < 1) return fail(iat + ": 'not' with nothing to negate");
          break;
        case fb::ConditionOp::And:
        case fb::ConditionOp::Or:
          if (depth < 2) return fail(iat + ": 'and' / 'or' needs two operands");
          --depth;
          break;
        default: return fail(iat + format(": unknown operation %u", static_cast<unsigned>(c.op())));
      }
      if (depth > 16) return fail(iat + ": the condition needs more than 16 stack entries");
    }
    if (depth != 1) return fail(at + format(": the condition leaves %d values instead of 1", depth));
    return {};
  }

  const fb::Graph& g_;
  uint64_t& budget_;
  std::string where_;
  size_t param_count_ = 0, clip_count_ = 0, node_count_ = 0, machine_count_ = 0;
  std::vector<uint8_t> referrers_;
  std::vector<uint8_t> retarget_clip_;  // per clip: 1 when a retarget node plays it
  std::vector<uint32_t> depth_;
  std::vector<int> machine_player_;
};

}  // namespace

Status validate_graph(const fb::Graph& graph, size_t index, std::string_view name, uint64_t& budget) {
  return GraphChecker(graph, index, name, budget).run();
}

}  // namespace ossa
