// retarget_cook_test.cpp — retargeting the shared sample rigs, none of them tuned for: ossa-cook
// --retarget-to across Pab (FBX, centimetres, Biped-style spine), a Quaternius character (the
// Cowboy: FBX, IK feet hanging from the root, a T-pose), CesiumMan (glTF, names that say nothing:
// mapped by its map file, arms half down) and a CMU BVH capture (its floor 17 m above its rest
// pose), plus an A-pose Cowboy made from the T-pose one (ossa-test-apose).
//
// Per pair, from the cook's --report: limb directions within 5 degrees of the source's at every
// frame (limbs the mid-plane guard swung back are reported apart), no hand or foot across the
// mid-plane where the source's is not, every planted foot within 1 cm of where it is held. Then a
// rig onto itself equals the source within 0.1 mm, missing bones are named, map file mistakes are
// named, and the live job (ossa::retarget on the cooked source clip) equals the cooked clip within
// 0.1 mm; a graph's retarget node (format v10) equals the live job, allocates nothing per update
// and its compile mistakes are named. Cooks go to one cache folder under the test tree; a second
// test process finds them up to date (their cook keys match) instead of cooking again.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <span>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <ossa/anim/pose_ops.h>
#include <ossa/graph/graph.h>
#include <ossa/anim/sample.h>
#include <ossa/loader/asset.h>
#include <ossa/retarget/foot_contacts.h>
#include <ossa/retarget/retarget.h>
#include "tools/retarget/map_file.h"
#include "allocation_counter.h"
#include "test_files.h"

namespace fs = std::filesystem;
using ossa::test::run_command;

