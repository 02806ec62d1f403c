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
// Layout: a particle is one vec4 (xyz, inverse mass in w), so a constraint loads two vec4s; the
// cooker stores edges greedily coloured, so neighbouring constraints touch different particles and
// the CPU overlaps them. With one iteration (the default: small steps) the XPBD multiplier starts
// at zero every substep and is never read back, so that loop keeps no multipliers at all.
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
};

void apply_carry(ClothInstance& c, const Carry& k) {
  if (k.identity) return;
  const glm::mat3 r = glm::mat3_cast(k.rotation);
  const size_t n = c.current.size();
  size_t i = 0;
#if OSSA_HAVE_VECTOR_CLONES
  if (detail::cloth_kernels_selected()) {
    i = n & ~size_t{7};
    detail::carry_particles8(c.current.data(), c.previous.data(), i, r, k.translation);
  }
#endif
  for (; i < n; ++i) {
    glm::vec4& x = c.current[i];
    glm::vec4& p = c.previous[i];
    const glm::vec3 xn = r * xyz(x) + k.translation, pn = r * xyz(p) + k.translation;
    x = glm::vec4(xn, x.w);
    p = glm::vec4(pn, p.w);
  }
}

/// Particle i's prediction (see predict).
OSSA_INLINE void predict_one(ClothInstance& c, size_t i, std::span<const glm::vec3> skinned, const Step& st) {
  glm::vec4& x = c.current[i];
  glm::vec4& p = c.previous[i];
  if (x.w == 0.0f) {
    p = x;
    x = glm::vec4(st.w.of(c.skinned_older[i], c.skinned_before[i], skinned[i]), 0.0f);
    return;
  }
  const glm::vec3 at = xyz(x);
  glm::vec3 v = (at - xyz(p)) * st.keep;
  if (st.drag > 0.0f) {
    // The wind's drag along the normal of a triangle the particle is a corner of, from the
    // current positions (the particles before i already predicted, as the loop goes).
    const uint16_t* f = &c.facing[3 * i];
    const glm::vec3 a = xyz(c.current[f[0]]);
    glm::vec3 nrm = glm::cross(xyz(c.current[f[1]]) - a, xyz(c.current[f[2]]) - a);
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
  p = glm::vec4(at, p.w);
  x = glm::vec4(at + v, x.w);
}

/// Damped velocity, the wind's drag, gravity and the speed limit for free particles; fixed ones
/// step to their skinned position. Without drag the particles do not read each other, and the
/// kernel takes eight at a time.
void predict(ClothInstance& c, std::span<const glm::vec3> skinned, const Step& st) {
  const size_t n = c.current.size();
  size_t i = 0;
#if OSSA_HAVE_VECTOR_CLONES
  if (detail::cloth_kernels_selected() && !(st.drag > 0.0f)) {
    for (; i + 8 <= n; i += 8)
      for (uint32_t fixed =
               detail::predict_particles8(c.current.data(), c.previous.data(), i, st.keep, st.gravity_h2, st.max_step);
           fixed != 0; fixed &= fixed - 1)
        predict_one(c, i + static_cast<size_t>(__builtin_ctz(fixed)), skinned, st);
  }
#endif
  for (; i < n; ++i) predict_one(c, i, skinned, st);
}

/// One XPBD distance constraint. kLambda: keep its multiplier across iterations (iterations > 1).
template <bool kLambda>
OSSA_INLINE void project_edge(glm::vec4* x, const fb::ClothEdge& e, float alpha, float* lambda) {
  glm::vec4& a = x[e.a()];
  glm::vec4& b = x[e.b()];
  const float wsum = a.w + b.w;
  const glm::vec3 d(b.x - a.x, b.y - a.y, b.z - a.z);
  const float len2 = glm::dot(d, d);
  if (!(len2 > 1e-24f) || wsum == 0.0f) return;
  const float len = std::sqrt(len2);
  const float violation = len - e.rest();
  float s;  // the correction per unit of d: dl / len, in one division where no multiplier is kept
  if constexpr (kLambda) {
    const float dl = (-violation - alpha * *lambda) / (wsum + alpha);
    *lambda += dl;
    s = dl / len;
  } else {
    s = -violation / ((wsum + alpha) * len);
  }
  const glm::vec3 corr = d * s;
  a.x -= a.w * corr.x;
  a.y -= a.w * corr.y;
  a.z -= a.w * corr.z;
  b.x += b.w * corr.x;
  b.y += b.w * corr.y;
  b.z += b.w * corr.z;
}

/// Visits [0, count) in order: `one(k)` for a single constraint; with the eight-wide kernels,
/// `eight(k, n)` for the first multiple of 8 of each run of constraints that share no particle
/// (`runs`: where each ends) and `one` for the run's last few, which gives the same bits as the
/// stored order (no constraint of a run reads what another writes).
template <typename Eight, typename One>
OSSA_INLINE void by_runs(size_t count, std::span<const uint32_t> runs, bool wide, Eight eight, One one) {
  size_t k = 0;
#if OSSA_HAVE_VECTOR_CLONES
  if (wide) {
    for (const uint32_t end : runs) {
      const size_t n = (end - k) & ~size_t{7};
      if (n > 0) eight(k, n);
      for (k += n; k < end; ++k) one(k);
    }
  }
#else
  (void)runs;
  (void)wide;
  (void)eight;
#endif
  for (; k < count; ++k) one(k);
}

template <bool kLambda>
void project_edges(glm::vec4* x, std::span<const fb::ClothEdge> edges, std::span<const uint32_t> runs, float alpha,
                   float* lambda, bool wide) {
  by_runs(
      edges.size(), runs, wide,
      [&]([[maybe_unused]] size_t k, [[maybe_unused]] size_t n) {
#if OSSA_HAVE_VECTOR_CLONES
        detail::project_edges8(x, edges.data() + k, n, alpha, kLambda ? lambda + k : nullptr);
#endif
      },
      [&](size_t k) { project_edge<kLambda>(x, edges[k], alpha, kLambda ? lambda + k : nullptr); });
}

/// Moves `p` onto the sphere of radius `limit` around `anchor` when it is outside it (a tether).
OSSA_INLINE bool hold_within(glm::vec3& p, const glm::vec3& anchor, float limit) {
  const glm::vec3 d = p - anchor;
  const float len2 = glm::dot(d, d);
  if (len2 <= limit * limit) return false;
  p = anchor + d * (limit / std::sqrt(len2));
  return true;
}

OSSA_INLINE void project_tether(glm::vec4* x, const fb::ClothTether& t, float scale) {
  glm::vec4& p = x[t.particle()];
  if (p.w == 0.0f) return;
  glm::vec3 at = xyz(p);
  if (hold_within(at, xyz(x[t.anchor()]), t.length() * scale)) p = glm::vec4(at, p.w);
}

void project_tethers(glm::vec4* x, std::span<const fb::ClothTether> tethers, std::span<const uint32_t> runs,
                     float scale, bool wide) {
  by_runs(
      tethers.size(), runs, wide,
      [&]([[maybe_unused]] size_t k, [[maybe_unused]] size_t n) {
#if OSSA_HAVE_VECTOR_CLONES
        detail::project_tethers8(x, tethers.data() + k, n, scale);
#endif
      },
      [&](size_t k) { project_tether(x, tethers[k], scale); });
}

/// Max distance and backstop against the skinned pose `f` of the way through this update.
void project_limits(ClothInstance& c, std::span<const glm::vec3> skinned, std::span<const glm::vec3> normals,
                    const Step& st) {
  const float f = st.f;
  const ClothSource& s = c.source;
  if (s.max_distances.empty() && s.backstops.empty()) return;
  const size_t n = c.current.size();
  for (size_t i = 0; i < n; ++i) {
    glm::vec4& x = c.current[i];
    if (x.w == 0.0f) continue;
    const glm::vec3 anchor = st.w.of(c.skinned_older[i], c.skinned_before[i], skinned[i]);
    glm::vec3 at = xyz(x);
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
    x = glm::vec4(at, x.w);
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
  const size_t n = c.current.size();
  const auto push = [&](size_t i) {
    glm::vec4& x = c.current[i];
    if (x.w == 0.0f) return;
    glm::vec3 at = xyz(x);
    push_out(c, at, xyz(c.previous[i]));
    x = glm::vec4(at, x.w);
  };
  size_t next = 0;
#if OSSA_HAVE_VECTOR_CLONES
  if (wide) {
    for (; next + 8 <= n; next += 8)
      detail::push_out_colliders8(c.current.data(), c.previous.data(), next, c.collider_step.data(), count);
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
  glm::vec4* x = c.current.data();
  const ClothSource& src = c.source;
  if (s.iterations > 1) std::fill(c.lambda.begin(), c.lambda.end(), 0.0f);
  const bool wide = detail::cloth_kernels_selected();
  set_collider_step(c, st.w);
  for (uint32_t it = 0; it < s.iterations; ++it) {
    if (s.iterations > 1) {
      project_edges<true>(x, src.stretch, c.stretch_runs, stretch_alpha, c.lambda.data(), wide);
      project_edges<true>(x, src.bend, c.bend_runs, bend_alpha, c.lambda.data() + src.stretch.size(), wide);
    } else {
      project_edges<false>(x, src.stretch, c.stretch_runs, stretch_alpha, nullptr, wide);
      project_edges<false>(x, src.bend, c.bend_runs, bend_alpha, nullptr, wide);
    }
    project_tethers(x, src.tethers, c.tether_runs, s.tether_scale, wide);
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
  const size_t n = c.current.size();
  for (size_t i = 0; i < n; ++i) {
    c.current[i] = glm::vec4(in.skinned_positions[i], c.current[i].w);
    c.previous[i] = c.current[i];
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
/// particles at their skinned positions; normals from the triangles.
void write_output(ClothInstance& c, const ClothInput& in, float ahead, const Carry& rest_of_frame) {
  const size_t n = c.current.size();
  const glm::mat3 r = glm::mat3_cast(rest_of_frame.rotation);
  for (size_t i = 0; i < n; ++i) {
    const glm::vec4& x = c.current[i];
    if (x.w == 0.0f) {
      c.out_positions[i] = in.skinned_positions[i];
      continue;
    }
    glm::vec3 o = xyz(x) + (xyz(x) - xyz(c.previous[i])) * ahead;
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
    if (c.current[t.particle()].w == 0.0f) continue;
    hold_within(c.out_positions[t.particle()], c.out_positions[t.anchor()], t.length() * scale);
  }
  for (size_t i = 0; i < n; ++i) {
    if (c.current[i].w == 0.0f) continue;
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
    if (c.current[i].w != 0.0f) push_out(c, c.out_positions[i], xyz(c.current[i]));
  };
  size_t next = 0;
#if OSSA_HAVE_VECTOR_CLONES
  if (detail::cloth_kernels_selected() && !s.colliders.empty()) {
    for (; next + 8 <= n; next += 8)
      detail::push_out_colliders8(c.out_positions.data(), c.current.data(), next, c.collider_step.data(),
                                  s.colliders.size());
  }
#endif
  if (!s.colliders.empty())
    for (; next < n; ++next) push(next);
  // Normals: area-weighted sums over the triangles, then unit length.
  std::fill(c.out_normals.begin(), c.out_normals.end(), glm::vec3(0.0f));
  const auto& tri = s.triangles;
  for (size_t t = 0; t + 2 < tri.size(); t += 3) {
    const glm::vec3& pa = c.out_positions[tri[t]];
    const glm::vec3 nrm = glm::cross(c.out_positions[tri[t + 1]] - pa, c.out_positions[tri[t + 2]] - pa);
    c.out_normals[tri[t]] += nrm;
    c.out_normals[tri[t + 1]] += nrm;
    c.out_normals[tri[t + 2]] += nrm;
  }
  for (size_t i = 0; i < n; ++i) {
    glm::vec3& nrm = c.out_normals[i];
    const float len2 = glm::dot(nrm, nrm);
    if (len2 > 1e-30f) nrm *= 1.0f / std::sqrt(len2);
    else nrm = in.skinned_normals.empty() ? glm::vec3(0.0f, 1.0f, 0.0f) : in.skinned_normals[i];
  }
}

float rotation_angle(const glm::quat& a, const glm::quat& b) {
  const float d = std::min(1.0f, std::fabs(glm::dot(a, b)));
  return 2.0f * std::acos(d);
}

}  // namespace

Status update_cloth(ClothInstance& c, const ClothInput& in) {
  const size_t n = c.current.size();
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
    apply_carry(c, carry(last, at, s));
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
