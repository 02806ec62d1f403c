// cloth_solve.cpp — the cloth solver: XPBD over fixed substeps in the character's model space
// (see cloth.h for the model and why it is shaped so).
//
// One substep, in order: carry the particles by the world's motion since the last substep (scaled
// by the inertia settings), predict (damped velocity, gravity, the wind's drag along the normal,
// the speed limit), then per iteration project stretch and bend edges (XPBD: the compliance term
// alpha / h^2 makes stiffness independent of h and of the iteration count), the tethers (a hard,
// one-sided limit on the distance to a fixed particle), each particle's max distance and backstop,
// and last the colliders, so no substep ends inside one. Fixed particles (inverse mass 0) are set
// to their skinned position and never moved by a constraint, since every correction is weighted by
// inverse mass.
//
// Layout: the particles are planes (ClothParticles: x[], y[], z[], inverse mass[]), and the
// constraints run in the order of their wide lists (ClothWideList: the cooker's colours, each
// regrouped by make_cloth_instance so that eight consecutive constraints touch different, mostly
// consecutive, particles), which lets the AVX2 kernels take eight with plain loads and the CPU
// overlap them on either path, with the stored order's bits.
// With one iteration (the default: small steps) the XPBD multiplier starts at zero every substep
// and is never read back, so that loop keeps no multipliers at all.
#include <ossa/anim/cloth.h>

#include <algorithm>
#include <cmath>

#include <glm/gtc/quaternion.hpp>

#include "anim/cloth_kernels.h"
#include "common/message.h"
#include "internal/rotation.h"
#include "internal/vector_clones.h"

namespace ossa {
namespace {

constexpr int kMaxSubsteps = 64;  // a longer dt (a hitch, a debugger pause) is dropped

/// A model-to-world transform as rotation, translation and uniform scale.
struct Frame {
  glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};
  glm::vec3 translation{0.0f};
  float scale = 1.0f;
};

Frame frame_of(const glm::mat4& m) {
  Frame f;
  f.rotation = detail::orientation(m);
  f.translation = glm::vec3(m[3]);
  const float s = glm::length(glm::vec3(m[0]));
  f.scale = s > 1e-12f ? s : 1.0f;
  return f;
}

glm::mat4 matrix_of(const Frame& f) {
  glm::mat4 m = glm::mat4_cast(f.rotation);
  for (int c = 0; c < 3; ++c) m[c] *= f.scale;
  m[3] = glm::vec4(f.translation, 1.0f);
  return m;
}

/// Where a point at rest in the world moves in model space when the frame goes from `a` to `b`,
/// with the inertia settings' share of it: p' = rotation * p + translation.
struct Carry {
  glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};
  glm::vec3 translation{0.0f};
  bool identity = true;
};

Carry carry(const Frame& a, const Frame& b, const ClothSettings& s) {
  const glm::quat to_b = glm::conjugate(b.rotation);
  Carry c;
  c.rotation = glm::slerp(glm::quat(1.0f, 0.0f, 0.0f, 0.0f), to_b * a.rotation, s.angular_inertia);
  c.translation = (to_b * (a.translation - b.translation)) * (s.linear_inertia / b.scale);
  c.identity = c.rotation == glm::quat(1.0f, 0.0f, 0.0f, 0.0f) && c.translation == glm::vec3(0.0f);
  return c;
}

/// A world-space vector (per second or per second^2) in frame f's model space.
glm::vec3 to_model(const Frame& f, const glm::vec3& v) { return (glm::conjugate(f.rotation) * v) / f.scale; }

glm::vec3 xyz(const glm::vec4& v) { return glm::vec3(v.x, v.y, v.z); }

bool finite_matrix(const glm::mat4& m) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r])) return false;
  return true;
}

glm::vec3 closest_on_segment(const glm::vec3& p, const glm::vec3& a, const glm::vec3& b) {
  const glm::vec3 ab = b - a;
  const float len2 = glm::dot(ab, ab);
  if (!(len2 > 0.0f)) return a;
  return a + ab * std::clamp(glm::dot(p - a, ab) / len2, 0.0f, 1.0f);
}

