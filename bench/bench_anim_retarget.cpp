// bench_anim_retarget.cpp — the live retarget job (ossa/retarget/retarget.h) per character per
// frame (ossa-bench-anim; bench_fixture.h).
//
// Pab's walk (67 joints) retargeted onto CesiumMan (19 joints, mapped by assets/CesiumMan's map
// file) and onto Pab itself, from poses sampled beforehand (so the time is the retarget alone:
// the source's model space, the per-joint transfer, the mid-plane guard, and with contacts the
// pelvis shift and the leg IK). One call is one character's frame; `ns_per_joint` divides by the
// two rigs' joints together.
//
// Run: ossa-bench-anim --benchmark_filter=BM_Retarget --benchmark_repetitions=5
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <unistd.h>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "bench_fixture.h"
#include "cooker/cook.h"
#include "tools/retarget/map_file.h"
#include <ossa/anim/sample.h>
#include <ossa/retarget/foot_contacts.h>
#include <ossa/retarget/retarget.h>

namespace {

namespace fs = std::filesystem;
using namespace ossa;

struct RigData {
  std::vector<std::string_view> names;
  std::vector<Transform> bind;
  RetargetRig rig;
};

void rig_of(const SkeletonView& sk, RigData& d) {
  for (size_t j = 0; j < sk.joint_count(); ++j) {
    d.names.push_back(sk.joint_name(j));
    const fb::Vec3& t = sk.bind_translations()[j];
    const fb::Quat& r = sk.bind_rotations()[j];
    const fb::Vec3& s = sk.bind_scales()[j];
    d.bind.push_back({{t.x(), t.y(), t.z()}, glm::quat(r.w(), r.x(), r.y(), r.z()), {s.x(), s.y(), s.z()}});
  }
  d.rig.parents = sk.parents();
  d.rig.bind = d.bind;
  d.rig.names = d.names;
  d.rig.humanoid = map_humanoid(sk);
}

struct RetargetBench {
  std::optional<Asset> cesium;
  RigData pab, man;
  RetargetMap to_cesium, to_pab;
  std::vector<Pose> frames;  // Pab's walk, every frame
};

[[noreturn]] void die(const std::string& why) {
  std::fprintf(stderr, "ossa-bench-anim: retarget: %s\n", why.c_str());
  std::exit(1);
}

const RetargetBench& data() {
  static RetargetBench* b = [] {
    auto* r = new RetargetBench;
    const bench::BenchData& d = bench::bench_data();
    const fs::path assets = fs::path(OSSA_BENCH_SOURCE_DIR) / "assets" / "CesiumMan";
    const fs::path out = fs::temp_directory_path() / ("ossa-bench-retarget-" + std::to_string(::getpid()));
    const cook::CookRecord rec = cook::cook_file(assets / "CesiumMan.glb", out / "CesiumMan.ossa", {});
    if (!rec.ok) die(rec.error);
    auto cesium = Asset::open((out / "CesiumMan.ossa").string());
    if (!cesium) die(cesium.error().message);
    r->cesium.emplace(std::move(*cesium));
    fs::remove_all(out);
    rig_of(d.skeleton.skeleton(), r->pab);
    rig_of(r->cesium->skeleton(), r->man);
    auto map_file = cook::load_humanoid_map_file(assets / "CesiumMan.humanoid.json");
    if (!map_file) die(map_file.error().message);
    auto applied = tools::apply_rig_map(&*map_file->rig, r->man.names, r->cesium->skeleton().parents(), "CesiumMan");
    if (!applied) die(applied.error().message);
    r->man.rig.humanoid = applied->humanoid;
    auto to_cesium = make_retarget_map(r->pab.rig, r->man.rig);
    auto to_pab = make_retarget_map(r->pab.rig, r->pab.rig);
    if (!to_cesium || !to_pab) die(to_cesium ? to_pab.error().message : to_cesium.error().message);
    r->to_cesium = std::move(*to_cesium);
    r->to_pab = std::move(*to_pab);
    const ClipView walk = d.walk.clip(0);
    auto cache = make_sampling_cache(walk, d.skeleton.skeleton());
    if (!cache) die(cache.error().message);
    for (uint32_t f = 0; f < walk.frame_count(); ++f) {
      r->frames.emplace_back(static_cast<uint32_t>(r->pab.names.size()));
      sample(walk, static_cast<float>(f) / walk.sample_rate(), {}, *cache, r->frames.back());
    }
    return r;
  }();
  return *b;
}

void run(benchmark::State& state, const RetargetMap& map, bool contacts) {
  const RetargetBench& b = data();
  RetargetScratch scratch = make_retarget_scratch(map);
  Pose out(map.target_joint_count);
  std::array<FootContact, 2> held{FootContact{1.0f, glm::vec3(0.0f), glm::vec3(0.0f)}, FootContact{}};
  RetargetInput in;
  if (contacts) in.contacts = held;
  size_t f = 0;
  for (auto _ : state) {
    in.source = b.frames[f];
    f = f + 1 == b.frames.size() ? 0 : f + 1;
    if (!retarget(map, in, scratch, out)) state.SkipWithError("retarget refused its input");
    benchmark::DoNotOptimize(out.span().base);
    benchmark::ClobberMemory();
  }
  // As bench_anim_pose.cpp's: an inverted rate scaled by 1e-9 prints nanoseconds ("1.9s").
  const double joints = static_cast<double>(map.source_joint_count + map.target_joint_count);
  state.counters["ns_per_joint"] =
      benchmark::Counter(joints * 1e-9, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void BM_RetargetPabToCesiumMan(benchmark::State& state) { run(state, data().to_cesium, false); }
void BM_RetargetPabToCesiumManContacts(benchmark::State& state) { run(state, data().to_cesium, true); }
void BM_RetargetPabToPab(benchmark::State& state) { run(state, data().to_pab, false); }
void BM_RetargetPabToPabContacts(benchmark::State& state) { run(state, data().to_pab, true); }

}  // namespace

BENCHMARK(BM_RetargetPabToCesiumMan);
BENCHMARK(BM_RetargetPabToCesiumManContacts);
BENCHMARK(BM_RetargetPabToPab);
BENCHMARK(BM_RetargetPabToPabContacts);
