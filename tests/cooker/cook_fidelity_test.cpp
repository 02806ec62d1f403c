// cook_fidelity_test.cpp — what a cook keeps of sources nobody here made (issue "Cooked = source"):
// rig-only files, unnamed joints, point/line-only meshes, clip names that exporters invent,
// materials no mesh uses, and vertex colours. Each case is a small real source the test writes (Collada, ASCII FBX,
// OBJ, BVH), cooked by the real ossa-cook through Assimp and read back by the verifying loader.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include <flatbuffers/flatbuffers.h>

#include <ossa/anim/pose.h>
#include <ossa/anim/sample.h>
#include <ossa/format/vertex_codec.h>
#include <ossa/loader/asset.h>
#include "fbx_text.h"
#include "test_files.h"

namespace fs = std::filesystem;
using ossa::test::run_command;

namespace {

std::string cook_cmd() { return (ossa::test::bin_dir() / "ossa-cook").string(); }
std::string q(const fs::path& p) { return "'" + p.string() + "'"; }

bool contains(const std::string& text, const std::string& what) { return text.find(what) != std::string::npos; }

/// A Collada rig with no mesh and no animation: Hips (1 m up) > Spine (+0.2) > Head (+0.4), and
/// Hips > LegL; plus a camera node beside it that must not become a joint.
const char* kRigDae = R"(<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="meter" meter="1"/><up_axis>Y_UP</up_axis></asset>
  <library_visual_scenes>
    <visual_scene id="Scene" name="Scene">
      <node id="Hips" name="Hips" sid="Hips" type="JOINT">
        <matrix sid="transform">1 0 0 0 0 1 0 1 0 0 1 0 0 0 0 1</matrix>
        <node id="Spine" name="Spine" sid="Spine" type="JOINT">
          <matrix sid="transform">1 0 0 0 0 1 0 0.2 0 0 1 0 0 0 0 1</matrix>
          <node id="Head" name="Head" sid="Head" type="JOINT">
            <matrix sid="transform">1 0 0 0 0 1 0 0.4 0 0 1 0 0 0 0 1</matrix>
          </node>
        </node>
        <node id="LegL" name="LegL" sid="LegL" type="JOINT">
          <matrix sid="transform">1 0 0 0.1 0 1 0 -0.5 0 0 1 0 0 0 0 1</matrix>
        </node>
      </node>
    </visual_scene>
  </library_visual_scenes>
  <scene><instance_visual_scene url="#Scene"/></scene>
</COLLADA>
)";

/// An ASCII FBX rig: LimbNodes Hips > "" > "", the two below Hips without names (some exporters
/// write "Model::" and Assimp keeps the empty name).
const std::string kUnnamedFbx =
    ossa::test::fbx_ascii_head("\t\tP: \"UnitScaleFactor\", \"double\", \"Number\", \"\",1\n") + R"(Objects:  {
	Model: 1000, "Model::Hips", "LimbNode" {
		Version: 232
		Properties70:  {
			P: "Lcl Translation", "Lcl Translation", "", "A",0,100,0
		}
	}
	Model: 1001, "Model::", "LimbNode" {
		Version: 232
		Properties70:  {
			P: "Lcl Translation", "Lcl Translation", "", "A",0,20,0
		}
	}
	Model: 1002, "Model::", "LimbNode" {
		Version: 232
		Properties70:  {
			P: "Lcl Translation", "Lcl Translation", "", "A",0,30,0
		}
	}
}
Connections:  {
	C: "OO",1000,0
	C: "OO",1001,1000
	C: "OO",1002,1001
}
)";

/// A two-joint BVH with three frames; Assimp names its one clip "Motion".
const char* kBvh = R"(HIERARCHY
ROOT Hips
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT Spine
  {
    OFFSET 0 10 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    End Site
    {
      OFFSET 0 10 0
    }
  }
}
MOTION
Frames: 3
Frame Time: 0.033333
0 90 0 0 0 0 0 0 0
1 90 0 0 10 0 5 0 0
2 90 0 0 20 0 10 0 0
)";

struct Cooked {
  ossa::test::CommandResult run;
  fs::path out;
};

Cooked cook(const fs::path& dir, const std::string& file, const std::string& text, const std::string& extra = "") {
  EXPECT_TRUE(ossa::test::write_file(dir / file, std::vector<uint8_t>(text.begin(), text.end())));
  Cooked c{run_command(cook_cmd() + " " + q(dir / file) + " -o " + q(dir / "out") + " -v " + extra), dir / "out"};
  return c;
}

/// The cooked output of `c` named `file`, opened by the verifying loader (the test fails if not).
std::optional<ossa::Asset> open_cooked(const Cooked& c, const std::string& file) {
  auto a = ossa::Asset::open((c.out / file).string());
  EXPECT_TRUE(a.ok()) << a.error().message;
  if (!a.ok()) return std::nullopt;
  return std::move(*a);
}