/// How a substep's inputs are made from the last three updates': older * w.older + before *
/// w.before + now * w.now (Lagrange weights of the parabola through them; a line between the last
/// two when there is no older one).
struct Weights {
  float older = 0.0f, before = 1.0f, now = 0.0f;
  glm::vec3 of(const glm::vec3& o, const glm::vec3& b, const glm::vec3& n) const {
    return o * older + b * before + n * now;
  }
};

/// The weights at s seconds into an update of dt seconds that came `gap` seconds after the one
/// before it; quadratic only with a usable older update.
Weights weights_at(float s, float dt, float gap, bool quadratic) {
  Weights w;
  if (!(dt > 0.0f)) {
    w.before = 0.0f;
    w.now = 1.0f;
    return w;
  }
  if (!quadratic || !(gap > 1e-6f)) {
    w.now = s / dt;
    w.before = 1.0f - w.now;
    return w;
  }
  // Times -gap, 0, dt.
  w.older = s * (s - dt) / (gap * (gap + dt));
  w.before = -(s + gap) * (s - dt) / (gap * dt);
  w.now = (s + gap) * s / (dt * (gap + dt));
  return w;
}

/// Everything one substep needs besides the instance.
struct Step {
  float h = 0.0f;              // seconds
  float f = 0.0f;              // where the substep ends between the last update's inputs (0) and this one's (1)
  Weights w;                   // the inputs at the substep's end
  glm::vec3 gravity_h2{0.0f};  // model space, displacement per substep from gravity
  glm::vec3 wind_h{0.0f};      // model space, the air's displacement per substep
  float keep = 1.0f;           // velocity kept per substep (damping)
  float drag = 0.0f;           // share of the normal relative velocity taken per substep
  float max_step = 0.0f;       // > 0: the longest move per substep (max_speed * h)
  bool carried = true;         // false: predict applies the world's carry (carry_r, carry_t) first
  glm::mat3 carry_r{1.0f};
  glm::vec3 carry_t{0.0f};
};

/// The world's carry for particles `first` on (those before it are the prediction kernel's).
void apply_carry(ClothInstance& c, const Carry& k, size_t first) {
  if (k.identity) return;
  const glm::mat3 r = glm::mat3_cast(k.rotation);
  ClothParticles& p = c.particles;
  const size_t n = p.size();
  size_t i = first;
#if OSSA_HAVE_VECTOR_CLONES
  if (detail::cloth_kernels_selected() && first == 0) {
    i = n & ~size_t{7};
    detail::carry_particles8(p, i, r, k.translation);
  }
#endif
  for (; i < n; ++i) {
    p.set(i, r * p.at(i) + k.translation);
    p.set_before(i, r * p.before(i) + k.translation);
  }
}

/// Particle i's prediction (see predict).
OSSA_INLINE void predict_one(ClothInstance& c, size_t i, std::span<const glm::vec3> skinned, const Step& st) {
  ClothParticles& p = c.particles;
  const glm::vec3 at = p.at(i);
  if (p.w[i] == 0.0f) {
    p.set_before(i, at);
    p.set(i, st.w.of(c.skinned_older[i], c.skinned_before[i], skinned[i]));
    return;
  }
  glm::vec3 v = (at - p.before(i)) * st.keep;
  if (st.drag > 0.0f) {
    // The wind's drag along the normal of a triangle the particle is a corner of, from the
    // current positions (the particles before i already predicted, as the loop goes).
    const uint16_t* f = &c.facing[3 * i];
    const glm::vec3 a = p.at(f[0]);
    glm::vec3 nrm = glm::cross(p.at(f[1]) - a, p.at(f[2]) - a);
    const float len2 = glm::dot(nrm, nrm);
    nrm = len2 > 1e-30f ? nrm * (1.0f / std::sqrt(len2)) : glm::vec3(0.0f);
    v += nrm * (glm::dot(nrm, st.wind_h - v) * st.drag);
  }
  v += st.gravity_h2;
  const float max2 = st.max_step * st.max_step;
  if (max2 > 0.0f) {
    const float l2 = glm::dot(v, v);
    if (l2 > max2) v *= st.max_step / std::sqrt(l2);
  }
  p.set_before(i, at);
  p.set(i, at + v);
}

