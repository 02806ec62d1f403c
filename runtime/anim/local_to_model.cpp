// local_to_model.cpp — local SoA pose -> one model-space glm::mat4 per joint (pose_ops.h).
//
// Two halves per block of kPoseLanes joints:
//  1. TRS -> affine 3x4 for the 8 lanes at once (quaternion to rotation matrix, times scale, plus
//     translation), a lane loop that vectorizes like the blend kernels (8-wide in the avx2 clone);
//     the result sits in a 384-byte stack block, so nothing is allocated.
//  2. The parent chain, joint by joint in skeleton order (parents[i] < i, so the parent's model
//     matrix is final when its child is reached): model_i = model_parent * local_i, an affine
//     product written by hand: each output column is a sum of the parent's first three columns
//     weighted by the local column (plus the parent's translation for column 3), i.e. 12
//     4-wide multiplies and 9 adds. GLM's generic mat4 product treats the bottom row as data,
//     and building each local mat4 with glm::translate * mat4_cast * scale is three more
//     products (bench/bench_anim_pose.cpp, BM_GlmLocalToModel, measures that path: ~10x slower).
// The affine product uses SSE (x86-64 baseline) when available, plain scalar code elsewhere;
// avx2 clone or not, the same IEEE operations run in the same order, so results are identical
// on every x86-64 machine.
//
// A joint whose parent index is not in [0, i) (a root, or a parents array that was never
// validated) is treated as a root: a bad skeleton yields a wrong pose, never an out-of-bounds read.
#include <algorithm>
#include <cstddef>

#include <ossa/anim/pose_ops.h>
#include "internal/float_env.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#include "internal/vector_clones.h"
#endif