TEST(CookFidelity, RigOnlyColladaCooksAsASkeleton) {
  const fs::path dir = ossa::test::make_temp_dir("fidelity-rig");
  const Cooked c = cook(dir, "rig.dae", kRigDae);
  ASSERT_EQ(c.run.exit_code, 0) << c.run.err;
  EXPECT_TRUE(contains(c.run.err, "no mesh and no animation")) << c.run.err;
  auto a = open_cooked(c, "rig.ossa");
  ASSERT_TRUE(a);
  const ossa::SkeletonView s = a->skeleton();
  ASSERT_EQ(s.joint_count(), 4u);
  EXPECT_EQ(s.joint_name(0), "Hips");
  EXPECT_EQ(s.parents()[0], -1);
  const int head = s.find_joint("Head"), spine = s.find_joint("Spine"), leg = s.find_joint("LegL");
  ASSERT_GE(head, 0);
  ASSERT_GE(spine, 0);
  ASSERT_GE(leg, 0);
  EXPECT_EQ(s.parents()[static_cast<size_t>(head)], spine);
  EXPECT_EQ(s.parents()[static_cast<size_t>(leg)], 0);
  EXPECT_NEAR(s.bind_translations()[static_cast<size_t>(head)].y(), 0.4f, 1e-6f);
  EXPECT_NEAR(s.bind_translations()[static_cast<size_t>(leg)].x(), 0.1f, 1e-6f);
  EXPECT_EQ(a->mesh_count(), 0u);
  EXPECT_EQ(a->material_count(), 0u) << "Assimp's generated SkeletonMaterial is used by no mesh";
}