/// Damped velocity, the wind's drag, gravity and the speed limit for free particles; fixed ones
/// step to their skinned position. Without drag the particles do not read each other, and the
/// kernel takes eight at a time (applying the world's carry first when st.carried is false).
void predict(ClothInstance& c, std::span<const glm::vec3> skinned, const Step& st) {
  const size_t n = c.particles.size();
  size_t i = 0;
#if OSSA_HAVE_VECTOR_CLONES
  if (detail::cloth_kernels_selected() && !(st.drag > 0.0f)) {
    for (; i + 8 <= n; i += 8)
      for (uint32_t fixed = detail::predict_particles8(c.particles, i, st.keep, st.gravity_h2, st.max_step,
                                                       st.carried ? nullptr : &st.carry_r, st.carry_t);
           fixed != 0; fixed &= fixed - 1)
        predict_one(c, i + static_cast<size_t>(__builtin_ctz(fixed)), skinned, st);
  }
#endif
  for (; i < n; ++i) predict_one(c, i, skinned, st);
}

/// Lane k of a wide list as one XPBD distance constraint (the kernels' edge_one; an idle lane
/// has no inverse mass and changes nothing). kLambda: keep its multiplier across iterations.
template <bool kLambda>
OSSA_INLINE void project_edge(ClothParticles& p, const ClothWideList& l, size_t k, float alpha, float* lambda) {
  const uint32_t a = l.a[k], b = l.b[k];
  const float wa = l.wa[k], wb = l.wb[k], wsum = wa + wb;
  const glm::vec3 d(p.x[b] - p.x[a], p.y[b] - p.y[a], p.z[b] - p.z[a]);
  const float len2 = glm::dot(d, d);
  if (!(len2 > 1e-24f) || wsum == 0.0f) return;
  const float len = std::sqrt(len2);
  const float violation = len - l.rest[k];
  float s;  // the correction per unit of d: dl / len, in one division where no multiplier is kept
  if constexpr (kLambda) {
    const float dl = (-violation - alpha * lambda[k]) / (wsum + alpha);
    lambda[k] += dl;
    s = dl / len;
  } else {
    s = -violation / ((wsum + alpha) * len);
  }
  const glm::vec3 corr = d * s;
  p.x[a] -= wa * corr.x;
  p.y[a] -= wa * corr.y;
  p.z[a] -= wa * corr.z;
  p.x[b] += wb * corr.x;
  p.y[b] += wb * corr.y;
  p.z[b] += wb * corr.z;
}

template <bool kLambda>
void project_edges(ClothParticles& p, const ClothWideList& l, float alpha, float* lambda) {
  for (size_t k = 0; k < l.a.size(); ++k) project_edge<kLambda>(p, l, k, alpha, lambda);
}

/// Moves `p` onto the sphere of radius `limit` around `anchor` when it is outside it (a tether).
OSSA_INLINE bool hold_within(glm::vec3& p, const glm::vec3& anchor, float limit) {
  const glm::vec3 d = p - anchor;
  const float len2 = glm::dot(d, d);
  if (len2 <= limit * limit) return false;
  p = anchor + d * (limit / std::sqrt(len2));
  return true;
}

/// Lane k of a wide list as a tether (the particle a held within the length of the anchor b).
OSSA_INLINE void project_tether(ClothParticles& p, const ClothWideList& l, size_t k, float scale) {
  if (l.wa[k] == 0.0f) return;
  glm::vec3 at = p.at(l.a[k]);
  if (hold_within(at, p.at(l.b[k]), l.rest[k] * scale)) p.set(l.a[k], at);
}

/// Stretch, bend and tethers, one pass, in the wide lists' order (the stored runs in turn: see
/// ClothWideList): one lane at a time, or with the kernels, with the same bits.
void project_distances(ClothInstance& c, float stretch_alpha, float bend_alpha, bool wide) {
  ClothParticles& p = c.particles;
  const ClothSettings& s = c.settings;
  float* lambda = s.iterations > 1 ? c.lambda.data() : nullptr;
  float* bend_lambda = lambda ? lambda + c.wide_stretch.a.size() : nullptr;
#if OSSA_HAVE_VECTOR_CLONES
  if (wide) {
    detail::project_wide(p, c.wide_stretch, false, stretch_alpha, 0.0f, lambda);
    detail::project_wide(p, c.wide_bend, false, bend_alpha, 0.0f, bend_lambda);
    detail::project_wide(p, c.wide_tethers, true, 0.0f, s.tether_scale, nullptr);
    return;
  }
#else
  (void)wide;
#endif
  if (lambda) {
    project_edges<true>(p, c.wide_stretch, stretch_alpha, lambda);
    project_edges<true>(p, c.wide_bend, bend_alpha, bend_lambda);
  } else {
    project_edges<false>(p, c.wide_stretch, stretch_alpha, nullptr);
    project_edges<false>(p, c.wide_bend, bend_alpha, nullptr);
  }
  for (size_t k = 0; k < c.wide_tethers.a.size(); ++k) project_tether(p, c.wide_tethers, k, s.tether_scale);
}

