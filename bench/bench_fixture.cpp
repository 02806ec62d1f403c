// bench_fixture.cpp — cooks the benchmark assets once (see bench_fixture.h).
#include "bench_fixture.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <span>
#include <filesystem>
#include <memory>
#include <string>

#include "cooker/cook.h"
#include <ossa/format/vertex_codec.h>

namespace ossa::bench {
namespace fs = std::filesystem;

namespace {

Asset open_or_die(const fs::path& p) {
  auto a = Asset::open(p.string());
  if (!a) {
    std::fprintf(stderr, "bench: %s\n", a.error().message.c_str());
    std::exit(1);
  }
  return std::move(*a);
}

void cook_or_die(const fs::path& in, const fs::path& out, const cook::CookOptions& options) {
  const cook::CookRecord r = cook::cook_file(in, out, options);
  if (!r.ok) {
    std::fprintf(stderr, "bench: %s\n", r.error.c_str());
    std::exit(1);
  }
}

std::unique_ptr<BenchData> load() {
  const fs::path pab = fs::path(OSSA_BENCH_SOURCE_DIR) / "assets" / "Pab";
  const fs::path dir = fs::temp_directory_path() / ("ossa-bench-anim-" + std::to_string(::getpid()));
  cook_or_die(pab / "skeleton.fbx", dir / "skeleton.ossa", {});
  auto reference = cook::load_reference_skeleton(dir / "skeleton.ossa");
  if (!reference) {
    std::fprintf(stderr, "bench: %s\n", reference.error().message.c_str());
    std::exit(1);
  }
  cook::CookOptions bound;
  bound.reference = &*reference;
  bound.reference_name = "skeleton.ossa";
  for (const char* name : {"walk", "jog", "run", "arnaud", "crossarms"})
    cook_or_die(pab / (std::string(name) + ".fbx"), dir / (std::string(name) + ".ossa"), bound);
  auto data = std::unique_ptr<BenchData>(new BenchData{
      open_or_die(dir / "skeleton.ossa"), open_or_die(dir / "walk.ossa"), open_or_die(dir / "jog.ossa"),
      open_or_die(dir / "run.ossa"), open_or_die(dir / "arnaud.ossa"), open_or_die(dir / "crossarms.ossa")});
  std::error_code ec;
  fs::remove_all(dir, ec);  // the mappings stay valid after unlink
  return data;
}

}  // namespace

std::vector<uint8_t> dealt_copy(const Asset& asset) {
  const std::span<const uint8_t> file = asset.bytes();
  const MeshView mesh = asset.mesh(0);
  std::vector<uint8_t> out(file.begin(), file.end());
  const size_t at = static_cast<size_t>(mesh.vertex_bytes().data() - file.data());
  const size_t stride = mesh.vertex_stride();
  const uint32_t weights = mesh.attribute(fb::VertexSemantic::Weights)->offset();
  // The class runs of the cooked order (skin_cpu's classes of the weight bytes), then one vertex
  // of each run in turn.
  std::vector<std::vector<uint32_t>> runs;
  uint32_t last = ~0u;
  for (uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    uint32_t w;
    std::memcpy(&w, mesh.vertex_bytes().data() + v * stride + weights, 4);
    const auto c = static_cast<uint32_t>(influence_class(w));
    if (c != last) runs.emplace_back();
    runs.back().push_back(v);
    last = c;
  }
  size_t n = 0;
  for (size_t i = 0; n < mesh.vertex_count(); ++i)
    for (const auto& run : runs)
      if (i < run.size())
        std::memcpy(out.data() + at + n++ * stride, mesh.vertex_bytes().data() + run[i] * stride, stride);
  return out;
}

std::vector<uint8_t> noisy_rest_copy(const Asset& skeleton, size_t* noisy) {
  const std::span<const uint8_t> file = skeleton.bytes();
  std::vector<uint8_t> out(file.begin(), file.end());
  const SkeletonView view = skeleton.skeleton();
  size_t changed = 0;
  const auto add_noise = [&](const void* values, size_t floats) {
    const size_t at = static_cast<size_t>(static_cast<const uint8_t*>(values) - file.data());
    for (size_t i = 0; i < floats; ++i) {
      float v;
      std::memcpy(&v, out.data() + at + 4 * i, 4);
      if (v != 0.0f) continue;
      v = changed++ % 2 ? -7.7e-34f : 7.7e-34f;
      std::memcpy(out.data() + at + 4 * i, &v, 4);
    }
  };
  add_noise(view.bind_rotations().data(), 4 * view.bind_rotations().size());
  add_noise(view.bind_translations().data(), 3 * view.bind_translations().size());
  *noisy = changed;
  return out;
}

const BenchData& bench_data() {
  static const std::unique_ptr<BenchData> data = load();
  return *data;
}

}  // namespace ossa::bench
