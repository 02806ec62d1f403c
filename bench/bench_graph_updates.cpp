// bench_graph_updates.cpp — ossa-bench-graph-updates: a fixed amount of Pab graph updates, for
// valgrind --tool=callgrind (instruction counts do not depend on the machine's load, where the
// wall-clock rows of ossa-bench-graph on a shared machine vary several times over).
//
//   ossa-bench-graph-updates PAB.ossa [--montage] [--crossed] [--characters N] [--preroll N] [--updates N]
//
// N characters (default 50) of the cooked Pab sample graph (ossa-cook assets/Pab/pab.graph.json),
// speeds 0.5, 1.0, ... (the parameter's range clamps them), procedural nodes at weight 0 as in
// ossa-bench-graph's plain rows; --crossed turns the crossed_arms layer on, --montage plays
// cross_arms on every character. Each is updated --preroll times (default 150), then every
// character --updates times (default 40) inside measured_updates(), which callgrind counts alone:
//   valgrind --tool=callgrind --toggle-collect=measured_updates ossa-bench-graph-updates pab.ossa --montage
// Instructions per character update = Collected / (characters * updates).
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <vector>

#include <ossa/graph/graph.h>

using namespace ossa;

namespace {

constexpr float kDt = 1.0f / 60.0f;

}  // namespace

/// The measured part: kept out of line (and out of any namespace) so callgrind can name it.
extern "C" [[gnu::noinline]] void measured_updates(std::vector<std::unique_ptr<GraphInstance>>& characters,
                                                   GraphScratch& scratch, int updates) {
  for (int u = 0; u < updates; ++u)
    for (auto& c : characters) c->update(kDt, scratch);
}

int main(int argc, char** argv) {
  const char* file = nullptr;
  bool montage = false, crossed = false;
  int characters = 50, preroll = 150, updates = 40;
  for (int i = 1; i < argc; ++i) {
    const char* a = argv[i];
    if (!std::strcmp(a, "--montage")) montage = true;
    else if (!std::strcmp(a, "--crossed")) crossed = true;
    else if (!std::strcmp(a, "--characters") && i + 1 < argc) characters = std::max(1, std::atoi(argv[++i]));
    else if (!std::strcmp(a, "--preroll") && i + 1 < argc) preroll = std::max(0, std::atoi(argv[++i]));
    else if (!std::strcmp(a, "--updates") && i + 1 < argc) updates = std::max(1, std::atoi(argv[++i]));
    else if (a[0] != '-' && !file) file = a;
    else {
      file = nullptr;
      break;
    }
  }
  if (!file) {
    std::fprintf(stderr,
                 "usage: ossa-bench-graph-updates PAB.ossa [--montage] [--crossed] [--characters N] "
                 "[--preroll N] [--updates N]\n");
    return 2;
  }
  auto asset = Asset::open(file);
  if (!asset) {
    std::fprintf(stderr, "ossa-bench-graph-updates: %s\n", asset.error().message.c_str());
    return 1;
  }
  auto def = GraphDefinition::create(*asset, "pab");
  if (!def) {
    std::fprintf(stderr, "ossa-bench-graph-updates: %s\n", def.error().message.c_str());
    return 1;
  }
  const int speed = def->find_parameter("speed"), arms = def->find_parameter("crossed_arms");
  const int cross_arms = def->find_montage("cross_arms");
  if (speed < 0 || arms < 0 || cross_arms < 0) {
    std::fprintf(stderr, "ossa-bench-graph-updates: %s: not the Pab sample graph (speed, crossed_arms, cross_arms)\n",
                 file);
    return 1;
  }
  GraphScratch scratch = GraphScratch::create(*def);
  std::vector<std::unique_ptr<GraphInstance>> all;
  for (int i = 0; i < characters; ++i) {
    auto inst = GraphInstance::create(*def, 64, /*own_scratch=*/false);
    if (!inst) {
      std::fprintf(stderr, "ossa-bench-graph-updates: %s\n", inst.error().message.c_str());
      return 1;
    }
    all.push_back(std::make_unique<GraphInstance>(std::move(*inst)));
    GraphInstance& c = *all.back();
    for (const char* off : {"look_weight", "feet_on_ground", "foot_lock"})
      if (const int q = def->find_parameter(off); q >= 0) c.set_float(q, 0.0f);
    c.set_float(speed, 0.5f + 0.5f * static_cast<float>(i));
    c.set_bool(arms, crossed);
    if (montage) c.play_montage(cross_arms);
    for (int k = 0; k < preroll; ++k) c.update(kDt, scratch);
  }
  measured_updates(all, scratch, updates);
  std::printf("%d characters x %d updates (montage %s, crossed_arms %s)\n", characters, updates, montage ? "on" : "off",
              crossed ? "on" : "off");
  return 0;
}
