// bench_fixture.cpp — cooks the benchmark assets once (see bench_fixture.h).
#include "bench_fixture.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>

#include "cooker/cook.h"

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
  for (const char* name : {"walk", "jog", "run", "arnaud"})
    cook_or_die(pab / (std::string(name) + ".fbx"), dir / (std::string(name) + ".ossa"), bound);
  auto data = std::unique_ptr<BenchData>(new BenchData{open_or_die(dir / "skeleton.ossa"), open_or_die(dir / "walk.ossa"),
                                                       open_or_die(dir / "jog.ossa"), open_or_die(dir / "run.ossa"),
                                                       open_or_die(dir / "arnaud.ossa")});
  std::error_code ec;
  fs::remove_all(dir, ec);  // the mappings stay valid after unlink
  return data;
}

}  // namespace

const BenchData& bench_data() {
  static const std::unique_ptr<BenchData> data = load();
  return *data;
}

}  // namespace ossa::bench