/// Max distance and backstop against the skinned pose `f` of the way through this update.
void project_limits(ClothInstance& c, std::span<const glm::vec3> skinned, std::span<const glm::vec3> normals,
                    const Step& st) {
  const float f = st.f;
  const ClothSource& s = c.source;
  if (s.max_distances.empty() && s.backstops.empty()) return;
  ClothParticles& p = c.particles;
  for (size_t i = 0; i < p.size(); ++i) {
    if (p.w[i] == 0.0f) continue;
    const glm::vec3 anchor = st.w.of(c.skinned_older[i], c.skinned_before[i], skinned[i]);
    glm::vec3 at = p.at(i);
    if (!s.max_distances.empty()) {
      const float limit = s.max_distances[i];
      const glm::vec3 d = at - anchor;
      const float len2 = glm::dot(d, d);
      if (len2 > limit * limit) at = anchor + d * (limit / std::sqrt(len2));
    }
    if (!s.backstops.empty() && !normals.empty()) {
      const glm::vec3 nrm = glm::mix(c.skinned_normal_before[i], normals[i], f);
      const float depth = glm::dot(at - anchor, nrm);
      if (depth < -s.backstops[i]) at -= nrm * (depth + s.backstops[i]);
    }
    p.set(i, at);
  }
}

/// Each collider's ends and bounding sphere at weights w of the last three updates' (or, with
/// `now`, at this update's pose) into collider_step.
void set_collider_step(ClothInstance& c, const Weights& w, bool now = false) {
  const ClothSource& s = c.source;
  for (size_t k = 0; k < s.colliders.size(); ++k) {
    const auto end = [&](size_t e) {
      return now ? c.colliders_now[e] : w.of(c.colliders_older[e], c.colliders_before[e], c.colliders_now[e]);
    };
    const glm::vec3 a = end(2 * k), b = end(2 * k + 1);
    const float reach = s.colliders[k].radius() + c.settings.thickness;
    const float bound = 0.5f * glm::length(b - a) + reach;
    c.collider_step[3 * k] = glm::vec4(a, reach);
    c.collider_step[3 * k + 1] = glm::vec4(b, 0.0f);
    c.collider_step[3 * k + 2] = glm::vec4(0.5f * (a + b), bound * bound);
  }
}

/// Pushes the point `at` out of every collider of collider_step in turn; a point exactly on a
/// collider's axis goes out along `side - q` (the previous position's side of it).
OSSA_INLINE void push_out(const ClothInstance& c, glm::vec3& at, const glm::vec3& side) {
  const size_t count = c.source.colliders.size();
  for (size_t k = 0; k < count; ++k) {
    const glm::vec4& ea = c.collider_step[3 * k];
    const glm::vec4& bound = c.collider_step[3 * k + 2];
    const glm::vec3 dc = at - xyz(bound);
    if (glm::dot(dc, dc) >= bound.w) continue;
    const float reach = ea.w;
    const glm::vec3 q = closest_on_segment(at, xyz(ea), xyz(c.collider_step[3 * k + 1]));
    const glm::vec3 away = at - q;
    const float dist2 = glm::dot(away, away);
    if (dist2 >= reach * reach) continue;
    const float dist = std::sqrt(dist2);
    glm::vec3 dir = dist > 1e-12f ? away / dist : side - q;
    const float dl = glm::length(dir);
    dir = dl > 1e-12f ? dir / dl : glm::vec3(0.0f, 1.0f, 0.0f);
    at = q + dir * reach;
  }
}