namespace {

std::string q(const fs::path& p) { return "'" + p.string() + "'"; }
std::string tool(const char* name) { return q(ossa::test::bin_dir() / name); }
fs::path shared(const char* rel) { return ossa::test::shared_assets() / rel; }
fs::path cesium_map() { return ossa::test::source_dir() / "assets" / "CesiumMan" / "CesiumMan.humanoid.json"; }
const char* kCmuUnit = " --metres-per-unit 0.056444";  // CMU's BVH units (the file states none)

fs::path cache() {
  const fs::path dir = fs::path(ossa::test::env_or("OSSA_TEST_TMP", OSSA_TEST_TMP_DIR)) / "retarget-cooked";
  fs::create_directories(dir);
  return dir;
}

bool have_assets() { return fs::exists(shared("Pab/walk.fbx")) && fs::exists(shared("CMU_BVH/01_03.bvh")); }

/// Cooks (or finds up to date) `args` into cache()/sub; fails the test on a non-zero exit.
bool cook(const std::string& args, const std::string& sub, std::string* err = nullptr) {
  const auto r = run_command(tool("ossa-cook") + " -q " + args + " -o " + q(cache() / sub));
  if (err != nullptr) *err = r.err;
  EXPECT_EQ(r.exit_code, 0) << args << "\n" << r.err;
  return r.exit_code == 0;
}

/// The four rigs and the A-pose Cowboy, cooked once.
struct Rigs {
  fs::path pab, cowboy, cesium, cmu, cowboy_a;
};
Rigs rigs() {
  Rigs r;
  r.pab = cache() / "rigs" / "skeleton.ossa";
  r.cowboy = cache() / "rigs" / "Cowboy.ossa";
  r.cesium = cache() / "rigs" / "CesiumMan.ossa";
  r.cmu = cache() / "rigs" / "01_03.ossa";
  r.cowboy_a = cache() / "rigs" / "CowboyA.ossa";
  cook(q(shared("Pab/skeleton.fbx")) + " " + q(shared("Quaternius_Cowboy/Cowboy.fbx")) + " " +
           q(shared("CesiumMan/CesiumMan.glb")) + " --jobs 2",
       "rigs");
  cook(q(shared("CMU_BVH/01_03.bvh")) + kCmuUnit, "rigs");
  // Made again whenever the tool is newer than the file (a build that changed the format, say).
  std::error_code ec;
  const fs::path apose_tool = ossa::test::bin_dir() / "ossa-test-apose";
  if (!fs::exists(r.cowboy_a) || fs::last_write_time(apose_tool, ec) > fs::last_write_time(r.cowboy_a, ec)) {
    const auto made =
        run_command(tool("ossa-test-apose") + " " + q(shared("Quaternius_Cowboy/Cowboy.fbx")) + " " + q(r.cowboy_a));
    EXPECT_EQ(made.exit_code, 0) << made.err;
  }
  return r;
}

struct Source {
  std::string label, args;  // the source file and its rig / unit / map options
};

/// Retargets `source` onto `target` and returns the report's retarget entries.
nlohmann::json retarget(const Source& source, const fs::path& target, const std::string& sub,
                        const std::string& extra = "") {
  const fs::path report = cache() / (sub + ".json");
  // --force: an up-to-date output's record carries no retarget entries (they are measured while
  // cooking), so a second run of the suite in one build folder must cook again.
  if (!cook(source.args + " --retarget-to " + q(target) + extra + " --force --report " + q(report), sub)) return {};
  const auto text = ossa::test::read_text(report);
  if (!text) return {};
  const auto doc = nlohmann::json::parse(*text);
  nlohmann::json all = nlohmann::json::array();
  for (const auto& record : doc.at("records"))
    if (record.contains("retarget"))
      for (const auto& r : record.at("retarget")) all.push_back(r);
  return all;
}

TEST(RetargetCook, CrossPairsOfUntunedRigs) {
  if (!have_assets()) GTEST_SKIP() << "no ../shared/assets";
  const Rigs r = rigs();
  const std::string map = " --map " + q(cesium_map());
  const Source pab{"Pab walk", q(shared("Pab/walk.fbx")) + " --skeleton " + q(r.pab)};
  const Source cowboy{"Cowboy", q(shared("Quaternius_Cowboy/Cowboy.fbx"))};
  const Source cesium{"CesiumMan", q(shared("CesiumMan/CesiumMan.glb")) + map};
  const Source cmu{"CMU 01_03", q(shared("CMU_BVH/01_03.bvh")) + kCmuUnit};
  struct Pair {
    const Source* source;
    fs::path target;
    std::string name, extra;
  };
  const std::vector<Pair> pairs = {
      {&pab, r.cowboy, "pab-cowboy", ""},
      {&pab, r.cesium, "pab-cesium", map},
      {&pab, r.cmu, "pab-cmu", ""},
      {&cowboy, r.pab, "cowboy-pab", ""},
      {&cowboy, r.cesium, "cowboy-cesium", map},
      {&cowboy, r.cmu, "cowboy-cmu", ""},
      {&cesium, r.pab, "cesium-pab", ""},
      {&cesium, r.cowboy, "cesium-cowboy", ""},
      {&cesium, r.cmu, "cesium-cmu", ""},
      {&cmu, r.pab, "cmu-pab", ""},
      {&cmu, r.cowboy, "cmu-cowboy", ""},
      {&cmu, r.cesium, "cmu-cesium", map},
      {&pab, r.cowboy_a, "pab-cowboy-apose", ""},
      {&cowboy, r.cowboy_a, "cowboy-tpose-to-apose", ""},
  };
  std::printf("%-24s %-28s %7s %6s %6s %6s %6s %6s %5s %8s %7s %7s %7s\n", "pair", "clip", "frames", "hips", "limbs",
              "guard", "hands", "feet", "cross", "contacts", "held", "slide", "source");
  for (const Pair& p : pairs) {
    SCOPED_TRACE(p.name);
    const nlohmann::json clips = retarget(*p.source, p.target, p.name, p.extra);
    ASSERT_FALSE(clips.empty());
    for (const auto& c : clips) {
      SCOPED_TRACE(c.at("clip").get<std::string>());
      EXPECT_LT(c.at("limb_max_deg").get<double>(), 5.0);
      EXPECT_EQ(c.at("crossing_frames").get<int>(), 0);
      double held = 0.0, slide = 0.0, source_slide = 0.0;
      for (const auto& contact : c.at("contacts")) {
        held = std::max(held, contact.at("held_mm").get<double>());
        slide = std::max(slide, contact.at("slide_mm").get<double>());
        source_slide = std::max(source_slide, contact.at("source_slide_mm").get<double>());
      }
      EXPECT_LT(held, 10.0);  // planted feet within 1 cm of where they are held
      std::printf("%-24s %-28.28s %7d %6.3f %6.2f %6.2f %6.2f %6.2f %5d %8zu %7.3f %7.2f %7.2f\n", p.name.c_str(),
                  c.at("clip").get<std::string>().c_str(), c.at("frames").get<int>(), c.at("hips_ratio").get<double>(),
                  c.at("limb_max_deg").get<double>(), c.at("guard_max_deg").get<double>(),
                  c.at("hand_max_deg").get<double>(), c.at("foot_max_deg").get<double>(),
                  c.at("crossing_frames").get<int>(), c.at("contacts").size(), held, slide, source_slide);
    }
    // The output is a clip of the target rig: it binds to it.
    for (const auto& e : fs::directory_iterator(cache() / p.name)) {
      auto clip = ossa::Asset::open(e.path().string());
      auto rig = ossa::Asset::open(p.target.string());
      ASSERT_TRUE(clip.ok() && rig.ok());
      EXPECT_TRUE(clip->skeleton().empty());
      for (size_t i = 0; i < clip->clip_count(); ++i)
        EXPECT_TRUE(ossa::check_clip_binding(clip->clip(i), rig->skeleton(), e.path().string()).ok());
    }
  }
  // The report of a retarget is valid against its schema.
  const auto check =
      run_command("python3 " + q(ossa::test::source_dir() / "tests" / "support" / "json_schema_check.py") + " " +
                  q(ossa::test::source_dir() / "docs" / "schemas" / "ossa-cook-report.schema.json") + " " +
                  q(cache() / "cmu-cesium.json"));
  EXPECT_EQ(check.exit_code, 0) << check.out << check.err;
}

/// Largest distance between the joints of two clips of one rig, in millimetres, at every frame.
double clip_distance_mm(const ossa::Asset& rig, const ossa::ClipView& a, const ossa::ClipView& b) {
  const ossa::SkeletonView sk = rig.skeleton();
  auto ca = ossa::make_sampling_cache(a, sk), cb = ossa::make_sampling_cache(b, sk);
  if (!ca.ok() || !cb.ok()) return 1e9;
  const auto n = static_cast<uint32_t>(sk.joint_count());
  ossa::Pose pa(n), pb(n);
  std::vector<glm::mat4> ma(n), mb(n);
  double worst = 0.0;
  for (uint32_t f = 0; f < a.frame_count(); ++f) {
    const float t = static_cast<float>(f) / a.sample_rate();
    ossa::sample(a, t, {false}, *ca, pa);
    ossa::sample(b, t, {false}, *cb, pb);
    ossa::local_to_model(sk.parents(), pa, ma);
    ossa::local_to_model(sk.parents(), pb, mb);
    for (uint32_t j = 0; j < n; ++j)
      worst = std::max(worst, static_cast<double>(glm::length(glm::vec3(ma[j][3] - mb[j][3]))));
  }
  return worst * rig.file().metres_per_unit() * 1000.0;
}

TEST(RetargetCook, RigOntoItselfEqualsTheSource) {
  if (!have_assets()) GTEST_SKIP() << "no ../shared/assets";
  const Rigs r = rigs();
  const std::string walk = q(shared("Pab/walk.fbx")) + " --skeleton " + q(r.pab) + " --no-clip-compression";
  ASSERT_TRUE(cook(walk, "self-plain"));
  ASSERT_TRUE(cook(walk + " --retarget-to " + q(r.pab), "self-retargeted"));
  auto rig = ossa::Asset::open(r.pab.string());
  auto plain = ossa::Asset::open((cache() / "self-plain" / "walk.ossa").string());
  auto self = ossa::Asset::open((cache() / "self-retargeted" / "walk.ossa").string());
  ASSERT_TRUE(rig.ok() && plain.ok() && self.ok());
  const double mm = clip_distance_mm(*rig, plain->clip(0), self->clip(0));
  std::printf("Pab walk onto Pab: largest joint distance %.5f mm\n", mm);
  EXPECT_LT(mm, 0.1);
}

TEST(RetargetCook, MissingBonesAndMapMistakesAreNamed) {
  if (!have_assets()) GTEST_SKIP() << "no ../shared/assets";
  const Rigs r = rigs();
  const auto run = [&](const std::string& args) {
    return run_command(tool("ossa-cook") + " -q " + args + " -o " + q(ossa::test::make_temp_dir("retarget-bad")));
  };
  // CesiumMan's joint names say nothing: without its map file, the missing bones are named.
  auto missing = run(q(shared("CesiumMan/CesiumMan.glb")) + " --retarget-to " + q(r.pab));
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.err.find("CesiumMan.glb (source rig): missing humanoid bones: hips, spine, head,"),
            std::string::npos)
      << missing.err;
  EXPECT_NE(missing.err.find("rightFoot"), std::string::npos) << missing.err;
  // ... and as a target.
  auto as_target = run(q(shared("Pab/walk.fbx")) + " --skeleton " + q(r.pab) + " --retarget-to " + q(r.cesium));
  EXPECT_EQ(as_target.exit_code, 1);
  EXPECT_NE(as_target.err.find("CesiumMan.ossa (target rig): missing humanoid bones: hips"), std::string::npos)
      << as_target.err;

