// cloth_kernels.h — the cloth solver's eight-wide kernels (AVX2), internal to runtime/anim.
//
// Every pass of a substep (cloth_solve.cpp) is a loop over particles or constraints whose scalar
// form is dominated by loads, stores and one square root or division each; eight at a time in
// 256-bit registers it costs well under half (ossa-bench-cloth, docs/CLOTH.md):
// - edges and tethers: a run of them that share no particle (the cooker colours edges;
//   make_cloth_instance finds the runs and regroups each: ClothWideList) is projected eight at once with exactly the
//   result of projecting them one by one, since none reads what another writes; the particles are planes
//   (ClothParticles), so a group whose ends are consecutive particles (most of a grid's) costs plain loads and
//   stores, and no transposes;
// - the world's carry and the prediction (without drag: with it a particle reads its neighbours'
//   new positions, so that stays scalar): particles do not interact;
// - colliders: a block of eight particles goes through every collider in turn (each particle meets
//   the colliders in the scalar loop's order; particles do not interact there), and a collider
//   whose bounding sphere holds none of the eight is skipped after a few operations.
// Every operation is the scalar code's, in its order, with no FMA, so the AVX2 copy and the
// scalar path give the same bits (Cloth.VectorAndScalarPathsAgreeBitForBit). Built only where
// the per-joint loops' AVX2 copy is (internal/vector_clones.h), and used when that copy is
// selected (ossa/anim/vector_isa.h); elsewhere the solver runs its scalar loops.
#pragma once
#include <cstddef>
#include <cstdint>

#include <glm/glm.hpp>

#include <ossa/anim/cloth.h>
#include <ossa/format/ossa_generated.h>

namespace ossa::detail {

/// True when this build has the kernels below and the AVX2 copy is selected (vector_isa). The
/// kernels are defined only where OSSA_HAVE_VECTOR_CLONES (internal/vector_clones.h) is 1.
bool cloth_kernels_selected();

/// How a wide list's group of eight lanes (ClothWideList) finds its ends, a being the group's
/// first lane's a: kBlocks, lanes a + l and b + l (b: the first lane's b); kPairs1 and kPairs2,
/// the sixteen particles a .. a + 15 joined in pairs 1 or 2 apart, two loads and one shuffle per
/// end and coordinate (cloth_setup.cpp's kPairOffsets give the lanes' order); kGather, any ends
/// (gathered, and stored one by one).
enum WideKind : uint8_t { kGather = 0, kBlocks = 1, kPairs1 = 2, kPairs2 = 3 };

/// Projects a wide list (ClothInstance::wide_*) on the particles' current positions: each run's
/// groups eight at a time, then its last few lanes, every lane as cloth_solve.cpp's project_edge
/// (with XPBD multipliers, one per lane, when lambda is not null), or, with `tethers`, as
/// project_tether with lengths times tether_scale: the scalar loop's bits, since the constraints
/// of a run share no particle. O(lanes).
void project_wide(ClothParticles& p, const ClothWideList& list, bool tethers, float alpha, float tether_scale,
                  float* lambda);

/// Particles [0, count) (count a multiple of 8), now and before, moved to r * p + t. O(count).
void carry_particles8(ClothParticles& p, size_t count, const glm::mat3& r, const glm::vec3& t);

/// The prediction of particles first .. first + 7 without drag (cloth_solve.cpp's predict):
/// free ones get previous = x, x += (x - previous) * keep + gravity (the step clamped to max_step
/// when it is > 0); with r, all are first carried as carry_particles8 carries them. Returns the
/// fixed lanes (w == 0), left for the caller. O(1).
uint32_t predict_particles8(ClothParticles& p, size_t first, float keep, const glm::vec3& gravity, float max_step,
                            const glm::mat3* r, const glm::vec3& t);

/// Pushes particles first .. first + 7 (first + 8 <= particle count; free ones, w != 0) out of
/// each collider in turn, as cloth_solve.cpp's push_out does, the previous position giving the
/// side a particle exactly on an axis goes out to. `step`: 3 vec4 per collider (ClothInstance::
/// collider_step: end a with the reach in w, end b, bounding sphere centre with its radius^2).
/// O(count).
void push_out_colliders8(ClothParticles& p, size_t first, const glm::vec4* step, size_t count);

/// The same for the points out[first .. first + 7], free where the particle is and going out
/// towards its current position. O(count).
void push_out_colliders8(glm::vec3* out, const ClothParticles& state, size_t first, const glm::vec4* step,
                         size_t count);

}  // namespace ossa::detail
