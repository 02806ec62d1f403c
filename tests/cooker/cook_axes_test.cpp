// cook_axes_test.cpp — every output is Y-up, whatever axis its source calls up (issue 28: Z-up SMD
// files rendered lying down). Each case is a column two units tall along its source's up axis,
// written by the test: Valve SMD (Z-up by convention) skinned to two bones with a clip, Collada
// stating Z_UP and X_UP, an ASCII FBX rig whose GlobalSettings say UpAxis 2, and --up-axis over
// a file's statement. Cooked by the real ossa-cook; "standing" means the tallest extent of the
// mesh as skinned in the bind pose (what a viewer draws), of the joints in the bind pose and of
// the joints in a sampled frame is along +Y.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include <ossa/anim/pose.h>
#include <ossa/anim/pose_ops.h>
#include <ossa/anim/sample.h>
#include <ossa/loader/asset.h>
#include <ossa/skinning/skinning.h>
#include "fbx_text.h"
#include "test_files.h"

namespace fs = std::filesystem;
using ossa::test::fbx_ascii_head;
using ossa::test::run_command;

namespace {

std::string q(const fs::path& p) { return "'" + p.string() + "'"; }

/// `p` written in a source whose up is `up` (0 x, 1 y, 2 z) and whose ground is the other two,
/// right-handed: the inverse of the cooker's turn to Y-up.
glm::vec3 in_source(glm::vec3 p, int up) {
  if (up == 2) return {p.x, -p.z, p.y};
  if (up == 0) return {p.y, -p.x, p.z};
  return p;
}

/// A Valve SMD column 0.4 x 0.4 x 2 standing on +`up`: bone "root" at the origin, "top" 1 up,
/// each holding half the column, and a 3-frame clip that bends "top".
std::string column_smd(int up) {
  const auto v = [up](glm::vec3 p) {
    const glm::vec3 s = in_source(p, up);
    return std::to_string(s.x) + " " + std::to_string(s.y) + " " + std::to_string(s.z);
  };
  std::string t = "version 1\nnodes\n0 \"root\" -1\n1 \"top\" 0\nend\nskeleton\n";
  for (int f = 0; f < 3; ++f)
    t += "time " + std::to_string(f) + "\n0 0 0 0 0 0 0\n1 " + v({0, 1, 0}) + " " + std::to_string(0.2 * f) + " 0 0\n";
  t += "end\ntriangles\n";
  for (int bone = 0; bone < 2; ++bone) {
    const float y0 = float(bone), y1 = float(bone + 1);
    const glm::vec3 c[4] = {{-0.2f, 0, -0.2f}, {0.2f, 0, -0.2f}, {0.2f, 0, 0.2f}, {-0.2f, 0, 0.2f}};
    for (int side = 0; side < 4; ++side) {
      const glm::vec3 a = c[side], b = c[(side + 1) % 4];
      const glm::vec3 quad[4] = {{a.x, y0, a.z}, {b.x, y0, b.z}, {b.x, y1, b.z}, {a.x, y1, a.z}};
      const glm::vec3 n = glm::normalize(glm::vec3(a.x + b.x, 0, a.z + b.z));
      static const int kTris[2][3] = {{0, 1, 2}, {0, 2, 3}};
      for (const auto& tri : kTris) {
        t += "skin\n";
        for (int k : tri)
          t += std::to_string(bone) + " " + v(quad[k]) + " " + v(n) + " 0 0 1 " + std::to_string(bone) + " 1\n";
      }
    }
  }
  return t + "end\n";
}

/// A Collada triangle pair (a 0.4 x 2 wall) standing on the axis `up_axis` names (X_UP, Y_UP, Z_UP).
std::string wall_dae(const std::string& up_axis, int up) {
  std::string pos;
  for (glm::vec3 p : {glm::vec3(-0.2f, 0, 0), glm::vec3(0.2f, 0, 0), glm::vec3(0.2f, 2, 0), glm::vec3(-0.2f, 2, 0)}) {
    const glm::vec3 s = in_source(p, up);
    pos += std::to_string(s.x) + " " + std::to_string(s.y) + " " + std::to_string(s.z) + " ";
  }
  return R"(<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="meter" meter="1"/><up_axis>)" +
         up_axis + R"(</up_axis></asset>
  <library_geometries><geometry id="g" name="wall"><mesh>
    <source id="p"><float_array id="pa" count="12">)" +
         pos + R"(</float_array>
      <technique_common><accessor source="#pa" count="4" stride="3">
        <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
      </accessor></technique_common></source>
    <vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
    <triangles count="2"><input semantic="VERTEX" source="#v" offset="0"/><p>0 1 2 0 2 3</p></triangles>
  </mesh></geometry></library_geometries>
  <library_visual_scenes><visual_scene id="s"><node id="n" name="wall"><instance_geometry url="#g"/></node>
  </visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#s"/></scene>
</COLLADA>
)";
}