/// Pushes free particles out of every collider (collider_step: this substep's), each particle
/// through the colliders in order, eight at a time with the kernels.
void project_colliders(ClothInstance& c, bool wide) {
  const size_t count = c.source.colliders.size();
  if (count == 0) return;
  ClothParticles& p = c.particles;
  const size_t n = p.size();
  const auto push = [&](size_t i) {
    if (p.w[i] == 0.0f) return;
    glm::vec3 at = p.at(i);
    push_out(c, at, p.before(i));
    p.set(i, at);
  };
  size_t next = 0;
#if OSSA_HAVE_VECTOR_CLONES
  if (wide) {
    for (; next + 8 <= n; next += 8) detail::push_out_colliders8(p, next, c.collider_step.data(), count);
  }
#else
  (void)wide;
#endif
  for (; next < n; ++next) push(next);
}

void substep(ClothInstance& c, const ClothInput& in, const Step& st) {
  predict(c, in.skinned_positions, st);
  const ClothSettings& s = c.settings;
  const float h2 = st.h * st.h;
  const float stretch_alpha = s.stretch_compliance / h2, bend_alpha = s.bend_compliance / h2;
  if (s.iterations > 1) std::fill(c.lambda.begin(), c.lambda.end(), 0.0f);
  const bool wide = detail::cloth_kernels_selected();
  set_collider_step(c, st.w);
  for (uint32_t it = 0; it < s.iterations; ++it) {
    project_distances(c, stretch_alpha, bend_alpha, wide);
    project_limits(c, in.skinned_positions, in.skinned_normals, st);
    project_colliders(c, wide);
  }
}

/// The colliders' model-space ends now.
void place_colliders(ClothInstance& c, std::span<const glm::mat4> model) {
  const auto& cols = c.source.colliders;
  for (size_t k = 0; k < cols.size(); ++k) {
    const fb::ClothCollider& col = cols[k];
    const glm::mat4 m = col.joint() < model.size() ? model[col.joint()] : glm::mat4(1.0f);
    const fb::Vec3& o = col.offset();
    const fb::Vec3& t = col.tail();
    c.colliders_now[2 * k] = glm::vec3(m * glm::vec4(o.x(), o.y(), o.z(), 1.0f));
    c.colliders_now[2 * k + 1] = glm::vec3(m * glm::vec4(t.x(), t.y(), t.z(), 1.0f));
  }
}

void restart(ClothInstance& c, const ClothInput& in) {
  const size_t n = c.particles.size();
  for (size_t i = 0; i < n; ++i) {
    c.particles.set(i, in.skinned_positions[i]);
    c.particles.set_before(i, in.skinned_positions[i]);
    c.skinned_before[i] = c.skinned_older[i] = in.skinned_positions[i];
    c.skinned_normal_before[i] = in.skinned_normals.empty() ? glm::vec3(0.0f) : in.skinned_normals[i];
  }
  std::copy(c.colliders_now.begin(), c.colliders_now.end(), c.colliders_before.begin());
  std::copy(c.colliders_now.begin(), c.colliders_now.end(), c.colliders_older.begin());
  c.world_before = c.world_state = c.world_older = in.model_to_world;
  c.banked = 0.0f;
  c.dt_before = 0.0f;
  c.history = 0;
  c.started = true;
  ++c.restarts;
}

/// The world frame at weights w: translation and scale on the parabola, the rotation the
/// normalized blend of the three quaternions (each on the last one's hemisphere).
Frame frame_at(const Frame& older, const Frame& before, const Frame& now, const Weights& w) {
  const glm::quat qo = glm::dot(older.rotation, now.rotation) < 0.0f ? -older.rotation : older.rotation;
  const glm::quat qb = glm::dot(before.rotation, now.rotation) < 0.0f ? -before.rotation : before.rotation;
  Frame f;
  f.rotation = glm::normalize(qo * w.older + qb * w.before + now.rotation * w.now);
  f.translation = w.of(older.translation, before.translation, now.translation);
  f.scale = older.scale * w.older + before.scale * w.before + now.scale * w.now;
  return f;
}