namespace ossa {

namespace {

constexpr size_t kLanes = kPoseLanes;

/// Local affine matrices of 8 lanes, column-major 3x4: a[c * 3 + r][l] is row r of column c.
using AffineLanes = float[12][kLanes];

OSSA_INLINE void affine_lanes(ConstPoseSpan local, size_t first, AffineLanes& a) {
  const float* base = local.base + first;
  const size_t s = local.stride;
  const float *tx = base + kTx * s, *ty = base + kTy * s, *tz = base + kTz * s;
  const float *rx = base + kRx * s, *ry = base + kRy * s, *rz = base + kRz * s, *rw = base + kRw * s;
  const float *sx = base + kSx * s, *sy = base + kSy * s, *sz = base + kSz * s;
  for (size_t l = 0; l < kLanes; ++l) {
    // The unit-quaternion rotation matrix (as glm::mat3_cast), columns scaled by the scale.
    const float x = rx[l], y = ry[l], z = rz[l], w = rw[l];
    const float x2 = x + x, y2 = y + y, z2 = z + z;
    const float xx = x * x2, yy = y * y2, zz = z * z2;
    const float xy = x * y2, xz = x * z2, yz = y * z2;
    const float wx = w * x2, wy = w * y2, wz = w * z2;
    const float scx = sx[l], scy = sy[l], scz = sz[l];
    a[0][l] = scx * (1.0f - (yy + zz));
    a[1][l] = scx * (xy + wz);
    a[2][l] = scx * (xz - wy);
    a[3][l] = scy * (xy - wz);
    a[4][l] = scy * (1.0f - (xx + zz));
    a[5][l] = scy * (yz + wx);
    a[6][l] = scz * (xz + wy);
    a[7][l] = scz * (yz - wx);
    a[8][l] = scz * (1.0f - (xx + yy));
    a[9][l] = tx[l];
    a[10][l] = ty[l];
    a[11][l] = tz[l];
  }
}

// A model matrix in registers: the four columns, bottom row 0 0 0 1 (every matrix here is
// affine). Keeping the last joint's matrix in registers matters: in a depth-first skeleton most
// joints are the child of the joint just before them, and reloading the parent from the matrix
// just stored would put a store-to-load forwarding delay on the chain of dependent products.
#if defined(__SSE2__)
struct Columns {
  __m128 c0, c1, c2, c3;
};

OSSA_INLINE Columns load_columns(const float* m) {
  return {_mm_loadu_ps(m), _mm_loadu_ps(m + 4), _mm_loadu_ps(m + 8), _mm_loadu_ps(m + 12)};
}

OSSA_INLINE void store_columns(const Columns& m, float* out) {
  _mm_storeu_ps(out, m.c0);
  _mm_storeu_ps(out + 4, m.c1);
  _mm_storeu_ps(out + 8, m.c2);
  _mm_storeu_ps(out + 12, m.c3);
}

OSSA_INLINE Columns identity_columns() {
  return {_mm_setr_ps(1, 0, 0, 0), _mm_setr_ps(0, 1, 0, 0), _mm_setr_ps(0, 0, 1, 0), _mm_setr_ps(0, 0, 0, 1)};
}

/// (p.c0 * x + p.c1 * y) + p.c2 * z: one column of the affine product; the two-level sum keeps
/// the dependent chain at one multiply and two adds.
OSSA_INLINE __m128 combine(const Columns& p, float x, float y, float z) {
  return _mm_add_ps(_mm_add_ps(_mm_mul_ps(p.c0, _mm_set1_ps(x)), _mm_mul_ps(p.c1, _mm_set1_ps(y))),
                    _mm_mul_ps(p.c2, _mm_set1_ps(z)));
}

/// parent * local (lane l of `a`), both affine: column c of the product is parent.c0 * a(0,c) +
/// parent.c1 * a(1,c) + parent.c2 * a(2,c) (+ parent.c3 for c = 3); the bottom row comes out
/// 0 0 0 1 by itself. 12 multiplies and 9 adds, 4 wide.
OSSA_INLINE Columns mul_affine(const Columns& p, const AffineLanes& a, size_t l) {
  return {combine(p, a[0][l], a[1][l], a[2][l]), combine(p, a[3][l], a[4][l], a[5][l]),
          combine(p, a[6][l], a[7][l], a[8][l]), _mm_add_ps(combine(p, a[9][l], a[10][l], a[11][l]), p.c3)};
}
#else
struct Columns {
  float m[16];
};

OSSA_INLINE Columns load_columns(const float* m) {
  Columns c;
  for (int k = 0; k < 16; ++k) c.m[k] = m[k];
  return c;
}

OSSA_INLINE void store_columns(const Columns& m, float* out) {
  for (int k = 0; k < 16; ++k) out[k] = m.m[k];
}

OSSA_INLINE Columns identity_columns() { return {{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}}; }

OSSA_INLINE Columns mul_affine(const Columns& p, const AffineLanes& a, size_t l) {
  Columns out;
  for (int col = 0; col < 4; ++col)
    for (int r = 0; r < 4; ++r) {
      const float v = (p.m[r] * a[col * 3 + 0][l] + p.m[4 + r] * a[col * 3 + 1][l]) + p.m[8 + r] * a[col * 3 + 2][l];
      out.m[col * 4 + r] = col == 3 ? v + p.m[12 + r] : v;
    }
  return out;
}
#endif

}  // namespace

OSSA_INLINE static void local_to_model_body(std::span<const int16_t> parents, ConstPoseSpan local,
                                            std::span<glm::mat4> out_model) {
  const detail::FlushDenormals flush;  // internal/float_env.h
  const size_t n = std::min({size_t(local.joint_count), parents.size(), out_model.size()});
  AffineLanes a;
  Columns previous{};  // model matrix of joint i - 1
  for (size_t first = 0; first < n; first += kLanes) {
    affine_lanes(local, first, a);  // whole lanes: padding is identity, and within the stride
    const size_t count = std::min(kLanes, n - first);
    for (size_t l = 0; l < count; ++l) {
      const size_t i = first + l;
      const int p = parents[i];
      // Only the parent is chosen per case; a root multiplies the identity (exact), so the local
      // matrix's scalars are read once, after the branches, straight into broadcasts.
      Columns parent;
      if (p >= 0 && size_t(p) + 1 == i) parent = previous;
      else if (p >= 0 && size_t(p) < i) parent = load_columns(&out_model[size_t(p)][0][0]);  // 16 contiguous floats
      else parent = identity_columns();
      const Columns model = mul_affine(parent, a, l);
      store_columns(model, &out_model[i][0][0]);
      previous = model;
    }
  }
}

OSSA_VECTOR_DISPATCH(local_to_model,
                     (std::span<const int16_t> parents, ConstPoseSpan local, std::span<glm::mat4> out_model),
                     (parents, local, out_model))

}  // namespace ossa
