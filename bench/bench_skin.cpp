// bench_skin.cpp — ossa-bench-skin: skin_cpu's time per vertex on the skinned meshes of cooked files,
// and whether each mesh is on the fast path.
//
//   ossa-bench-skin [--rounds N] FILE.ossa...
//
// For every mesh with joints: its vertex count, its order (the cooker orders a skinned mesh's
// vertices by influence class, so skin_cpu runs one loop per class range; a mesh whose classes are
// not in order, from another tool or an older cook, is classified batch by batch), and the minimum
// over N interleaved rounds of the ns per vertex for positions alone, positions and normals, and
// with tangents where the mesh has them. Two cooks of one source, given side by side, compare in
// one run. The palette is a fixed set of rigid transforms (a few degrees and a shift per slot), so
// the figures depend on the mesh, not on a pose. Prints the machine line first (machine.h).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <ossa/loader/asset.h>
#include <ossa/skinning/skinning.h>

#include "bench/machine.h"

namespace {

using Clock = std::chrono::steady_clock;

struct Case {
  std::string file;
  size_t mesh_index = 0;
  ossa::MeshView mesh;
  std::vector<glm::mat4> palette;
  std::vector<float> positions, normals, tangents;
  double best[3] = {1e300, 1e300, 1e300};  // positions; + normals; + tangents
  int streams = 2;                         // 3 when the mesh has tangents
  std::string order;
};

/// "by class (R ranges)" when influence classes never decrease along the vertex buffer, else
/// "unordered (R class runs)": what decides between skin_cpu's range loops and classified batches.
std::string order_of(const ossa::MeshView& mesh) {
  const ossa::InfluenceOrder o = ossa::influence_order(mesh);
  if (!o.unorm8_weights) return "not unorm8 weights";
  return (o.class_ordered ? "by class (" + std::to_string(o.class_runs) + " ranges)"
                          : "unordered (" + std::to_string(o.class_runs) + " class runs)");
}

/// Times `reps` calls of one stream selection and keeps the minimum per vertex.
void time_streams(Case& c, int s, int reps) {
  const ossa::SkinnedStreams out{c.positions, s >= 1 ? std::span<float>(c.normals) : std::span<float>(),
                                 s >= 2 ? std::span<float>(c.tangents) : std::span<float>()};
  const auto start = Clock::now();
  for (int i = 0; i < reps; ++i) ossa::skin_cpu(c.mesh, c.palette, ossa::SkinningMethod::Linear, out);
  const double ns = std::chrono::duration<double, std::nano>(Clock::now() - start).count() / reps;
  c.best[s] = std::min(c.best[s], ns / c.mesh.vertex_count());
}

[[noreturn]] void usage() {
  std::fprintf(stderr, "usage: ossa-bench-skin [--rounds N] [--clone baseline|avx2|avx512] FILE.ossa...\n");
  std::exit(2);
}

}  // namespace

int main(int argc, char** argv) {
  std::string error;
  if (!ossa::bench::apply_clone(argc, argv, &error)) {
    std::fprintf(stderr, "ossa-bench-skin: %s\n", error.c_str());
    return 2;
  }
  int rounds = 31;
  std::vector<std::string> files;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--rounds") == 0 && i + 1 < argc) rounds = std::max(1, std::atoi(argv[++i]));
    else if (argv[i][0] == '-') usage();
    else files.emplace_back(argv[i]);
  }
  if (files.empty()) usage();
  std::printf("# %s\n", ossa::bench::machine_line().c_str());

  std::vector<ossa::Asset> assets;
  assets.reserve(files.size());
  for (const std::string& f : files) {
    auto a = ossa::Asset::open(f);
    if (!a) {
      std::fprintf(stderr, "ossa-bench-skin: %s\n", a.error().message.c_str());
      return 1;
    }
    assets.push_back(std::move(*a));
  }
  std::vector<Case> cases;
  for (size_t f = 0; f < assets.size(); ++f)
    for (size_t m = 0; m < assets[f].mesh_count(); ++m) {
      const ossa::MeshView mesh = assets[f].mesh(m);
      if (mesh.joints().empty() || mesh.vertex_count() == 0) continue;
      Case c;
      c.file = files[f];
      c.mesh_index = m;
      c.mesh = mesh;
      for (size_t s = 0; s < mesh.joints().size(); ++s) {
        const float a = 0.05f * static_cast<float>(s % 7) - 0.15f;
        glm::mat4 x = glm::rotate(glm::mat4(1.0f), a, glm::normalize(glm::vec3(1.0f, 0.5f + 0.1f * a, 0.25f)));
        x[3] = glm::vec4(0.01f * static_cast<float>(s), 0.02f, -0.01f, 1.0f);
        c.palette.push_back(x);
      }
      const size_t n = mesh.vertex_count();
      c.positions.resize(3 * n);
      c.normals.resize(mesh.attribute(ossa::fb::VertexSemantic::Normal) ? 3 * n : 0);
      c.streams = c.normals.empty() ? 1 : 2;
      if (!c.normals.empty() && mesh.attribute(ossa::fb::VertexSemantic::Tangent) != nullptr) {
        c.tangents.resize(4 * n);
        c.streams = 3;
      }
      c.order = order_of(mesh);
      cases.push_back(std::move(c));
    }
  if (cases.empty()) {
    std::fprintf(stderr, "ossa-bench-skin: no skinned mesh in the files given\n");
    return 1;
  }
  // Each call ~50 us of work or more, so that a round's timer overhead is negligible.
  std::vector<int> reps(cases.size());
  for (size_t i = 0; i < cases.size(); ++i) reps[i] = std::max(1, int(50000 / (3.0 * cases[i].mesh.vertex_count())));
  for (int r = 0; r < rounds; ++r)
    for (size_t i = 0; i < cases.size(); ++i)
      for (int s = 0; s < cases[i].streams; ++s) time_streams(cases[i], s, reps[i]);

  std::printf("# ns per vertex, the minimum of %d interleaved rounds; order: how skin_cpu walks the mesh\n", rounds);
  int width = 4;
  for (const Case& c : cases) width = std::max(width, static_cast<int>(c.file.size()));
  std::printf("%-*s %4s %8s  %-28s %9s %12s %12s\n", width, "file", "mesh", "vertices", "order", "positions",
              "+normals", "+tangents");
  for (const Case& c : cases) {
    char t[32] = "-";
    if (c.streams == 3) std::snprintf(t, sizeof t, "%.3f", c.best[2]);
    char n[32] = "-";
    if (c.streams >= 2) std::snprintf(n, sizeof n, "%.3f", c.best[1]);
    std::printf("%-*s %4zu %8u  %-28s %9.3f %12s %12s\n", width, c.file.c_str(), c.mesh_index, c.mesh.vertex_count(),
                c.order.c_str(), c.best[0], n, t);
  }
  return 0;
}