  const fs::path dir = ossa::test::make_temp_dir("retarget-maps");
  const auto with_map = [&](const std::string& text) {
    const fs::path file = dir / "map.json";
    EXPECT_TRUE(ossa::test::write_file(file, text));
    return run(q(shared("CesiumMan/CesiumMan.glb")) + " --retarget-to " + q(r.pab) + " --map " + q(file));
  };
  auto typo = with_map(R"({"ossa_humanoid_map": 1, "rig": {"bones": {"leftUpperArmm": "x"}}})");
  EXPECT_EQ(typo.exit_code, 2);
  EXPECT_NE(typo.err.find("map.json: rig.bones: 'leftUpperArmm' is not a humanoid bone (did you mean 'leftUpperArm'?)"),
            std::string::npos)
      << typo.err;
  auto twice = with_map(R"({"ossa_humanoid_map": 1, "source": {"rest": "bind", "rest": "straighten"}})");
  EXPECT_EQ(twice.exit_code, 2);
  EXPECT_NE(twice.err.find("key 'rest' appears twice"), std::string::npos) << twice.err;
  auto no_joint = with_map(R"({"ossa_humanoid_map": 1, "source": {"bones": {"hips": "pelvis_joint"}}})");
  EXPECT_EQ(no_joint.exit_code, 1);
  EXPECT_NE(no_joint.err.find("bones.hips: the rig has no joint 'pelvis_joint'"), std::string::npos) << no_joint.err;
  auto not_unit =
      with_map(R"({"ossa_humanoid_map": 1, "source": {"rest_rotations": {"leg_joint_L_1": [0, 0, 0, 2]}}})");
  EXPECT_EQ(not_unit.exit_code, 2);
  EXPECT_NE(not_unit.err.find("rest_rotations.leg_joint_L_1: is not a unit quaternion"), std::string::npos)
      << not_unit.err;
  // ossa-inspect --humanoid says the same before any cook.
  const auto inspect = run_command(tool("ossa-inspect") + " " + q(r.cesium) + " --humanoid");
  EXPECT_EQ(inspect.exit_code, 0);
  EXPECT_NE(inspect.out.find("not retargetable"), std::string::npos) << inspect.out;
  const auto mapped = run_command(tool("ossa-inspect") + " " + q(r.cesium) + " --humanoid --map " + q(cesium_map()));
  EXPECT_NE(mapped.out.find("leftUpperArm             Skeleton_arm_joint_L__4_"), std::string::npos) << mapped.out;
  EXPECT_NE(mapped.out.find("retargetable:"), std::string::npos) << mapped.out;
}

