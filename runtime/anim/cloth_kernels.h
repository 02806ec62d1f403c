// cloth_kernels.h — the cloth solver's eight-wide kernels (AVX2), internal to runtime/anim.
//
// Every pass of a substep (cloth_solve.cpp) is a loop over particles or constraints whose scalar
// form is dominated by loads, stores and one square root or division each; eight at a time in
// 256-bit registers it costs well under half (ossa-bench-cloth, docs/CLOTH.md):
// - edges and tethers: a run of them that share no particle (the cooker colours edges;
//   make_cloth_instance finds the runs) is projected eight at once with exactly the result of
//   projecting them one by one, since none reads what another writes;
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

#include <ossa/format/ossa_generated.h>

namespace ossa::detail {

/// True when this build has the kernels below and the AVX2 copy is selected (vector_isa). The
/// kernels are defined only where OSSA_HAVE_VECTOR_CLONES (internal/vector_clones.h) is 1.
bool cloth_kernels_selected();

/// Projects edges[0 .. count) (count a multiple of 8, no particle in two of them) as
/// cloth_solve.cpp's project_edges does, with XPBD multipliers `lambda` (one per edge) when not
/// null. O(count).
void project_edges8(glm::vec4* x, const fb::ClothEdge* edges, size_t count, float alpha, float* lambda);

/// Projects tethers[0 .. count) (count a multiple of 8, no particle in two of them) as
/// cloth_solve.cpp's project_tethers does, their lengths times `scale`. O(count).
void project_tethers8(glm::vec4* x, const fb::ClothTether* tethers, size_t count, float scale);

/// x and previous [0 .. count) (count a multiple of 8) moved to r * p + t, w kept. O(count).
void carry_particles8(glm::vec4* x, glm::vec4* previous, size_t count, const glm::mat3& r, const glm::vec3& t);

/// The prediction of particles first .. first + 7 without drag (cloth_solve.cpp's predict):
/// free ones get previous = x, x += (x - previous) * keep + gravity (the step clamped to max_step
/// when it is > 0). Returns the fixed lanes (w == 0), left for the caller. O(1).
uint32_t predict_particles8(glm::vec4* x, glm::vec4* previous, size_t first, float keep, const glm::vec3& gravity,
                            float max_step);

/// Pushes particles first .. first + 7 (first + 8 <= particle count; free ones, w != 0) out of
/// each collider in turn, as cloth_solve.cpp's push_out does, `previous` giving the side a
/// particle exactly on an axis goes out to. `step`: 3 vec4 per collider (ClothInstance::
/// collider_step: end a with the reach in w, end b, bounding sphere centre with its radius^2).
/// O(count).
void push_out_colliders8(glm::vec4* x, const glm::vec4* previous, size_t first, const glm::vec4* step, size_t count);

/// The same for vec3 points, free where `state`'s w != 0 and going out towards `state`'s xyz. O(count).
void push_out_colliders8(glm::vec3* p, const glm::vec4* state, size_t first, const glm::vec4* step, size_t count);

}  // namespace ossa::detail
