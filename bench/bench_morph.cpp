// bench_morph.cpp — ossa-bench-morph: what morph targets cost on disk and on the CPU.
//
//   ossa-bench-morph [--min-seconds S] [--targets N] SOURCE
//
// SOURCE is a character whose meshes carry morph targets (RobotExpressive.glb: a head with 3).
// It is imported and its meshes built in-process exactly as ossa-cook does (import_scene,
// build_meshes at the default bounds, write_ossa), then read back through Asset::from_bytes.
// Two kinds of row, tab-separated with a header:
//   size  asset target vertices listed raw_bytes stored_bytes ratio position_error_mm normal_error_deg
//     vertices: of the source meshes holding the target; raw_bytes: the target's dense float deltas
//     over them (12 bytes per vertex per stream: what glTF stores and what Assimp hands over);
//     stored_bytes: its sparse int16 form (4 bytes per listed vertex + 6 per listed vertex per
//     stream). A last "(all)" row per asset sums them.
//   apply asset targets_active moved_vertex_targets streams us_per_apply ns_per_moved_vertex_target
//     apply_morphs over the whole mesh with every target's weight non-zero, median of batches run for
//     at least --min-seconds; "moved vertex targets" sums the listed vertices of the active targets.
// Besides the source's own targets, a "face" row set: the source's morph-bearing meshes (its head)
// given N (default 52, ARKit's face shapes) generated targets — each a smooth bump of 1-6 mm around
// a pseudo-random vertex, over 8-30 % of the head, with matching normal tilts — built and measured
// the same way. The CPU model is printed first; apply_morphs has one (scalar) implementation.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include <ossa/anim/morph.h>
#include <ossa/loader/asset.h>

#include "cooker/import/import_scene.h"
#include "cooker/mesh/mesh_build.h"
#include "cooker/write/write_ossa.h"
#include "bench/machine.h"

using Clock = std::chrono::steady_clock;
using namespace ossa::cook;