/// The live job on a cooked source clip, as ossa-cook --retarget-to runs it (its three passes over
/// the clip's grid, with the runtime's functions), then played at `times` (empty: every frame of
/// the grid): the target's local poses.
std::vector<ossa::Pose> live_frames(const ossa::Asset& sa, const ossa::ClipView& source, const ossa::Asset& ta,
                                    std::span<const float> times = {}) {
  struct RigData {
    std::vector<std::string_view> names;
    std::vector<ossa::Transform> bind;
    ossa::RetargetRig rig;
  };
  auto rig_of = [](const ossa::SkeletonView& sk, RigData& d) {
    for (size_t j = 0; j < sk.joint_count(); ++j) {
      d.names.push_back(sk.joint_name(j));
      const auto& t = sk.bind_translations()[j];
      const auto& r = sk.bind_rotations()[j];
      const auto& s = sk.bind_scales()[j];
      d.bind.push_back({{t.x(), t.y(), t.z()}, glm::quat(r.w(), r.x(), r.y(), r.z()), {s.x(), s.y(), s.z()}});
    }
    d.rig.parents = sk.parents();
    d.rig.bind = d.bind;
    d.rig.names = d.names;
    d.rig.humanoid = ossa::map_humanoid(sk);
  };
  RigData s, t;
  rig_of(sa.skeleton(), s);
  rig_of(ta.skeleton(), t);
  auto map = ossa::make_retarget_map(s.rig, t.rig);
  EXPECT_TRUE(map.ok());
  if (!map.ok()) return {};
  ossa::RetargetScratch scratch = ossa::make_retarget_scratch(*map);
  auto cache_s = ossa::make_sampling_cache(source, sa.skeleton());
  EXPECT_TRUE(cache_s.ok());
  if (!cache_s.ok()) return {};
  const auto ns = static_cast<uint32_t>(s.names.size()), nt = static_cast<uint32_t>(t.names.size());
  std::vector<ossa::Pose> frames;
  for (uint32_t f = 0; f < source.frame_count(); ++f) {
    frames.emplace_back(ns);
    ossa::sample(source, static_cast<float>(f) / source.sample_rate(), {false}, *cache_s, frames.back());
  }
  std::vector<ossa::ContactFrame> feet(frames.size());
  for (size_t f = 0; f < frames.size(); ++f) {
    ossa::pose_source(*map, frames[f], scratch);
    feet[f] = ossa::contact_frame(*map, scratch);
  }
  ossa::RetargetInput in;
  in.source_floor = ossa::clip_floor(*map, feet);
  ossa::Pose live(nt);
  for (size_t f = 0; f < frames.size(); ++f) {
    in.source = frames[f];
    ossa::retarget(*map, in, scratch, live);
    feet[f].target_ankle = ossa::contact_frame(*map, scratch).target_ankle;
  }
  const auto contacts = ossa::find_foot_contacts(*map, feet, source.sample_rate(), in.source_floor);
  std::array<ossa::FootContact, 2> held{};
  in.contacts = held;
  std::vector<ossa::Pose> out;
  ossa::Pose at_time(ns);
  const size_t count = times.empty() ? frames.size() : times.size();
  for (size_t f = 0; f < count; ++f) {
    const float frame = times.empty() ? static_cast<float>(f) : times[f] * source.sample_rate();
    ossa::foot_contacts_at(contacts, frame, source.sample_rate(), ossa::ContactSettings{}.blend_time, held);
    if (!times.empty()) ossa::sample(source, times[f], {true}, *cache_s, at_time);
    in.source = times.empty() ? frames[f].span() : at_time.span();
    out.emplace_back(nt);
    EXPECT_TRUE(ossa::retarget(*map, in, scratch, out.back()));
  }
  return out;
}