TEST(CookFidelity, UnnamedJointsGetStableNamesByIndex) {
  const fs::path dir = ossa::test::make_temp_dir("fidelity-unnamed");
  const Cooked c = cook(dir, "rig.fbx", kUnnamedFbx);
  ASSERT_EQ(c.run.exit_code, 0) << c.run.err;
  EXPECT_FALSE(contains(c.run.err, "internal error")) << c.run.err;
  EXPECT_TRUE(contains(c.run.err, "2 joints have no name in the source")) << c.run.err;
  auto a = open_cooked(c, "rig.ossa");
  ASSERT_TRUE(a);
  const ossa::SkeletonView s = a->skeleton();
  ASSERT_EQ(s.joint_count(), 3u);
  EXPECT_EQ(s.joint_name(0), "Hips");
  EXPECT_EQ(s.joint_name(1), "joint1");
  EXPECT_EQ(s.joint_name(2), "joint2");
  EXPECT_EQ(s.parents()[2], 1);
  EXPECT_NEAR(s.bind_translations()[2].y(), 30.0f, 1e-4f);
  // Stable: a second cook gives the same bytes.
  const fs::path again = dir / "again";
  const auto r = run_command(cook_cmd() + " " + q(dir / "rig.fbx") + " -o " + q(again) + " -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(ossa::test::read_file(again / "rig.ossa"), ossa::test::read_file(c.out / "rig.ossa"));
}

TEST(CookFidelity, PointAndLineOnlyMeshesAreSaidToBeSo) {
  const fs::path dir = ossa::test::make_temp_dir("fidelity-lines");
  for (const auto& [file, text] :
       {std::pair<std::string, std::string>{"lines.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nl 1 2\nl 2 3\n"},
        {"points.obj", "v 0 0 0\nv 1 0 0\np 1\np 2\n"}}) {
    const Cooked c = cook(dir, file, text);
    EXPECT_EQ(c.run.exit_code, 1) << file;
    EXPECT_TRUE(contains(c.run.err, file + ": its 1 mesh holds only points or lines")) << c.run.err;
    EXPECT_FALSE(fs::exists(c.out / (fs::path(file).stem().string() + ".ossa"))) << file;
  }
}

TEST(CookFidelity, AGenericSingleClipNameBecomesTheFileStem) {
  const fs::path dir = ossa::test::make_temp_dir("fidelity-clipname");
  const Cooked c = cook(dir, "walk_fast.bvh", kBvh);
  ASSERT_EQ(c.run.exit_code, 0) << c.run.err;
  EXPECT_TRUE(contains(c.run.err, "clip 'Motion' is named 'walk_fast' after the file")) << c.run.err;
  auto a = open_cooked(c, "walk_fast.ossa");
  ASSERT_TRUE(a);
  ASSERT_EQ(a->clip_count(), 1u);
  EXPECT_EQ(a->clip(0).name(), "walk_fast");
  EXPECT_EQ(a->material_count(), 0u);
}

TEST(CookFidelity, SidecarsAndSettingsMayStillUseTheSourceClipName) {
  const fs::path dir = ossa::test::make_temp_dir("fidelity-clipname-source");
  const std::string events = R"({"ossa_events": 1, "clips": {"Motion": [{"name": "step", "time": 0.03}]}})";
  ASSERT_TRUE(ossa::test::write_file(dir / "stroll.events.json", std::vector<uint8_t>(events.begin(), events.end())));
  const std::string settings = R"({"ossa_cook": 1, "clip_names": {"Motion": "amble"}})";
  ASSERT_TRUE(ossa::test::write_file(dir / "stroll.cook.json", std::vector<uint8_t>(settings.begin(), settings.end())));
  const Cooked c = cook(dir, "stroll.bvh", kBvh);
  ASSERT_EQ(c.run.exit_code, 0) << c.run.err;
  auto a = open_cooked(c, "stroll.ossa");
  ASSERT_TRUE(a);
  ASSERT_EQ(a->clip_count(), 1u);
  EXPECT_EQ(a->clip(0).name(), "amble");
  const auto* events_cooked = a->clip(0).fb->events();
  ASSERT_NE(events_cooked, nullptr) << "the sidecar's events, keyed by the source name, reached the clip";
  EXPECT_EQ(events_cooked->size(), 1u);
}

TEST(CookFidelity, GenericNamesAreRecognisedAndMeaningfulOnesKept) {
  // One-clip glTF files, the animation named as exporters name it.
  const fs::path dir = ossa::test::make_temp_dir("fidelity-gltf-names");
  const fs::path src = ossa::test::shared_assets() / "Khronos_embedded" / "rigged_simple.gltf";
  if (!fs::exists(src)) GTEST_SKIP() << "no " << src;
  const auto text = ossa::test::read_file(src);
  ASSERT_TRUE(text);
  nlohmann::json doc = nlohmann::json::parse(text->begin(), text->end());
  ASSERT_EQ(doc["animations"].size(), 1u);
  struct Case {
    std::string source_name, file_stem, expected;
  };
  const std::vector<Case> cases = {
      {"mixamo.com", "a1", "a1"},  {"Armature|mixamo.com", "a2", "a2"},      {"Take 001", "a3", "a3"},
      {"Unreal Take", "a4", "a4"}, {"Armature|Action.001", "a5", "a5"},      {"Bone", "a6", "a6"},
      {"Wave", "k1", "Wave"},      {"Armature|Wave", "k2", "Armature|Wave"}, {"Takeoff", "k3", "Takeoff"},
      {"animal", "k4", "animal"}};
  for (const auto& [name, stem, expected] : cases) {
    doc["animations"][0]["name"] = name;
    const std::string body = doc.dump();
    ASSERT_TRUE(ossa::test::write_file(dir / (stem + ".gltf"), std::vector<uint8_t>(body.begin(), body.end())));
    const auto r = run_command(cook_cmd() + " " + q(dir / (stem + ".gltf")) + " -o " + q(dir / "out") + " -q");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    auto a = ossa::Asset::open((dir / "out" / (stem + ".ossa")).string());
    ASSERT_TRUE(a.ok()) << a.error().message;
    ASSERT_EQ(a->clip_count(), 1u);
    EXPECT_EQ(a->clip(0).name(), expected) << "source name '" << name << "'";
  }
}

TEST(CookFidelity, FilesWithSeveralClipsKeepTheirNames) {
  const fs::path fox = ossa::test::source_dir() / "assets" / "Fox" / "Fox.glb";
  const fs::path dir = ossa::test::make_temp_dir("fidelity-fox");
  const auto r = run_command(cook_cmd() + " " + q(fox) + " -o " + q(dir) + " -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto a = ossa::Asset::open((dir / "Fox.ossa").string());
  ASSERT_TRUE(a.ok()) << a.error().message;
  ASSERT_EQ(a->clip_count(), 3u);
  EXPECT_EQ(a->clip(0).name(), "Survey");
  EXPECT_EQ(a->clip(1).name(), "Walk");
  EXPECT_EQ(a->clip(2).name(), "Run");
  // Fox.glb has a default material besides its textured one, used by no mesh: left out.
  EXPECT_EQ(a->material_count(), 1u);
}

/// An uncompressed 24-bit TGA, 2 x 2: red, green / blue, white (bottom row first, as TGA stores).
std::vector<uint8_t> tiny_tga() {
  std::vector<uint8_t> b = {0, 0, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 0, 2, 0, 24, 0};
  for (uint8_t v : {0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255}) b.push_back(v);  // BGR
  return b;
}

/// An OBJ quad whose material names its diffuse map as `map`.
void write_obj_with_texture(const fs::path& dir, const std::string& stem, const std::string& map) {
  const std::string obj = "mtllib " + stem +
                          ".mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                          "vn 0 0 1\nusemtl skin\nf 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n";
  const std::string mtl = "newmtl skin\nKd 1 1 1\nmap_Kd " + map + "\n";
  ASSERT_TRUE(ossa::test::write_file(dir / (stem + ".obj"), obj));
  ASSERT_TRUE(ossa::test::write_file(dir / (stem + ".mtl"), mtl));
}

size_t count_of(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(CookFidelity, AbsoluteWindowsTexturePathIsFoundByNameAndTgaEmbeddedAsPng) {
  const fs::path dir = ossa::test::make_temp_dir("fidelity-texture");
  ASSERT_TRUE(ossa::test::write_file(dir / "skin.tga", tiny_tga()));
  write_obj_with_texture(dir, "quad", "C:\\Users\\artist\\textures\\skin.tga");
  // Kept as source bytes, so the conversion to PNG shows; the default cook is checked below.
  const auto r =
      run_command(cook_cmd() + " " + q(dir / "quad.obj") + " -o " + q(dir / "out") + " -v --texture-format source");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(count_of(r.err, "is absolute, looked up as 'skin.tga' next to the source"), 1u) << r.err;
  EXPECT_EQ(count_of(r.err, "is a TGA image, embedded as PNG"), 1u) << r.err;
  auto a = ossa::Asset::open((dir / "out" / "quad.ossa").string());
  ASSERT_TRUE(a.ok()) << a.error().message;
  ASSERT_EQ(a->material_count(), 1u);
  const auto* textures = a->material(0).textures();
  ASSERT_NE(textures, nullptr);
  ASSERT_EQ(textures->size(), 1u);
  const auto* tex = textures->Get(0);
  EXPECT_EQ(flatbuffers::GetStringView(tex->mime()), "image/png");
  EXPECT_EQ(flatbuffers::GetStringView(tex->path()), "skin.tga") << "the path kept is relative, never C:\\...";
  ASSERT_NE(tex->data(), nullptr);
  const std::vector<uint8_t> png(tex->data()->begin(), tex->data()->end());
  ASSERT_GE(png.size(), 8u);
  EXPECT_EQ(png[1], 'P');
  EXPECT_EQ(png[2], 'N');
  EXPECT_EQ(png[3], 'G');
  // By default the TGA's texels become a GPU-ready chain like any other image.
  const auto bc = run_command(cook_cmd() + " " + q(dir / "quad.obj") + " -o " + q(dir / "bc"));
  ASSERT_EQ(bc.exit_code, 0) << bc.err;
  auto cooked = ossa::Asset::open((dir / "bc" / "quad.ossa").string());
  ASSERT_TRUE(cooked.ok()) << cooked.error().message;
  EXPECT_NE(cooked->material(0).textures()->Get(0)->encoding(), ossa::fb::TextureEncoding::Source);
  EXPECT_GE(cooked->material(0).textures()->Get(0)->mip_count(), 1u);
}

TEST(CookFidelity, ATextFileNamedTgaIsRefusedByName) {
  const fs::path dir = ossa::test::make_temp_dir("fidelity-fake-tga");
  ASSERT_TRUE(ossa::test::write_file(dir / "skin.tga", std::string("this is not an image, whatever its name says\n")));
  write_obj_with_texture(dir, "quad", "skin.tga");
  const auto r = run_command(cook_cmd() + " " + q(dir / "quad.obj") + " -o " + q(dir / "out"));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_TRUE(contains(r.err, "texture 'skin.tga' is not a TGA image")) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out" / "quad.ossa"));
}

/// The root's (Hips) sampled translation at `time` of the only clip of `clip_file` on `rig_file`.
glm::vec3 root_at(const fs::path& rig_file, const fs::path& clip_file, float time) {
  auto rig = ossa::Asset::open(rig_file.string());
  auto clips = ossa::Asset::open(clip_file.string());
  EXPECT_TRUE(rig.ok() && clips.ok());
  if (!rig.ok() || !clips.ok()) return glm::vec3(NAN);
  const ossa::ClipView clip = clips->clip(0);
  auto cache = ossa::make_sampling_cache(clip, rig->skeleton());
  EXPECT_TRUE(cache.ok());
  if (!cache.ok()) return glm::vec3(NAN);
  ossa::Pose pose(static_cast<uint32_t>(rig->skeleton().joint_count()));
  ossa::SampleOptions options;
  options.loop = false;
  ossa::sample(clip, time, options, *cache, pose);
  return ossa::get_transform(pose, 0).translation;
}

TEST(CookFidelity, AClipInOtherUnitsIsConvertedIntoTheRigsUnits) {
  const fs::path dir = ossa::test::make_temp_dir("fidelity-units");
  fs::create_directories(dir / "rig");
  fs::create_directories(dir / "cm");
  ASSERT_TRUE(ossa::test::write_file(dir / "rig" / "actor.bvh", std::string(kBvh)));
  ASSERT_TRUE(ossa::test::write_file(dir / "cm" / "take.bvh", std::string(kBvh)));
  // The rig in metres (BVH states no unit: 1 m assumed, and said so).
  auto r = run_command(cook_cmd() + " " + q(dir / "rig" / "actor.bvh") + " -o " + q(dir / "out") + " -v");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(contains(r.err, "BVH states no length unit: 1 metre per unit assumed")) << r.err;
  // The same motion, its unit stated as centimetres: converted into the rig's metres.
  r = run_command(cook_cmd() + " " + q(dir / "cm" / "take.bvh") + " --skeleton " + q(dir / "out" / "actor.ossa") +
                  " --metres-per-unit 0.01 -o " + q(dir / "out") + " -v");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(contains(r.err, "converted from the file's unit (0.01 m) to the reference rig's (1 m): lengths x 0.01"))
      << r.err;
  // Frame 1 of kBvh puts Hips at (1, 90, 0) source units.
  const float t1 = 0.033333f;
  const glm::vec3 in_rig_units = root_at(dir / "out" / "actor.ossa", dir / "out" / "take.ossa", t1);
  EXPECT_NEAR(in_rig_units.x, 0.01f, 1e-4f);
  EXPECT_NEAR(in_rig_units.y, 0.90f, 1e-3f);
  const glm::vec3 own = root_at(dir / "out" / "actor.ossa", dir / "out" / "actor.ossa", t1);
  EXPECT_NEAR(own.y, 90.0f, 0.1f) << "the rig's own clip keeps the rig's units";
  auto cooked = ossa::Asset::open((dir / "out" / "take.ossa").string());
  ASSERT_TRUE(cooked.ok());
  EXPECT_FLOAT_EQ(cooked->file().metres_per_unit(), 1.0f) << "the clip file states the rig's unit";

  // The same through a per-asset setting, which also enters the cook key.
  ASSERT_TRUE(ossa::test::write_file(dir / "cm" / "take.cook.json",
                                     std::string(R"({"ossa_cook": 1, "metres_per_unit": 0.01})")));
  r = run_command(cook_cmd() + " " + q(dir / "cm" / "take.bvh") + " --skeleton " + q(dir / "out" / "actor.ossa") +
                  " -o " + q(dir / "set") + " -v");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NEAR(root_at(dir / "out" / "actor.ossa", dir / "set" / "take.ossa", t1).y, 0.90f, 1e-3f);
}

/// A Collada arm: joints Upper > Lower, a six-vertex strip skinned to them with inverse bind
/// matrices for a straight arm (Lower 1 m above Upper, unrotated), while the nodes stand bent (Lower
/// turned 90 degrees about z): a source exported mid-pose.
const char* kBentArmDae = R"(<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="meter" meter="1"/><up_axis>Y_UP</up_axis></asset>
  <library_geometries>
    <geometry id="arm-mesh" name="arm">
      <mesh>
        <source id="arm-pos">
          <float_array id="arm-pos-array" count="18">-0.1 0 0  0.1 0 0  0.1 1 0  -0.1 1 0  0.1 2 0  -0.1 2
            0</float_array>
          <technique_common><accessor source="#arm-pos-array" count="6" stride="3">
            <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/></accessor>
              </technique_common>
        </source>
        <vertices id="arm-verts"><input semantic="POSITION" source="#arm-pos"/></vertices>
        <triangles count="4">
          <input semantic="VERTEX" source="#arm-verts" offset="0"/>
          <p>0 1 2 0 2 3 3 2 4 3 4 5</p>
        </triangles>
      </mesh>
    </geometry>
  </library_geometries>
  <library_controllers>
    <controller id="arm-skin">
      <skin source="#arm-mesh">
        <bind_shape_matrix>1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1</bind_shape_matrix>
        <source id="arm-joints"><Name_array id="arm-joints-array" count="2">Upper Lower</Name_array>
          <technique_common><accessor source="#arm-joints-array" count="2" stride="1">
            <param name="JOINT" type="name"/></accessor></technique_common></source>
        <source id="arm-ibm">
          <float_array id="arm-ibm-array" count="32">1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1  1 0 0 0 0 1 0 -1 0 0 1 0 0 0 0
            1</float_array>
          <technique_common><accessor source="#arm-ibm-array" count="2" stride="16">
            <param name="TRANSFORM" type="float4x4"/></accessor></technique_common></source>
        <source id="arm-weights"><float_array id="arm-weights-array" count="2">1 1</float_array>
          <technique_common><accessor source="#arm-weights-array" count="2" stride="1">
            <param name="WEIGHT" type="float"/></accessor></technique_common></source>
        <joints><input semantic="JOINT" source="#arm-joints"/><input semantic="INV_BIND_MATRIX" source="#arm-ibm"/>
          </joints>
        <vertex_weights count="6">
          <input semantic="JOINT" source="#arm-joints" offset="0"/>
            <input semantic="WEIGHT" source="#arm-weights" offset="1"/>
          <vcount>1 1 1 1 1 1</vcount>
          <v>0 0 0 0 1 1 1 1 1 1 1 1</v>
        </vertex_weights>
      </skin>
    </controller>
  </library_controllers>
  <library_visual_scenes>
    <visual_scene id="Scene" name="Scene">
      <node id="Upper" name="Upper" sid="Upper" type="JOINT">
        <matrix sid="transform">1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1</matrix>
        <node id="Lower" name="Lower" sid="Lower" type="JOINT">
          <matrix sid="transform">0 -1 0 0 1 0 0 1 0 0 1 0 0 0 0 1</matrix>
        </node>
      </node>
      <node id="arm" name="arm">
        <instance_controller url="#arm-skin"><skeleton>#Upper</skeleton></instance_controller>
      </node>
    </visual_scene>
  </library_visual_scenes>
  <scene><instance_visual_scene url="#Scene"/></scene>
</COLLADA>
)";

TEST(CookFidelity, TheBindPoseIsThePoseTheSkinWasBoundInNotTheNodePose) {
  const fs::path dir = ossa::test::make_temp_dir("fidelity-bind");
  const Cooked c = cook(dir, "bent.dae", kBentArmDae);
  ASSERT_EQ(c.run.exit_code, 0) << c.run.err;
  EXPECT_TRUE(contains(c.run.err, "the skins were bound in another pose than the nodes stand in")) << c.run.err;
  auto a = open_cooked(c, "bent.ossa");
  ASSERT_TRUE(a);
  const ossa::SkeletonView s = a->skeleton();
  ASSERT_EQ(s.joint_count(), 2u);
  const int lower = s.find_joint("Lower");
  ASSERT_EQ(lower, 1);
  const auto& t = s.bind_translations()[1];
  const auto& r = s.bind_rotations()[1];
  EXPECT_NEAR(t.y(), 1.0f, 1e-5f);
  // Straight (the skin's pose), not the nodes' 90 degrees about z (w = 0.707).
  EXPECT_NEAR(std::abs(r.w()), 1.0f, 1e-5f) << "x " << r.x() << " y " << r.y() << " z " << r.z() << " w " << r.w();
}

/// A BVH capture of `frames` frames at 120 fps: the root walks along x (1 cm a frame) and the
/// spine sways (frame-dependent z rotation), so every frame is a distinct key.
std::string long_bvh(uint32_t frames) {
  std::string text =
      "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n  CHANNELS 6 Xposition Yposition Zposition Zrotation "
      "Xrotation Yrotation\n  JOINT Spine\n  {\n    OFFSET 0 10 0\n    CHANNELS 3 Zrotation Xrotation "
      "Yrotation\n    End Site\n    {\n      OFFSET 0 10 0\n    }\n  }\n}\nMOTION\nFrames: " +
      std::to_string(frames) + "\nFrame Time: 0.0083333333\n";
  char line[128];
  for (uint32_t f = 0; f < frames; ++f) {
    std::snprintf(line, sizeof line, "%.2f 90 0 0 0 0 %.3f 0 0\n", 0.01 * f, 20.0 * std::sin(0.01 * f));
    text += line;
  }
  return text;
}

TEST(CookFidelity, ALongCaptureIsCookedInConsecutiveClipsNotRefused) {
  // 100,000 frames at 120 fps (833 s) is past the 65,536 frames one clip addresses.
  const fs::path dir = ossa::test::make_temp_dir("fidelity-long");
  constexpr uint32_t kFrames = 100000;
  const Cooked c = cook(dir, "session.bvh", long_bvh(kFrames));
  ASSERT_EQ(c.run.exit_code, 0) << c.run.err.substr(0, 2000);
  EXPECT_TRUE(contains(c.run.err,
                       "clip 'session' has 100000 frames at 120 frames/s, more than the 65536 one clip holds: "
                       "cooked as 2 consecutive clips 'session.part1' (0.000-546.125 s), 'session.part2'"))
      << c.run.err.substr(0, 2000);
  auto a = open_cooked(c, "session.ossa");
  ASSERT_TRUE(a);
  ASSERT_EQ(a->clip_count(), 2u);
  EXPECT_EQ(a->clip(0).name(), "session.part1");
  EXPECT_EQ(a->clip(1).name(), "session.part2");
  EXPECT_EQ(a->clip(0).frame_count(), 65536u);
  EXPECT_EQ(a->clip(0).frame_count() + a->clip(1).frame_count() - 1, kFrames) << "parts share their boundary frame";
  EXPECT_FLOAT_EQ(a->clip(0).sample_rate(), 120.0f);
  // The boundary: part 1's last frame and part 2's first are the source's frame 65535 (root at
  // x = 655.35), and a frame well inside part 2 is the source's.
  const auto sample_root = [&](size_t clip_index, float time) {
    const ossa::ClipView clip = a->clip(clip_index);
    auto cache = ossa::make_sampling_cache(clip, a->skeleton());
    EXPECT_TRUE(cache.ok());
    ossa::Pose pose(static_cast<uint32_t>(a->skeleton().joint_count()));
    ossa::SampleOptions options;
    options.loop = false;
    ossa::sample(clip, time, options, *cache, pose);
    return ossa::get_transform(pose, 0).translation;
  };
  const float end1 = a->clip(0).duration();
  EXPECT_NEAR(sample_root(0, end1).x, 655.35f, 0.01f);
  EXPECT_NEAR(sample_root(1, 0.0f).x, 655.35f, 0.01f);
  EXPECT_NEAR(sample_root(1, 10000.0f / 120.0f).x, 0.01f * (65535 + 10000), 0.01f);
}

// ---------------------------------------------------------------------------------------------
// Vertex colours

/// One cooked vertex: de-quantized position and its colour (white when the mesh has none).
struct ColouredVertex {
  glm::vec3 position;
  glm::vec4 colour;
};

std::vector<ColouredVertex> coloured_vertices(const ossa::MeshView& mesh) {
  namespace fb = ossa::fb;
  std::vector<ColouredVertex> out;
  const fb::VertexAttribute* pos = mesh.attribute(fb::VertexSemantic::Position);
  const fb::VertexAttribute* col = mesh.attribute(fb::VertexSemantic::Color0);
  EXPECT_NE(pos, nullptr);
  if (pos == nullptr) return out;
  const fb::Vec3* o = mesh.fb->position_offset();
  const fb::Vec3* sc = mesh.fb->position_scale();
  const auto bytes = mesh.vertex_bytes();
  for (uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    const uint8_t* p = bytes.data() + static_cast<size_t>(v) * mesh.vertex_stride();
    ColouredVertex cv{glm::vec3(0.0f), glm::vec4(1.0f)};
    if (pos->format() == fb::VertexFormat::Unorm16x4) {
      uint16_t q[3];
      std::memcpy(q, p + pos->offset(), sizeof q);
      cv.position =
          glm::vec3(o->x(), o->y(), o->z()) +
          glm::vec3(sc->x(), sc->y(), sc->z()) *
              glm::vec3(ossa::unorm16_to_float(q[0]), ossa::unorm16_to_float(q[1]), ossa::unorm16_to_float(q[2]));
    } else {
      std::memcpy(&cv.position, p + pos->offset(), sizeof cv.position);
    }
    if (col != nullptr && col->format() == fb::VertexFormat::Unorm8x4) {
      for (int k = 0; k < 4; ++k) cv.colour[k] = ossa::unorm8_to_float(p[col->offset() + k]);
    } else if (col != nullptr) {
      EXPECT_EQ(col->format(), fb::VertexFormat::Float32x4);
      std::memcpy(&cv.colour, p + col->offset(), sizeof cv.colour);
    }
    out.push_back(cv);
  }
  return out;
}

/// The colour of the cooked vertex nearest `at` (the test meshes' vertices are far apart).
glm::vec4 colour_at(const std::vector<ColouredVertex>& vertices, glm::vec3 at) {
  const ColouredVertex* best = nullptr;
  for (const auto& v : vertices)
    if (!best || glm::length(v.position - at) < glm::length(best->position - at)) best = &v;
  EXPECT_NE(best, nullptr);
  EXPECT_LT(best ? glm::length(best->position - at) : 1.0f, 1e-3f)
      << "nearest (" << best->position.x << ", " << best->position.y << ", " << best->position.z << ")";
  return best ? best->colour : glm::vec4(-1.0f);
}

/// A glTF triangle (0,0,0) (1,0,0) (0,1,0) whose COLOR_0 is red, green, blue: as normalized
/// unsigned bytes (VEC4, alpha 0.5 on the blue corner) or as floats (VEC3, whose alpha Assimp
/// 5.2.5 loses: the cooker restores the specification's 1).
void write_coloured_gltf(const fs::path& dir, const std::string& stem, bool bytes) {
  const float positions[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::string bin(reinterpret_cast<const char*>(positions), sizeof positions);
  nlohmann::json colour_accessor;
  if (bytes) {
    const uint8_t c[12] = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 128};
    bin.append(reinterpret_cast<const char*>(c), sizeof c);
    colour_accessor = {
        {"bufferView", 1}, {"componentType", 5121}, {"normalized", true}, {"count", 3}, {"type", "VEC4"}};
  } else {
    const float c[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    bin.append(reinterpret_cast<const char*>(c), sizeof c);
    colour_accessor = {{"bufferView", 1}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"}};
  }
  const nlohmann::json j = {
      {"asset", {{"version", "2.0"}}},
      {"scene", 0},
      {"scenes", {{{"nodes", {0}}}}},
      {"nodes", {{{"mesh", 0}}}},
      {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}, {"COLOR_0", 1}}}}}}}}},
      {"buffers", {{{"uri", stem + ".bin"}, {"byteLength", bin.size()}}}},
      {"bufferViews",
       {{{"buffer", 0}, {"byteLength", 36}}, {{"buffer", 0}, {"byteOffset", 36}, {"byteLength", bin.size() - 36}}}},
      {"accessors",
       {{{"bufferView", 0},
         {"componentType", 5126},
         {"count", 3},
         {"type", "VEC3"},
         {"min", {0, 0, 0}},
         {"max", {1, 1, 0}}},
        colour_accessor}}};
  ASSERT_TRUE(ossa::test::write_file(dir / (stem + ".bin"), bin));
  ASSERT_TRUE(ossa::test::write_file(dir / (stem + ".gltf"), j.dump()));
}

