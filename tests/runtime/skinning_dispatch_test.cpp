// skinning_dispatch_test.cpp — the CPU dispatch of skin_cpu's hand-vectorized paths, on a
// synthetic file (no cooker), so it is part of the runtime suites and also runs in the Windows
// cross build under Wine: there, it proves that the AVX2 / AVX-512 kernels compiled by MinGW-w64
// (target attributes, -Wa,-muse-unaligned-vector-move) run and agree with the portable path, and
// that the run-time feature query (internal/cpu.h) works. The full skinning suite (skinning_test)
// needs cooked meshes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <ossa/loader/asset.h>
#include <ossa/skinning/skinning.h>
#include "test_files.h"

namespace ossa {
namespace {

const char* isa_name(SkinningIsa isa) {
  switch (isa) {
    case SkinningIsa::Portable: return "portable";
    case SkinningIsa::Avx2: return "avx2";
    case SkinningIsa::Avx512: return "avx512";
  }
  return "?";
}

/// Restores the process-wide choice when a test ends.
struct IsaGuard {
  SkinningIsa saved = skinning_isa();
  ~IsaGuard() { set_skinning_isa(saved); }
};

TEST(SkinningDispatch, EveryAvailablePathMatchesPortable) {
  const IsaGuard guard;
  // More vertices than one batch, with the cooker's quantized layout (the fast paths' input).
  test::SyntheticSpec spec;
  std::vector<test::SyntheticVertex>& vertices = spec.meshes[0].vertices;
  const std::vector<test::SyntheticVertex> base = vertices;
  for (int copy = 1; copy < 50; ++copy)
    for (test::SyntheticVertex v : base) {
      v.position = fb::Vec3(v.position.x() + 0.01f * copy, v.position.y(), v.position.z() - 0.02f * copy);
      vertices.push_back(v);
    }
  const std::vector<uint8_t> bytes = test::make_valid_file(spec);
  auto asset = Asset::from_bytes(bytes, "skin.ossa");
  ASSERT_TRUE(asset.ok()) << asset.error().message;
  const MeshView mesh = asset->mesh(0);
  const size_t n = mesh.vertex_count();

  std::vector<glm::mat4> model(asset->skeleton().joint_count());
  for (size_t j = 0; j < model.size(); ++j)
    model[j] = glm::rotate(glm::translate(glm::mat4(1.0f), glm::vec3(0.1f * float(j), 0.2f, -0.3f)),
                           0.3f * float(j + 1), glm::normalize(glm::vec3(1.0f, 2.0f, 0.5f)));
  std::vector<glm::mat4> palette(mesh.joints().size());
  skinning_matrices(mesh, model, palette);

  const auto skin = [&](std::vector<float>& p, std::vector<float>& nrm) {
    p.assign(3 * n, 0.0f);
    nrm.assign(3 * n, 0.0f);
    skin_cpu(mesh, palette, SkinningMethod::Linear, SkinnedStreams{p, nrm, {}});
  };
  const SkinningIsa detected = skinning_isa();
  std::printf("skinning: best ISA on this CPU: %s\n", isa_name(detected));
  ASSERT_TRUE(set_skinning_isa(SkinningIsa::Portable));
  std::vector<float> ref_p, ref_n;
  skin(ref_p, ref_n);

  int compared = 0;
  for (const SkinningIsa isa : {SkinningIsa::Avx2, SkinningIsa::Avx512}) {
    if (!set_skinning_isa(isa)) {
      std::printf("skinning: %s not available here\n", isa_name(isa));
      continue;
    }
    ++compared;
    std::vector<float> p, nrm;
    skin(p, nrm);
    for (size_t i = 0; i < 3 * n; ++i) {
      ASSERT_NEAR(p[i], ref_p[i], 1e-4f) << isa_name(isa) << " position component " << i;
      ASSERT_NEAR(nrm[i], ref_n[i], 2e-3f) << isa_name(isa) << " normal component " << i;
    }
  }
  // Portable is always available; an x86-64 CI machine has AVX2 (say so if not, rather than fail).
  if (compared == 0) GTEST_SKIP() << "this CPU has no AVX2: only the portable path ran";
}

}  // namespace
}  // namespace ossa