/// The largest distance between the joints of two poses of `sk`, in millimetres.
double pose_distance_mm(const ossa::SkeletonView& sk, float metres_per_unit, ossa::ConstPoseSpan a,
                        ossa::ConstPoseSpan b) {
  const size_t n = sk.joint_count();
  std::vector<glm::mat4> ma(n), mb(n);
  ossa::local_to_model(sk.parents(), a, ma);
  ossa::local_to_model(sk.parents(), b, mb);
  double worst = 0.0;
  for (size_t j = 0; j < n; ++j)
    worst = std::max(worst, static_cast<double>(glm::length(glm::vec3(ma[j][3] - mb[j][3]))));
  return worst * metres_per_unit * 1000.0;
}

/// The live job on a cooked source clip, frame by frame, against the cooked retargeted clip.
double live_against_cooked(const fs::path& source_rig, const fs::path& source_clip, const fs::path& target_rig,
                           const fs::path& cooked) {
  auto sa = ossa::Asset::open(source_rig.string()), sc = ossa::Asset::open(source_clip.string());
  auto ta = ossa::Asset::open(target_rig.string()), tc = ossa::Asset::open(cooked.string());
  EXPECT_TRUE(sa.ok() && sc.ok() && ta.ok() && tc.ok());
  if (!sa.ok() || !sc.ok() || !ta.ok() || !tc.ok()) return 1e9;
  const std::vector<ossa::Pose> live = live_frames(*sa, sc->clip(0), *ta);
  const ossa::ClipView target = tc->clip(0);
  auto cache_t = ossa::make_sampling_cache(target, ta->skeleton());
  EXPECT_TRUE(cache_t.ok());
  if (!cache_t.ok() || live.empty()) return 1e9;
  ossa::Pose cooked_pose(static_cast<uint32_t>(ta->skeleton().joint_count()));
  double worst = 0.0;
  for (size_t f = 0; f < live.size(); ++f) {
    ossa::sample(target, static_cast<float>(f) / target.sample_rate(), {false}, *cache_t, cooked_pose);
    worst = std::max(worst, pose_distance_mm(ta->skeleton(), ta->file().metres_per_unit(), live[f], cooked_pose));
  }
  return worst;
}