/// An ASCII FBX rig Hips > Spine > Head, 1 unit apart along the up axis its GlobalSettings state.
std::string chain_fbx(int up) {
  const auto t = [up](float y) {
    const glm::vec3 s = in_source({0, y, 0}, up);
    return std::to_string(s.x) + "," + std::to_string(s.y) + "," + std::to_string(s.z);
  };
  std::string text = fbx_ascii_head("\t\tP: \"UpAxis\", \"int\", \"Integer\", \"\"," + std::to_string(up) +
                                    "\n\t\tP: \"UpAxisSign\", \"int\", \"Integer\", \"\",1\n"
                                    "\t\tP: \"UnitScaleFactor\", \"double\", \"Number\", \"\",100\n") +
                     "Objects:  {\n";
  const char* names[3] = {"Hips", "Spine", "Head"};
  for (int i = 0; i < 3; ++i)
    text += "\tModel: " + std::to_string(1000 + i) + ", \"Model::" + names[i] + "\", \"LimbNode\" {\n" +
            "\t\tVersion: 232\n\t\tProperties70:  {\n" +
            "\t\t\tP: \"Lcl Translation\", \"Lcl Translation\", \"\", \"A\"," + t(i == 0 ? 0.5f : 1) + "\n\t\t}\n\t}\n";
  return text + "}\nConnections:  {\n\tC: \"OO\",1000,0\n\tC: \"OO\",1001,1000\n\tC: \"OO\",1002,1001\n}\n";
}

/// The axis (0 x, 1 y, 2 z) along which `lo`..`hi` is longest, or -1 when no axis is.
int tallest(glm::vec3 lo, glm::vec3 hi) {
  const glm::vec3 e = hi - lo;
  if (e.y > e.x && e.y > e.z) return 1;
  if (e.x > e.y && e.x > e.z) return 0;
  if (e.z > e.x && e.z > e.y) return 2;
  return -1;
}

struct Extents {
  int mesh = -1, bind = -1, frame = -1;  // tallest axis of each; -1 when there is none to measure
  float top_y = NAN;                     // the highest joint's (or, without joints, vertex's) height
};

/// The extent of mesh 0 of `a` skinned with the joints' model matrices `model` (static: as stored).
void skinned_extent(const ossa::Asset& a, std::span<const glm::mat4> model, glm::vec3* lo, glm::vec3* hi) {
  const ossa::MeshView mesh = a.mesh(0);
  std::vector<glm::mat4> palette(std::max<size_t>(1, mesh.joints().size()));
  ossa::skinning_matrices(mesh, model, palette);
  std::vector<float> positions(3 * size_t(mesh.vertex_count()));
  ossa::skin_cpu(mesh, palette, ossa::SkinningMethod::Linear, {positions, {}, {}});
  *lo = glm::vec3(INFINITY), *hi = glm::vec3(-INFINITY);
  for (size_t v = 0; v + 2 < positions.size(); v += 3) {
    const glm::vec3 p(positions[v], positions[v + 1], positions[v + 2]);
    *lo = glm::min(*lo, p), *hi = glm::max(*hi, p);
  }
}