void expect_rgb_corners(const ossa::Asset& a, float blue_alpha) {
  ASSERT_EQ(a.mesh_count(), 1u);
  ASSERT_NE(a.mesh(0).attribute(ossa::fb::VertexSemantic::Color0), nullptr) << "colours kept";
  const auto v = coloured_vertices(a.mesh(0));
  const float e = 0.5f / 255.0f + 1e-6f;  // Unorm8's rounding
  const glm::vec4 r = colour_at(v, {0, 0, 0}), g = colour_at(v, {1, 0, 0}), b = colour_at(v, {0, 1, 0});
  for (int k = 0; k < 4; ++k) {
    EXPECT_NEAR(r[k], glm::vec4(1, 0, 0, 1)[k], e) << "component " << k;
    EXPECT_NEAR(g[k], glm::vec4(0, 1, 0, 1)[k], e);
    EXPECT_NEAR(b[k], glm::vec4(0, 0, 1, blue_alpha)[k], e);
  }
}

TEST(CookFidelity, GltfVertexColoursAreCarriedAsStored) {
  const fs::path dir = ossa::test::make_temp_dir("fidelity-colour-gltf");
  write_coloured_gltf(dir, "bytes", true);
  write_coloured_gltf(dir, "floats", false);
  for (const char* stem : {"bytes", "floats"}) {
    const auto r = run_command(cook_cmd() + " " + q(dir / (std::string(stem) + ".gltf")) + " -o " + q(dir / "out"));
    ASSERT_EQ(r.exit_code, 0) << stem << ": " << r.err;
  }
  auto bytes = ossa::Asset::open((dir / "out" / "bytes.ossa").string());
  auto floats = ossa::Asset::open((dir / "out" / "floats.ossa").string());
  ASSERT_TRUE(bytes.ok() && floats.ok());
  expect_rgb_corners(*bytes, 128.0f / 255.0f);
  expect_rgb_corners(*floats, 1.0f);
  // --float-vertices stores them as floats, exactly.
  const auto r = run_command(cook_cmd() + " " + q(dir / "floats.gltf") + " -o " + q(dir / "f32") + " --float-vertices");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto f32 = ossa::Asset::open((dir / "f32" / "floats.ossa").string());
  ASSERT_TRUE(f32.ok());
  EXPECT_EQ(f32->mesh(0).attribute(ossa::fb::VertexSemantic::Color0)->format(), ossa::fb::VertexFormat::Float32x4);
  expect_rgb_corners(*f32, 1.0f);
}