TEST(RetargetCook, LiveJobEqualsTheCookedClip) {
  if (!have_assets()) GTEST_SKIP() << "no ../shared/assets";
  const Rigs r = rigs();
  const std::string walk = q(shared("Pab/walk.fbx")) + " --skeleton " + q(r.pab) + " --no-clip-compression";
  ASSERT_TRUE(cook(walk, "live-source"));
  ASSERT_TRUE(cook(walk + " --retarget-to " + q(r.cowboy), "live-cooked"));
  const double pab_mm = live_against_cooked(r.pab, cache() / "live-source" / "walk.ossa", r.cowboy,
                                            cache() / "live-cooked" / "walk.ossa");
  // A capture whose floor is not its rig's: the floor rides along.
  const std::string cmu = q(shared("CMU_BVH/01_03.bvh")) + kCmuUnit + " --no-clip-compression";
  ASSERT_TRUE(cook(cmu, "live-cmu-source"));
  ASSERT_TRUE(cook(cmu + " --retarget-to " + q(r.pab), "live-cmu"));
  const fs::path cmu_source = cache() / "live-cmu-source" / "01_03.ossa";
  const double cmu_mm = live_against_cooked(cmu_source, cmu_source, r.pab, cache() / "live-cmu" / "01_03.ossa");
  std::printf("live against cooked: Pab walk on the Cowboy %.5f mm, CMU 01_03 on Pab %.5f mm\n", pab_mm, cmu_mm);
  EXPECT_LT(pab_mm, 0.1);
  EXPECT_LT(cmu_mm, 0.1);
}

/// Writes `json` as NAME.graph.json into a folder of its own and cooks it into cache()/sub (reads
/// allowed in the shared assets, the repository's assets and the cache); returns the exit status.
int cook_graph(const std::string& name, const std::string& json, const std::string& sub, std::string* err = nullptr) {
  const fs::path dir = ossa::test::make_temp_dir("retarget-graph");
  const fs::path file = dir / (name + ".graph.json");
  EXPECT_TRUE(ossa::test::write_file(file, json));
  const auto r = run_command(tool("ossa-cook") + " -q " + q(file) + " --root " + q(dir) + " --allow-dir " +
                             q(ossa::test::shared_assets()) + " --allow-dir " + q(ossa::test::source_dir() / "assets") +
                             " --allow-dir " + q(cache()) + " --force -o " + q(cache() / sub));
  if (err != nullptr) *err = r.err;
  return r.exit_code;
}

/// A graph over the rig in `skeleton` whose root is `node` (JSON), with a "speed" parameter.
std::string graph_json(const std::string& name, const fs::path& skeleton, const std::string& node,
                       const std::string& clips = "{}") {
  return R"({"ossa_graph": 1, "name": ")" + name + R"(", "skeleton": )" + nlohmann::json(skeleton.string()).dump() +
         R"(, "clips": )" + clips + R"(, "parameters": {"speed": {"type": "float", "default": 1, "min": 0, "max": 3}},
            "root": )" +
         node + "}";
}

std::string path_json(const fs::path& p) { return nlohmann::json(p.string()).dump(); }

/// Plays graph `name` of `character` with `files` and compares every frame but the last (where a
/// looping node wraps) with `expected`; the worst joint distance in mm. `allocations`, when given,
/// receives how many times the updates after the first allocated.
double graph_against(const ossa::Asset& character, const std::string& name, std::span<const ossa::Asset* const> files,
                     const std::vector<ossa::Pose>& expected, float rate, size_t* allocations = nullptr) {
  auto def = ossa::GraphDefinition::create(character, name, files);
  EXPECT_TRUE(def.ok()) << def.error().message;
  if (!def.ok()) return 1e9;
  auto instance = ossa::GraphInstance::create(*def);
  EXPECT_TRUE(instance.ok()) << instance.error().message;
  if (!instance.ok() || expected.empty()) return 1e9;
  const ossa::SkeletonView sk = character.skeleton();
  ossa::Pose got(static_cast<uint32_t>(sk.joint_count()));
  double worst = 0.0;
  instance->update(0.0f);
  for (size_t f = 0; f + 1 < expected.size(); ++f) {
    worst = std::max(worst, pose_distance_mm(sk, character.file().metres_per_unit(), instance->pose(), expected[f]));
    const size_t before = ossa::test::allocation_count();
    instance->update(1.0f / rate);
    if (allocations != nullptr) *allocations += ossa::test::allocation_count() - before;
  }
  return worst;
}