/// Cooks `file` (written with `text`) with `flags` and measures what stands up in the output.
Extents cook_and_measure(const fs::path& dir, const std::string& file, const std::string& text,
                         const std::string& flags = "") {
  EXPECT_TRUE(ossa::test::write_file(dir / file, text));
  const fs::path out = dir / ("out" + std::to_string(std::hash<std::string>{}(file + flags)));
  const auto r = run_command((ossa::test::bin_dir() / "ossa-cook").string() + " " + q(dir / file) + " -o " + q(out) +
                             " -q " + flags);
  EXPECT_EQ(r.exit_code, 0) << file << ": " << r.err;
  auto a = ossa::Asset::open((out / (fs::path(file).stem().string() + ".ossa")).string());
  EXPECT_TRUE(a.ok()) << file;
  Extents e;
  if (!a.ok()) return e;
  const ossa::SkeletonView sk = a->skeleton();
  glm::vec3 lo, hi;
  if (sk.empty()) {
    if (a->mesh_count() > 0) {
      skinned_extent(*a, {}, &lo, &hi);
      e.mesh = tallest(lo, hi);
      e.top_y = hi.y;
    }
    return e;
  }
  const auto span = [](std::span<const glm::mat4> model, glm::vec3* min, glm::vec3* max) {
    *min = glm::vec3(INFINITY), *max = glm::vec3(-INFINITY);
    for (const glm::mat4& m : model) *min = glm::min(*min, glm::vec3(m[3])), *max = glm::max(*max, glm::vec3(m[3]));
  };
  std::vector<glm::mat4> model(sk.joint_count());
  for (size_t j = 0; j < sk.joint_count(); ++j) {
    const auto& ib = sk.inverse_bind()[j];
    glm::mat4 m;
    for (int c = 0; c < 4; ++c)
      for (int r2 = 0; r2 < 4; ++r2) m[c][r2] = ib.m()->Get(static_cast<flatbuffers::uoffset_t>(c * 4 + r2));
    model[j] = glm::inverse(m);
  }
  span(model, &lo, &hi);
  e.bind = tallest(lo, hi);
  e.top_y = hi.y;
  if (a->mesh_count() > 0) {
    skinned_extent(*a, model, &lo, &hi);
    e.mesh = tallest(lo, hi);
  }
  if (a->clip_count() > 0) {
    auto cache = ossa::make_sampling_cache(a->clip(0), sk);
    EXPECT_TRUE(cache.ok());
    if (!cache.ok()) return e;
    ossa::Pose pose(static_cast<uint32_t>(sk.joint_count()));
    ossa::sample(a->clip(0), 0.0f, ossa::SampleOptions{}, *cache, pose);
    ossa::local_to_model(sk.parents(), pose, model);
    span(model, &lo, &hi);
    e.frame = tallest(lo, hi);
  }
  return e;
}

TEST(CookAxes, ZUpSmdCooksStanding) {
  const fs::path dir = ossa::test::make_temp_dir("axes-smd");
  const Extents e = cook_and_measure(dir, "column.smd", column_smd(2));
  EXPECT_EQ(e.mesh, 1);
  EXPECT_EQ(e.bind, 1);
  EXPECT_EQ(e.frame, 1);
  EXPECT_NEAR(e.top_y, 1.0f, 1e-3f) << "'top' stands 1 above 'root'";
  // --up-axis is over the convention: this SMD written Y-up and cooked with --up-axis y stands too,
  // and the Z-up one cooked with --up-axis y is taken as it is (lying along Z).
  EXPECT_EQ(cook_and_measure(dir, "ycolumn.smd", column_smd(1), "--up-axis y").mesh, 1);
  EXPECT_EQ(cook_and_measure(dir, "column.smd", column_smd(2), "--up-axis y").mesh, 2);
}

TEST(CookAxes, ColladaStatingZOrXUpCooksStanding) {
  const fs::path dir = ossa::test::make_temp_dir("axes-dae");
  EXPECT_EQ(cook_and_measure(dir, "z.dae", wall_dae("Z_UP", 2)).mesh, 1);
  EXPECT_EQ(cook_and_measure(dir, "x.dae", wall_dae("X_UP", 0)).mesh, 1);
  EXPECT_EQ(cook_and_measure(dir, "y.dae", wall_dae("Y_UP", 1)).mesh, 1);
  // --up-axis overrides the file: a wall written Z-up but labelled Y_UP stands with --up-axis z.
  EXPECT_EQ(cook_and_measure(dir, "mislabelled.dae", wall_dae("Y_UP", 2)).mesh, 2);
  EXPECT_EQ(cook_and_measure(dir, "mislabelled.dae", wall_dae("Y_UP", 2), "--up-axis z").mesh, 1);
}

TEST(CookAxes, FbxStatingZUpCooksStanding) {
  const fs::path dir = ossa::test::make_temp_dir("axes-fbx");
  const Extents z = cook_and_measure(dir, "z.fbx", chain_fbx(2));
  EXPECT_EQ(z.bind, 1);
  EXPECT_NEAR(z.top_y, 2.5f, 1e-3f);
  EXPECT_EQ(cook_and_measure(dir, "x.fbx", chain_fbx(0)).bind, 1);
  EXPECT_EQ(cook_and_measure(dir, "y.fbx", chain_fbx(1)).bind, 1);
}

TEST(CookAxes, UpAxisOverridesAFileThatStatesNone) {
  const fs::path dir = ossa::test::make_temp_dir("axes-obj");
  const std::string obj = "v -0.2 0 0\nv 0.2 0 0\nv 0.2 0 2\nv -0.2 0 2\nf 1 2 3\nf 1 3 4\n";  // 2 tall along Z
  EXPECT_EQ(cook_and_measure(dir, "wall.obj", obj).mesh, 2) << "an OBJ states no up axis: Y-up, taken as it is";
  EXPECT_EQ(cook_and_measure(dir, "wall.obj", obj, "--up-axis z").mesh, 1);
}

}  // namespace