/// The output: free particles carried `ahead` substeps further along their velocity and by the
/// world's motion since the last substep, then held to this update's limits and colliders; fixed
/// particles at their skinned positions; normals: area-weighted sums over the triangles, unit length.
void write_output(ClothInstance& c, const ClothInput& in, float ahead, const Carry& rest_of_frame) {
  const ClothParticles& p = c.particles;
  const size_t n = p.size();
  const glm::mat3 r = glm::mat3_cast(rest_of_frame.rotation);
  for (size_t i = 0; i < n; ++i) {
    if (p.w[i] == 0.0f) {
      c.out_positions[i] = in.skinned_positions[i];
      continue;
    }
    const glm::vec3 x = p.at(i);
    glm::vec3 o = x + (x - p.before(i)) * ahead;
    if (!rest_of_frame.identity) o = r * o + rest_of_frame.translation;
    c.out_positions[i] = o;
  }
  // Tethers, limits and colliders at this update's pose, on the output positions: the fixed
  // particles are at this update's skinned pose while the free ones were carried forward from the
  // last substep, so a fast (or discontinuous) pose would otherwise stretch the output. The
  // carrying itself stretches tethers by a hair, so the output holds them at 1 % over their
  // length (most need no square root then).
  const ClothSource& s = c.source;
  const float scale = c.settings.tether_scale * 1.01f;
  for (const fb::ClothTether& t : s.tethers) {
    if (p.w[t.particle()] == 0.0f) continue;
    hold_within(c.out_positions[t.particle()], c.out_positions[t.anchor()], t.length() * scale);
  }
  for (size_t i = 0; i < n && !(s.max_distances.empty() && s.backstops.empty()); ++i) {
    if (p.w[i] == 0.0f) continue;
    glm::vec3& at = c.out_positions[i];
    const glm::vec3& anchor = in.skinned_positions[i];
    if (!s.max_distances.empty()) {
      const float limit = s.max_distances[i];
      const glm::vec3 d = at - anchor;
      const float len2 = glm::dot(d, d);
      if (len2 > limit * limit) at = anchor + d * (limit / std::sqrt(len2));
    }
    if (!s.backstops.empty() && !in.skinned_normals.empty()) {
      const glm::vec3& nrm = in.skinned_normals[i];
      const float depth = glm::dot(at - anchor, nrm);
      if (depth < -s.backstops[i]) at -= nrm * (depth + s.backstops[i]);
    }
  }
  set_collider_step(c, Weights{}, true);
  const auto push = [&](size_t i) {
    if (p.w[i] != 0.0f) push_out(c, c.out_positions[i], p.at(i));
  };
  size_t next = 0;
#if OSSA_HAVE_VECTOR_CLONES
  if (detail::cloth_kernels_selected() && !s.colliders.empty()) {
    for (; next + 8 <= n; next += 8)
      detail::push_out_colliders8(c.out_positions.data(), p, next, c.collider_step.data(), s.colliders.size());
  }
#endif
  if (!s.colliders.empty())
    for (; next < n; ++next) push(next);
  // Normals: area-weighted sums over the triangles, then unit length.
  // Each particle sums its triangles' normals in the triangles' order (from its corner list),
  // rather than each triangle adding to its corners: those adds would wait on each other's stores.
  const auto& tri = s.triangles;
  for (size_t t = 0; 3 * t + 2 < tri.size(); ++t) {
    const glm::vec3& pa = c.out_positions[tri[3 * t]];
    c.triangle_normals[t] = glm::cross(c.out_positions[tri[3 * t + 1]] - pa, c.out_positions[tri[3 * t + 2]] - pa);
  }
  for (size_t i = 0; i < n; ++i) {
    glm::vec3 nrm(0.0f);
    for (uint32_t k = c.corner_start[i]; k < c.corner_start[i + 1]; ++k) nrm += c.triangle_normals[c.corners[k]];
    c.out_normals[i] = nrm;
    const float len2 = glm::dot(nrm, nrm);
    if (len2 > 1e-30f) c.out_normals[i] *= 1.0f / std::sqrt(len2);
    else c.out_normals[i] = in.skinned_normals.empty() ? glm::vec3(0.0f, 1.0f, 0.0f) : in.skinned_normals[i];
  }
}

float rotation_angle(const glm::quat& a, const glm::quat& b) {
  const float d = std::min(1.0f, std::fabs(glm::dot(a, b)));
  return 2.0f * std::acos(d);
}

}  // namespace