TEST(RetargetGraph, NodeEqualsTheLiveJob) {
  // Pab's walk (a clip library cooked once for Pab) played on the Cowboy by a graph's retarget
  // node, against the live job run on the same clip with the same contact passes.
  if (!have_assets()) GTEST_SKIP() << "no ../shared/assets";
  const Rigs r = rigs();
  const std::string walk = q(shared("Pab/walk.fbx")) + " --skeleton " + q(r.pab) + " --no-clip-compression";
  ASSERT_TRUE(cook(walk, "live-source"));
  std::string err;
  ASSERT_EQ(
      cook_graph("cowboy_walks_like_pab",
                 graph_json("cowboy_walks_like_pab", shared("Quaternius_Cowboy/Cowboy.fbx"),
                            R"({"retarget": "walk", "rig": )" + path_json(r.pab) + R"(, "rate_parameter": "speed"})"),
                 "graph-cowboy", &err),
      0)
      << err;
  auto character = ossa::Asset::open((cache() / "graph-cowboy" / "cowboy_walks_like_pab.ossa").string());
  auto rig = ossa::Asset::open(r.pab.string());
  auto library = ossa::Asset::open((cache() / "live-source" / "walk.ossa").string());
  ASSERT_TRUE(character.ok() && rig.ok() && library.ok());
  // The node's times: its clip time advanced by each update's 1/rate s (float sums, as the graph
  // adds them; sampled at exact grid times instead, a contact's edge moves by a rounding).
  const ossa::ClipView clip = library->clip(0);
  std::vector<float> times = {0.0f};
  while (times.size() < clip.frame_count())
    times.push_back(ossa::advance_time(times.back(), 1.0f / clip.sample_rate(), 1.0f, clip.duration(), true));
  const std::vector<ossa::Pose> live = live_frames(*rig, clip, *character, times);
  const ossa::Asset* files[] = {&*library, &*rig};
  size_t allocations = 0;
  const double mm = graph_against(*character, "cowboy_walks_like_pab", files, live, clip.sample_rate(), &allocations);
  EXPECT_EQ(allocations, 0u) << "the retarget node's updates allocated";
  std::printf("graph retarget node against the live job (Pab walk on the Cowboy): %.6f mm\n", mm);
  EXPECT_LT(mm, 1e-4);

  // Without the source rig among the files, the definition says which rig it needs.
  const ossa::Asset* clip_only[] = {&*library};
  auto missing = ossa::GraphDefinition::create(*character, "cowboy_walks_like_pab", clip_only);
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().message.find("clip 'walk' is played by a retarget node on another rig"), std::string::npos)
      << missing.error().message;
  EXPECT_NE(missing.error().message.find("no file given holds that skeleton"), std::string::npos)
      << missing.error().message;
}