TEST(CookFidelity, ObjVertexColoursAreCarriedClampedOrLeftOutWhenWhite) {
  const fs::path dir = ossa::test::make_temp_dir("fidelity-colour-obj");
  const std::string faces = "f 1 2 3\nf 1 3 4\n";
  // Colours past 1 (an HDR export) are clamped with a warning that names the mesh.
  ASSERT_TRUE(ossa::test::write_file(dir / "painted.obj",
                                     "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 1 1 0 0 0 1\nv 0 1 0 2 0.5 -1\n" + faces));
  ASSERT_TRUE(ossa::test::write_file(dir / "white.obj",
                                     "v 0 0 0 1 1 1\nv 1 0 0 1 1 1\nv 1 1 0 1 1 1\nv 0 1 0 1 1 1\n" + faces));
  const auto r = run_command(cook_cmd() + " " + q(dir / "painted.obj") + " " + q(dir / "white.obj") + " -o " +
                             q(dir / "out") + " -v");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(contains(r.err, "1 vertex colours outside [0, 1] were clamped")) << r.err;
  auto painted = ossa::Asset::open((dir / "out" / "painted.ossa").string());
  auto white = ossa::Asset::open((dir / "out" / "white.ossa").string());
  ASSERT_TRUE(painted.ok() && white.ok());
  const auto v = coloured_vertices(painted->mesh(0));
  EXPECT_EQ(colour_at(v, {1, 1, 0}), glm::vec4(0, 0, 1, 1));
  EXPECT_EQ(colour_at(v, {0, 1, 0}), glm::vec4(1, 128.0f / 255.0f, 0, 1)) << "2 -> 1, 0.5 -> 128 / 255, -1 -> 0";
  EXPECT_EQ(white->mesh(0).attribute(ossa::fb::VertexSemantic::Color0), nullptr)
      << "all-white colours draw as no colours and cost no bytes";
}

}  // namespace