namespace {

/// Deterministic xorshift, so every run generates the same face.
struct Rng {
  uint64_t s = 0x9E3779B97F4A7C15ull;
  double next() {
    s ^= s << 13;
    s ^= s >> 7;
    s ^= s << 17;
    return static_cast<double>(s >> 11) / 9007199254740992.0;
  }
};

/// The scene's meshes that carry morph targets, given `count` generated targets instead.
SourceScene generated_face(const SourceScene& scene, int count) {
  SourceScene face = scene;
  face.meshes.clear();
  for (const SourceMesh& m : scene.meshes)
    if (!m.morph_targets.empty()) face.meshes.push_back(m);
  glm::vec3 lo(1e30f), hi(-1e30f);
  std::vector<glm::vec3> all;
  for (const SourceMesh& m : face.meshes)
    for (const glm::vec3& p : m.positions) {
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
      all.push_back(p);
    }
  const float extent = glm::length(hi - lo);
  const float mm = 0.001f / (scene.metres_per_unit > 0.0f ? scene.metres_per_unit : 1.0f);
  Rng rng;
  for (SourceMesh& m : face.meshes) m.morph_targets.clear();
  for (int t = 0; t < count; ++t) {
    const glm::vec3 centre = all[static_cast<size_t>(rng.next() * static_cast<double>(all.size())) % all.size()];
    const float radius = extent * static_cast<float>(0.08 + 0.22 * rng.next());
    const glm::vec3 dir = glm::normalize(glm::vec3(rng.next() - 0.5, rng.next() - 0.5, rng.next() - 0.5) + 1e-3f);
    const float amplitude = mm * static_cast<float>(1.0 + 5.0 * rng.next());
    for (SourceMesh& m : face.meshes) {
      SourceMorphTarget target;
      target.name = "shape" + std::to_string(t);
      for (size_t v = 0; v < m.positions.size(); ++v) {
        const float d = glm::length(m.positions[v] - centre) / radius;
        const float fall = d < 1.0f ? (1.0f - d * d) * (1.0f - d * d) : 0.0f;
        target.positions.push_back(dir * (amplitude * fall));
        if (!m.normals.empty()) target.normals.push_back(glm::cross(dir, m.normals[v]) * (0.2f * fall));
      }
      m.morph_targets.push_back(std::move(target));
    }
  }
  return face;
}

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

struct Built {
  std::vector<uint8_t> bytes;
  std::vector<CookedMesh> meshes;
};

bool build(const SourceScene& scene, Built* out) {
  MeshBuildStats stats;
  std::vector<std::string> warnings;
  auto meshes = build_meshes(scene, MeshOptions{}, &stats, &warnings);
  if (!meshes) {
    std::fprintf(stderr, "ossa-bench-morph: %s\n", meshes.error().message.c_str());
    return false;
  }
  out->meshes = std::move(*meshes);
  SourceScene bare = scene;
  bare.clips.clear();
  out->bytes = write_ossa(bare, out->meshes, {}, WriteProvenance{}, WriteOptions{});
  return true;
}

void size_rows(const std::string& asset, const ossa::Asset& a, const SourceScene& scene) {
  const float metres_per_unit = scene.metres_per_unit;
  size_t raw_total = 0, stored_total = 0;
  for (size_t m = 0; m < a.mesh_count(); ++m) {
    const ossa::MeshView mesh = a.mesh(m);
    for (size_t t = 0; t < mesh.morph_target_count(); ++t) {
      const ossa::fb::MorphTarget& target = mesh.morph_target(t);
      const size_t listed = target.vertices()->size();
      const size_t streams = 1 + (target.normal_deltas() && target.normal_deltas()->size() ? 1 : 0) +
                             (target.tangent_deltas() && target.tangent_deltas()->size() ? 1 : 0);
      // Dense over the source meshes that hold the target, as the source stores it.
      size_t source_vertices = 0;
      for (const SourceMesh& sm : scene.meshes)
        for (const SourceMorphTarget& st : sm.morph_targets)
          if (st.name == flatbuffers::GetStringView(target.name())) source_vertices += sm.positions.size();
      const size_t raw = 12ull * source_vertices * streams;
      const size_t stored = 4 * listed + 6 * listed * streams;
      raw_total += raw;
      stored_total += stored;
      std::printf("size\t%s\t%s\t%zu\t%zu\t%zu\t%zu\t%.2f\t%.4f\t%.3f\n", asset.c_str(),
                  flatbuffers::GetStringView(target.name()).data(), source_vertices, listed, raw, stored,
                  stored ? static_cast<double>(raw) / static_cast<double>(stored) : 0.0,
                  1000.0 * metres_per_unit * target.position_error(), target.normal_error() * 57.29577951308232);
    }
  }
  std::printf("size\t%s\t(all)\t-\t-\t%zu\t%zu\t%.2f\t-\t-\n", asset.c_str(), raw_total, stored_total,
              stored_total ? static_cast<double>(raw_total) / static_cast<double>(stored_total) : 0.0);
}

void apply_rows(const std::string& asset, const ossa::Asset& a, double min_seconds) {
  for (size_t m = 0; m < a.mesh_count(); ++m) {
    const ossa::MeshView mesh = a.mesh(m);
    const size_t targets = mesh.morph_target_count();
    if (targets == 0) continue;
    std::vector<int32_t> channel(targets);
    std::vector<float> weights(targets);
    size_t moved = 0;
    for (size_t t = 0; t < targets; ++t) {
      channel[t] = static_cast<int32_t>(t);
      weights[t] = 0.5f + 0.5f * static_cast<float>(t) / static_cast<float>(targets);
      moved += mesh.morph_target(t).vertices()->size();
    }
    std::vector<glm::vec3> positions(mesh.vertex_count()), normals(mesh.vertex_count(), glm::vec3(0, 0, 1));
    for (int with_normals = 0; with_normals < 2; ++with_normals) {
      std::vector<double> per_call;
      const auto start = Clock::now();
      while (per_call.size() < 50 || seconds_since(start) < min_seconds) {
        constexpr int kBatch = 100;
        const auto t0 = Clock::now();
        for (int i = 0; i < kBatch; ++i) {
          if (with_normals) ossa::apply_morphs(mesh, channel, weights, positions, normals);
          else ossa::apply_morphs(mesh, channel, weights, positions);
        }
        per_call.push_back(seconds_since(t0) / kBatch);
      }
      std::sort(per_call.begin(), per_call.end());
      const double median = per_call[per_call.size() / 2];
      std::printf("apply\t%s\t%zu\t%zu\t%s\t%.2f\t%.3f\n", asset.c_str(), targets, moved,
                  with_normals ? "positions+normals" : "positions", median * 1e6,
                  median * 1e9 / static_cast<double>(moved));
    }
    volatile float sink = positions[0].x + normals[0].x;
    (void)sink;
  }
}

int usage() {
  std::fprintf(stderr, "usage: ossa-bench-morph [--min-seconds S] [--targets N] SOURCE\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  double min_seconds = 0.5;
  int generated = 52;
  std::string source;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--min-seconds" && i + 1 < argc) {
      min_seconds = std::atof(argv[++i]);
    } else if (arg == "--targets" && i + 1 < argc) {
      generated = std::atoi(argv[++i]);
    } else if (!arg.empty() && arg[0] == '-') {
      return usage();
    } else {
      source = arg;
    }
  }
  if (source.empty() || generated < 1 || generated > 1024) return usage();
  std::printf("# %s\n", ossa::bench::machine_line().c_str());
  auto scene = import_scene(source);
  if (!scene) {
    std::fprintf(stderr, "ossa-bench-morph: %s\n", scene.error().message.c_str());
    return 1;
  }
  bool any = false;
  for (const SourceMesh& m : scene->meshes) any = any || !m.morph_targets.empty();
  if (!any) {
    std::fprintf(stderr, "ossa-bench-morph: %s: no mesh has morph targets\n", source.c_str());
    return 1;
  }
  const std::string stem = std::string(source.substr(source.find_last_of('/') + 1));
  std::printf(
      "kind\tasset\ttarget\tvertices\tlisted\traw_bytes\tstored_bytes\tratio\tposition_error_mm\tnormal_error_deg\n");
  std::printf("kind\tasset\ttargets_active\tmoved_vertex_targets\tstreams\tus_per_apply\tns_per_moved_vertex_target\n");
  const std::string face_name = "face" + std::to_string(generated);
  struct Case {
    std::string name;
    SourceScene scene;
  };
  SourceScene own = *scene;
  std::vector<Case> cases;
  cases.push_back({stem, own});
  cases.push_back({face_name, generated_face(*scene, generated)});
  for (const Case& c : cases) {
    Built built;
    if (!build(c.scene, &built)) return 1;
    auto asset = ossa::Asset::from_bytes(built.bytes, c.name);
    if (!asset) {
      std::fprintf(stderr, "ossa-bench-morph: %s\n", asset.error().message.c_str());
      return 1;
    }
    size_rows(c.name, *asset, c.scene);
    apply_rows(c.name, *asset, min_seconds);
  }
  return 0;
}