TEST(RetargetGraph, NodeThroughAMapFileEqualsTheCookedRetarget) {
  // assets/CesiumMan/cesium_walks_like_pab.graph.json: CesiumMan (mapped by its map file) playing
  // Pab's walk from a clip library cooked once for Pab, against ossa-cook --retarget-to onto the
  // graph's character with the same map. The repository's samples only.
  const fs::path assets = ossa::test::source_dir() / "assets";
  ASSERT_TRUE(cook(q(assets / "CesiumMan" / "cesium_walks_like_pab.graph.json") + " --root " + q(assets), "graph"));
  ASSERT_TRUE(cook(q(assets / "Pab" / "skeleton.fbx") + " --root " + q(assets), "graph-pab"));
  const fs::path pab = cache() / "graph-pab" / "Pab" / "skeleton.ossa";
  const std::string walk = q(assets / "Pab" / "walk.fbx") + " --skeleton " + q(pab) + " --no-clip-compression";
  ASSERT_TRUE(cook(walk, "graph-library"));
  const fs::path character = cache() / "graph" / "CesiumMan" / "cesium_walks_like_pab.ossa";
  ASSERT_TRUE(cook(walk + " --retarget-to " + q(character) + " --map " + q(cesium_map()), "graph-cooked"));
  auto cesium = ossa::Asset::open(character.string());
  auto rig = ossa::Asset::open(pab.string());
  auto library = ossa::Asset::open((cache() / "graph-library" / "walk.ossa").string());
  auto cooked = ossa::Asset::open((cache() / "graph-cooked" / "walk.ossa").string());
  ASSERT_TRUE(cesium.ok() && rig.ok() && library.ok() && cooked.ok());
  const ossa::ClipView clip = cooked->clip(0);
  auto cache_c = ossa::make_sampling_cache(clip, cesium->skeleton());
  ASSERT_TRUE(cache_c.ok());
  std::vector<ossa::Pose> expected;
  for (uint32_t f = 0; f < clip.frame_count(); ++f) {
    expected.emplace_back(static_cast<uint32_t>(cesium->skeleton().joint_count()));
    ossa::sample(clip, static_cast<float>(f) / clip.sample_rate(), {false}, *cache_c, expected.back());
  }
  const ossa::Asset* files[] = {&*rig, &*library};
  const double mm = graph_against(*cesium, "cesium_walks_like_pab", files, expected, clip.sample_rate());
  std::printf("graph retarget node against the cooked retarget (Pab walk on CesiumMan, map file): %.5f mm\n", mm);
  EXPECT_LT(mm, 0.1);
}

TEST(RetargetGraph, CompileMistakesAreNamed) {
  if (!have_assets()) GTEST_SKIP() << "no ../shared/assets";
  const Rigs r = rigs();
  const fs::path cowboy = shared("Quaternius_Cowboy/Cowboy.fbx");
  const auto fails = [&](const std::string& what, const std::string& node, std::vector<std::string> words,
                         const std::string& clips = "{}") {
    std::string err;
    EXPECT_EQ(cook_graph("bad", graph_json("bad", cowboy, node, clips), "graph-bad", &err), 1) << what;
    EXPECT_NE(err.find("bad.graph.json:"), std::string::npos) << what << "\n" << err;
    for (const std::string& w : words) EXPECT_NE(err.find(w), std::string::npos) << what << ": '" << w << "'\n" << err;
  };
  // A source rig whose names say nothing (no map file): every missing bone named.
  fails("unmapped rig", R"({"retarget": "walk", "rig": )" + path_json(r.cesium) + "}",
        {"CesiumMan.ossa (the retarget node's source rig): missing humanoid bones: hips, spine, head,", "rightFoot"});
  // A map file naming a joint the rig lacks.
  const fs::path map = cache() / "bad.humanoid.json";  // inside the folders the cook may read
  ASSERT_TRUE(ossa::test::write_file(map, R"({"ossa_humanoid_map": 1, "source": {"bones": {"hips": "NoSuchJoint"}}})"));
  fails("map joint", R"({"retarget": "walk", "rig": )" + path_json(r.pab) + R"(, "map": )" + path_json(map) + "}",
        {"bad.humanoid.json", "NoSuchJoint"});
  fails("map bone typo",
        R"({"retarget": "walk", "rig": )" + path_json(r.pab) + R"(, "map": )" + path_json(cesium_map()) +
            R"(, "contact": true})",
        {"\"contact\""});
  fails("no rig file", R"({"retarget": "walk", "rig": "no-such-rig.ossa"})", {"no-such-rig.ossa: no such rig file"});
  fails("no rig", R"({"retarget": "walk"})", {"a retarget node needs \"rig\""});
  // The graph's own clip (made for its rig) is not a clip of another rig, and the other way round.
  const std::string own = R"({"idle": )" + path_json(shared("Quaternius_Cowboy/Cowboy.fbx")) + "}";
  fails("own clip", R"({"retarget": "idle", "rig": )" + path_json(r.pab) + "}",
        {"clip 'idle' is one of the graph's own clips"}, own);
  fails("clip node on a retarget clip",
        R"({"blend": [{"retarget": "walk", "rig": )" + path_json(r.pab) + R"(}, {"clip": "walk"}], "alpha": "speed"})",
        {"clip 'walk' is a retarget node's clip of another rig"});
  fails("bad start", R"({"retarget": "walk", "rig": )" + path_json(r.pab) + R"(, "start": -1})", {"\"start\""});
}

}  // namespace