Status update_cloth(ClothInstance& c, const ClothInput& in) {
  const size_t n = c.particles.size();
  if (in.skinned_positions.size() < n)
    return Error{detail::format("cloth: %zu skinned positions for %zu particles", in.skinned_positions.size(), n)};
  const bool needs_normals = !c.source.backstops.empty() || c.settings.drag > 0.0f;
  if (!in.skinned_normals.empty() ? in.skinned_normals.size() < n : needs_normals)
    return Error{detail::format("cloth: %zu skinned normals for %zu particles (backstops and drag need them)",
                                in.skinned_normals.size(), n)};
  if (!std::isfinite(in.dt) || in.dt < 0.0f) return Error{"cloth: dt must be a finite number >= 0"};
  if (!finite_matrix(in.model_to_world)) return Error{"cloth: model_to_world is not finite"};
  if (Status st = check_cloth_settings(c.settings); !st) return st;

  place_colliders(c, in.model);
  const ClothSettings& s = c.settings;
  const Frame now = frame_of(in.model_to_world);
  const Frame before = frame_of(c.world_before);
  const bool jumped =
      c.started &&
      ((s.teleport_distance > 0.0f && glm::length(now.translation - before.translation) > s.teleport_distance) ||
       (s.teleport_angle > 0.0f && rotation_angle(now.rotation, before.rotation) > s.teleport_angle));
  if (!c.started || jumped) restart(c, in);
  const Frame start = frame_of(c.world_before);

  const float h = s.substep;
  const float banked_before = c.banked;
  const float total = banked_before + in.dt;
  int steps = static_cast<int>(std::floor(total / h));
  c.banked = total - static_cast<float>(steps) * h;
  // Rounding can leave a whole substep banked (three 1/144 s frames are five 1/240 s substeps, and
  // the float sum falls a hair short): take it now, or the output trails its input by a substep
  // and a jump in the skinned pose shows in it for a frame.
  if (c.banked >= h * (1.0f - 1e-4f)) {
    ++steps;
    c.banked = 0.0f;
  }
  if (steps > kMaxSubsteps) {
    steps = kMaxSubsteps;
    c.banked = 0.0f;
  }
  if (c.banked < 0.0f) c.banked = 0.0f;
  Step st;
  st.h = h;
  st.keep = std::exp(-s.damping * h);
  st.drag = s.drag > 0.0f ? 1.0f - std::exp(-s.drag * h) : 0.0f;
  st.max_step = s.max_speed * h;
  Frame last = frame_of(c.world_state);
  const Frame older = frame_of(c.world_older);
  const bool quadratic = c.history >= 2;
  for (int k = 1; k <= steps; ++k) {
    const float into = static_cast<float>(k) * h - banked_before;  // seconds into this update
    st.f = in.dt > 0.0f ? std::clamp(into / in.dt, 0.0f, 1.0f) : 1.0f;
    st.w = weights_at(std::clamp(into, 0.0f, in.dt), in.dt, c.dt_before, quadratic);
    const Frame at = frame_at(older, start, now, st.w);
    // With the kernels and no drag, the prediction kernel carries the blocks of eight on its way
    // (the same operations, one pass less over the particles).
    const Carry k_carry = carry(last, at, s);
    const bool fuse = detail::cloth_kernels_selected() && !(st.drag > 0.0f) && !k_carry.identity;
    st.carried = !fuse;
    if (fuse) {
      st.carry_r = glm::mat3_cast(k_carry.rotation);
      st.carry_t = k_carry.translation;
    }
    apply_carry(c, k_carry, fuse ? n & ~size_t{7} : 0);
    st.gravity_h2 = to_model(at, s.gravity) * (h * h);
    st.wind_h = to_model(at, s.wind) * h;
    substep(c, in, st);
    last = at;
  }
  // The inputs' history moves on when time did.
  if (in.dt > 0.0f || c.history == 0) {
    for (size_t i = 0; i < n; ++i) {
      c.skinned_older[i] = c.skinned_before[i];
      c.skinned_before[i] = in.skinned_positions[i];
    }
    std::copy(c.colliders_before.begin(), c.colliders_before.end(), c.colliders_older.begin());
    std::copy(c.colliders_now.begin(), c.colliders_now.end(), c.colliders_before.begin());
    c.world_older = c.world_before;
    c.world_before = in.model_to_world;
    c.dt_before = in.dt;
    c.history = std::min<uint32_t>(c.history + 1, 2);
  }
  for (size_t i = 0; i < n; ++i)
    c.skinned_normal_before[i] = in.skinned_normals.empty() ? glm::vec3(0.0f) : in.skinned_normals[i];
  c.world_state = matrix_of(last);
  write_output(c, in, c.banked / h, carry(last, now, s));
  return {};
}

}  // namespace ossa
