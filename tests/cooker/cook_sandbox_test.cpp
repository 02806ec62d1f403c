// cook_sandbox_test.cpp — the cook's read sandbox (cooker/model/input_log.h) against the attacks a
// source from an untrusted hand can make: a glTF buffer or image URI climbing out of the tree, a
// graph source given by absolute path, a symlink pointing out, a FIFO or device as an input or a
// texture. Each is refused by name (never opened, so nothing hangs or leaks into an output), the
// cook fails alone, and --root / --allow-dir widen the sandbox when the user means it.
#include <sys/stat.h>

#include <gtest/gtest.h>

#include <chrono>
#include <cstring>
#include <optional>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include <ossa/loader/asset.h>
#include "test_files.h"

namespace fs = std::filesystem;
using ossa::test::run_command;

namespace {

std::string cook_cmd() { return (ossa::test::bin_dir() / "ossa-cook").string(); }
fs::path asset(const char* rel) { return ossa::test::source_dir() / "assets" / rel; }
std::string q(const fs::path& p) { return "'" + p.string() + "'"; }

/// A minimal glTF: one triangle whose positions come from buffer `uri` (36 bytes of floats), with
/// a material whose base-colour image is `image_uri` (none when empty).
std::string triangle_gltf(const std::string& uri, const std::string& image_uri = "") {
  nlohmann::json j = {{"asset", {{"version", "2.0"}}},
                      {"scene", 0},
                      {"scenes", {{{"nodes", {0}}}}},
                      {"nodes", {{{"mesh", 0}}}},
                      {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}, {"material", 0}}}}}}},
                      {"materials", {nlohmann::json::object()}},
                      {"buffers", {{{"uri", uri}, {"byteLength", 36}}}},
                      {"bufferViews", {{{"buffer", 0}, {"byteLength", 36}}}},
                      {"accessors",
                       {{{"bufferView", 0},
                         {"componentType", 5126},
                         {"count", 3},
                         {"type", "VEC3"},
                         {"min", {0, 0, 0}},
                         {"max", {1, 1, 0}}}}}};
  if (!image_uri.empty()) {
    j["images"] = {{{"uri", image_uri}}};
    j["textures"] = {{{"source", 0}}};
    j["materials"][0]["pbrMetallicRoughness"] = {{"baseColorTexture", {{"index", 0}}}};
  }
  return j.dump();
}

std::string triangle_bytes() {
  const float v[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  return std::string(reinterpret_cast<const char*>(v), sizeof v);
}

class CookSandbox : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = ossa::test::make_temp_dir("sandbox");
    tree = dir / "tree";
    secret = dir / "secret";
    fs::create_directories(tree / "chars");
    fs::create_directories(secret);
    ASSERT_TRUE(ossa::test::write_file(secret / "creds.bin", triangle_bytes()));
    ASSERT_TRUE(ossa::test::write_file(secret / "creds.png", std::string_view("\x89PNG\r\n\x1a\n secret")));
    ASSERT_TRUE(ossa::test::write_file(tree / "chars" / "tri.bin", triangle_bytes()));
  }
  ossa::test::CommandResult cook(const fs::path& input, const std::string& extra = "") {
    return run_command(cook_cmd() + " " + q(input) + " -o " + q(dir / "out") + " " + extra);
  }
  fs::path dir, tree, secret;
};

TEST_F(CookSandbox, AGltfInsideItsTreeCooks) {
  ASSERT_TRUE(ossa::test::write_file(tree / "chars" / "ok.gltf", triangle_gltf("tri.bin")));
  const auto r = cook(tree / "chars" / "ok.gltf");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir / "out" / "ok.ossa"));
}

TEST_F(CookSandbox, BufferUriClimbingOutIsRefusedByName) {
  ASSERT_TRUE(ossa::test::write_file(tree / "chars" / "evil.gltf", triangle_gltf("../../secret/creds.bin")));
  const auto r = cook(tree / "chars" / "evil.gltf", "--report " + q(dir / "report.json"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find((secret / "creds.bin").string() + ": refused: outside the folders this cook may read"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("evil.gltf"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out" / "evil.ossa"));
  // With the secret's folder allowed, the same file cooks: the refusal was the sandbox's doing.
  const auto allowed = cook(tree / "chars" / "evil.gltf", "--allow-dir " + q(secret));
  EXPECT_EQ(allowed.exit_code, 0) << allowed.err;
}

TEST_F(CookSandbox, ImageUriClimbingOutIsRefusedAndNothingIsEmbedded) {
  ASSERT_TRUE(ossa::test::write_file(tree / "chars" / "img.gltf", triangle_gltf("tri.bin", "../../secret/creds.png")));
  const auto r = cook(tree / "chars" / "img.gltf");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("creds.png: refused: outside the folders this cook may read"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("texture"), std::string::npos) << "names the reference: " << r.err;
  EXPECT_FALSE(fs::exists(dir / "out" / "img.ossa"));
}

TEST_F(CookSandbox, SymlinksOutOfTheTreeAreResolvedAndRefused) {
  fs::create_symlink(secret / "creds.bin", tree / "chars" / "link.bin");
  ASSERT_TRUE(ossa::test::write_file(tree / "chars" / "sym.gltf", triangle_gltf("link.bin")));
  const auto r = cook(tree / "chars" / "sym.gltf");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find((secret / "creds.bin").string() + ": refused: outside the folders this cook may read"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("link.bin'"), std::string::npos) << "names the link as written: " << r.err;
}

TEST_F(CookSandbox, GraphSourcesOutsideTheTreeAreRefused) {
  const std::string graph = R"({"ossa_graph": 1, "name": "g", "skeleton": ")" + asset("Pab/skeleton.fbx").string() +
                            R"(", "clips": {"walk": ")" + asset("Pab/walk.fbx").string() +
                            R"("}, "parameters": {}, "root": {"clip": "walk"}})";
  ASSERT_TRUE(ossa::test::write_file(tree / "g.graph.json", graph));
  const auto r = cook(tree / "g.graph.json");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("skeleton.fbx: refused: outside the folders this cook may read"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("g.graph.json:1:"), std::string::npos) << "names the graph entry: " << r.err;
}

// A refusal for a file outside the sandbox names the widening that allows it: --root at the nearest
// folder holding both the input and the file, or --allow-dir at the file's folder. Each layout
// (sibling folder, deeper nesting on both sides, a folder beside the tree) is refused, then cooks
// with exactly what the message proposed.
TEST_F(CookSandbox, AnOutsideRefusalNamesTheRootOrAllowDirThatAllowsIt) {
  struct Layout {
    fs::path input, buffer, root;
  };
  const fs::path base = fs::canonical(dir);
  const std::vector<Layout> layouts = {
      {base / "tree" / "chars" / "a.gltf", base / "tree" / "buffers" / "a.bin", base / "tree"},
      {base / "tree" / "p" / "q" / "r" / "b.gltf", base / "tree" / "p" / "x" / "y" / "b.bin", base / "tree" / "p"},
      {base / "tree" / "chars" / "c.gltf", base / "secret" / "deep" / "c.bin", base}};
  for (const Layout& l : layouts) {
    fs::create_directories(l.input.parent_path());
    fs::create_directories(l.buffer.parent_path());
    ASSERT_TRUE(ossa::test::write_file(l.buffer, triangle_bytes()));
    const std::string uri = fs::relative(l.buffer, l.input.parent_path()).generic_string();
    ASSERT_TRUE(ossa::test::write_file(l.input, triangle_gltf(uri)));
    const auto r = cook(l.input);
    EXPECT_EQ(r.exit_code, 1) << l.input;
    const std::string proposal =
        "--root " + l.root.string() + " or --allow-dir " + l.buffer.parent_path().string() + " would allow it";
    EXPECT_NE(r.err.find(proposal), std::string::npos) << "expected '" << proposal << "' in: " << r.err;
    fs::remove_all(dir / "out");
    const auto rooted = cook(l.input, "--root " + q(l.root));
    EXPECT_EQ(rooted.exit_code, 0) << rooted.err;
    fs::remove_all(dir / "out");
    const auto allowed = cook(l.input, "--allow-dir " + q(l.buffer.parent_path()));
    EXPECT_EQ(allowed.exit_code, 0) << allowed.err;
    fs::remove_all(dir / "out");
  }
}

TEST_F(CookSandbox, RootWidensTheSandboxAndADirectoryArgumentIsItsOwnTree) {
  fs::create_directories(tree / "textures");
  ASSERT_TRUE(ossa::test::write_file(tree / "textures" / "tri.bin", triangle_bytes()));
  ASSERT_TRUE(ossa::test::write_file(tree / "chars" / "up.gltf", triangle_gltf("../textures/tri.bin")));
  EXPECT_EQ(cook(tree / "chars" / "up.gltf").exit_code, 1) << "a file input: its own folder only";
  EXPECT_EQ(cook(tree / "chars" / "up.gltf", "--root " + q(tree)).exit_code, 0);
  fs::remove_all(dir / "out");
  const auto r = run_command(cook_cmd() + " " + q(tree) + " -o " + q(dir / "out") + " --root " + q(tree));
  EXPECT_EQ(r.exit_code, 0) << r.err;
}

TEST_F(CookSandbox, FifosAndDevicesAreRefusedWithoutBeingOpened) {
  ASSERT_EQ(::mkfifo((tree / "chars" / "pipe.gltf").c_str(), 0644), 0);
  ASSERT_EQ(::mkfifo((tree / "chars" / "pipe.bin").c_str(), 0644), 0);
  ASSERT_TRUE(ossa::test::write_file(tree / "chars" / "fifo.gltf", triangle_gltf("pipe.bin")));
  // A FIFO as the input itself, and a FIFO as a buffer; /dev/zero as an allowed folder's file.
  // Opening a FIFO would wait for a writer and reading /dev/zero never ends: either would end in
  // the time limit (or the memory limit) instead of the refusals below.
  const auto r = run_command(cook_cmd() + " " + q(tree / "chars" / "pipe.gltf") + " " +
                             q(tree / "chars" / "fifo.gltf") + " /dev/zero -o " + q(dir / "out") + " --timeout 120");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.err.find("exceeded the"), std::string::npos)
      << "something waited for a writer or read an endless device:\n"
      << r.err;
  EXPECT_NE(r.err.find("pipe.gltf: refused: is a FIFO, not a regular file"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("pipe.bin: refused: is a FIFO, not a regular file"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("/dev/zero: refused: is a device, not a regular file"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out"));
}

// A hard link is another name for the same bytes: `ln /secret tree/x.png` would read the secret
// through a name inside the tree. Regular files with more than one link are refused unless
// --allow-hard-links (docs/COOKING-SECURITY.md), whatever reads them: an image, a buffer, an OBJ
// source and the material library it names.
TEST_F(CookSandbox, HardLinkedFilesAreRefusedUnlessAllowed) {
  const auto png = ossa::test::tiny_png();
  ASSERT_TRUE(ossa::test::write_file(secret / "real.png", png));
  const std::string obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl skin\nf 1 2 3\n";
  ASSERT_TRUE(ossa::test::write_file(secret / "s.obj", obj));
  ASSERT_TRUE(ossa::test::write_file(secret / "m.mtl", std::string_view("newmtl skin\nKd 1 0 0\n")));
  struct Case {
    const char* name;    // the input, in tree/chars
    const char* linked;  // the name in tree/chars that is a hard link to a file in secret/
    const char* target;
  };
  const Case cases[] = {{"img.gltf", "hl.png", "real.png"},
                        {"buf.gltf", "hl.bin", "creds.bin"},
                        {"hl.obj", "hl.obj", "s.obj"},
                        {"mat.obj", "m.mtl", "m.mtl"}};
  ASSERT_TRUE(ossa::test::write_file(tree / "chars" / "img.gltf", triangle_gltf("tri.bin", "hl.png")));
  ASSERT_TRUE(ossa::test::write_file(tree / "chars" / "buf.gltf", triangle_gltf("hl.bin")));
  ASSERT_TRUE(ossa::test::write_file(tree / "chars" / "mat.obj", obj));
  for (const Case& c : cases) {
    const fs::path link = tree / "chars" / c.linked;
    fs::remove(link);
    fs::create_hard_link(secret / c.target, link);
    const auto r = cook(tree / "chars" / c.name, "--force");
    EXPECT_EQ(r.exit_code, 1) << c.name << ": " << r.err;
    EXPECT_NE(r.err.find(std::string(c.linked) + ": refused: has 2 hard links"), std::string::npos)
        << c.name << ": " << r.err;
    EXPECT_NE(r.err.find("--allow-hard-links"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "out" / (fs::path(c.name).stem().string() + ".ossa"))) << c.name;
    const auto allowed = cook(tree / "chars" / c.name, "--force --allow-hard-links");
    EXPECT_EQ(allowed.exit_code, 0) << c.name << ": " << allowed.err;
    fs::remove_all(dir / "out");
  }
}

// Wherever the cooker looks for a file that may be absent (settings, the events sidecar), a name
// that exists but is not a regular file fails the input: it is not taken for "absent".
TEST_F(CookSandbox, FifosNamedLikeSettingsOrSidecarsFailTheInput) {
  const std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  for (const char* name : {"ossa.cook.json", "a.cook.json", "a.events.json"}) {
    const fs::path folder = tree / ("f-" + std::string(name));
    fs::create_directories(folder);
    ASSERT_TRUE(ossa::test::write_file(folder / "a.obj", obj));
    ASSERT_EQ(::mkfifo((folder / name).c_str(), 0644), 0);
    const auto start = std::chrono::steady_clock::now();
    const auto r = cook(folder / "a.obj", "--timeout 20");
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 10.0) << name;
    EXPECT_EQ(r.exit_code, 1) << name << ": " << r.err;
    EXPECT_NE(r.err.find(std::string(name) + ": refused: is a FIFO, not a regular file"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("a.obj"), std::string::npos) << "names the input: " << r.err;
    EXPECT_FALSE(fs::exists(dir / "out" / "a.ossa")) << name;
    // The same source with nothing of that name cooks.
    fs::remove(folder / name);
    EXPECT_EQ(cook(folder / "a.obj").exit_code, 0) << name;
    fs::remove_all(dir / "out");
  }
}

// Textures are identified by their bytes and must decode (cooker/import/image_check.h).
TEST_F(CookSandbox, TexturesMustBeTheImagesTheyClaimToBe) {
  const auto png = ossa::test::tiny_png();
  std::string bomb(png.begin(), png.end());
  // The IHDR's width and height (bytes 16..23) rewritten to 20000 x 20000: a decompression bomb.
  for (int k = 0; k < 2; ++k) {
    bomb[16 + 4 * k] = 0;
    bomb[17 + 4 * k] = 0;
    bomb[18 + 4 * k] = char(20000 >> 8);
    bomb[19 + 4 * k] = char(20000 & 0xff);
  }
  const std::string cases[][2] = {
      {"text.png", "just some text, named like a picture\n"},
      {"truncated.png", std::string(png.begin(), png.begin() + 40)},
      {"bomb.png", bomb},
  };
  const char* expected[] = {"is not a PNG or JPEG image", "does not decode as png", "claims 20000 x 20000 pixels"};
  for (size_t i = 0; i < std::size(cases); ++i) {
    ASSERT_TRUE(ossa::test::write_file(tree / "chars" / cases[i][0], cases[i][1]));
    ASSERT_TRUE(ossa::test::write_file(tree / "chars" / "t.gltf", triangle_gltf("tri.bin", cases[i][0])));
    const auto r = cook(tree / "chars" / "t.gltf");
    EXPECT_EQ(r.exit_code, 1) << cases[i][0];
    EXPECT_NE(r.err.find("texture '" + cases[i][0] + "' " + expected[i]), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "out" / "t.ossa")) << cases[i][0];
  }
  // A real PNG under a .jpg name is embedded as what it is (kept as source bytes: image/png), and
  // cooked by default into a BC1 chain of its 2 x 2 texels.
  ASSERT_TRUE(ossa::test::write_file(tree / "chars" / "real.jpg", png));
  ASSERT_TRUE(ossa::test::write_file(tree / "chars" / "t.gltf", triangle_gltf("tri.bin", "real.jpg")));
  for (const char* format : {"source", "bc"}) {
    const auto r = cook(tree / "chars" / "t.gltf", std::string("--force --texture-format ") + format);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    auto a = ossa::Asset::open((dir / "out" / "t.ossa").string());
    ASSERT_TRUE(a.ok());
    size_t embedded = 0;
    for (const auto* m : *a->file().materials())
      if (m->textures())
        for (const auto* t : *m->textures()) {
          if (std::string(format) == "source") {
            EXPECT_EQ(flatbuffers::GetStringView(t->mime()), "image/png");
            EXPECT_EQ(t->encoding(), ossa::fb::TextureEncoding::Source);
          } else {
            EXPECT_EQ(t->encoding(), ossa::fb::TextureEncoding::Bc1);
            EXPECT_EQ(t->width(), 2u);
            EXPECT_EQ(t->mip_count(), 2u);
          }
          embedded += t->data() ? 1 : 0;
        }
    EXPECT_EQ(embedded, 1u) << format;
  }
}

// A huge but finite value in a source is named at import (it used to surface as "internal error,
// cooked bytes fail verification").
TEST_F(CookSandbox, HugeSourceValuesAreNamedAtImport) {
  // An animated node: keys at 0 s and 1 s, the first translation 1e20.
  const float data[8] = {0.0f, 1.0f, 1e20f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f};
  ASSERT_TRUE(ossa::test::write_file(tree / "chars" / "anim.bin",
                                     std::string(reinterpret_cast<const char*>(data), sizeof data)));
  nlohmann::json j = {
      {"asset", {{"version", "2.0"}}},
      {"scene", 0},
      {"scenes", {{{"nodes", {0}}}}},
      {"nodes", {{{"name", "hips"}}}},
      {"buffers", {{{"uri", "anim.bin"}, {"byteLength", 32}}}},
      {"bufferViews", {{{"buffer", 0}, {"byteLength", 8}}, {{"buffer", 0}, {"byteOffset", 8}, {"byteLength", 24}}}},
      {"accessors",
       {{{"bufferView", 0}, {"componentType", 5126}, {"count", 2}, {"type", "SCALAR"}, {"min", {0}}, {"max", {1}}},
        {{"bufferView", 1}, {"componentType", 5126}, {"count", 2}, {"type", "VEC3"}}}},
      {"animations",
       {{{"name", "move"},
         {"samplers", {{{"input", 0}, {"output", 1}}}},
         {"channels", {{{"sampler", 0}, {"target", {{"node", 0}, {"path", "translation"}}}}}}}}}};
  ASSERT_TRUE(ossa::test::write_file(tree / "chars" / "huge.gltf", j.dump()));
  const auto r = cook(tree / "chars" / "huge.gltf");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.err.find("internal error"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("clip 'move', joint 'hips': translation key 0 (at 0 s) (1e+20, 0, 0) is unusable"),
            std::string::npos)
      << r.err;
}

// What Assimp cannot take is handled before it reads the bytes (cooker/import/source_precheck.h).
TEST_F(CookSandbox, DeepHierarchiesAreRefusedBeforeTheImporterRecurses) {
  // A glTF chain of 20,000 nodes, and a BVH 20,000 joints deep.
  nlohmann::json nodes = nlohmann::json::array();
  for (int i = 0; i < 20000; ++i) {
    nlohmann::json node = {{"name", "n" + std::to_string(i)}};
    if (i + 1 < 20000) node["children"] = {i + 1};
    nodes.push_back(node);
  }
  const nlohmann::json gltf = {
      {"asset", {{"version", "2.0"}}}, {"scene", 0}, {"scenes", {{{"nodes", {0}}}}}, {"nodes", nodes}};
  ASSERT_TRUE(ossa::test::write_file(tree / "chars" / "chain.gltf", gltf.dump()));
  std::string bvh = "HIERARCHY\nROOT j0\n{\n OFFSET 0 0 0\n CHANNELS 3 Zrotation Xrotation Yrotation\n";
  for (int i = 1; i < 20000; ++i)
    bvh += " JOINT j" + std::to_string(i) + "\n {\n OFFSET 0 1 0\n CHANNELS 3 Zrotation Xrotation Yrotation\n";
  bvh += " End Site\n {\n OFFSET 0 1 0\n }\n";
  for (int i = 0; i < 20000; ++i) bvh += "}\n";
  bvh += "MOTION\nFrames: 1\nFrame Time: 0.033\n";
  for (int i = 0; i < 20000; ++i) bvh += "0 0 0 ";
  ASSERT_TRUE(ossa::test::write_file(tree / "chars" / "chainb.bvh", bvh));
  // Collada: <node>s nested 2,000 and 20,000 deep (Assimp cooked the first despite the documented
  // limit and crashed on the second), and a chain of 20,000 library nodes each instancing the next
  // (as deep once Assimp expands it, with no nesting in the XML).
  const auto collada = [](const std::string& library, const std::string& scene) {
    return "<?xml version=\"1.0\"?>\n<COLLADA xmlns=\"http://www.collada.org/2005/11/COLLADASchema\" version=\"1.4.1\">"
           "<asset><unit meter=\"1\"/><up_axis>Y_UP</up_axis></asset><library_nodes>" +
           library + "</library_nodes><library_visual_scenes><visual_scene id=\"s\">" + scene +
           "</visual_scene></library_visual_scenes><scene><instance_visual_scene url=\"#s\"/></scene></COLLADA>\n";
  };
  for (int n : {2000, 20000}) {
    std::string nested;
    for (int i = 0; i < n; ++i)
      nested += "<node id=\"n" + std::to_string(i) + "\" type=\"JOINT\"><translate>0 1 0</translate>";
    for (int i = 0; i < n; ++i) nested += "</node>";
    ASSERT_TRUE(ossa::test::write_file(tree / "chars" / ("chain" + std::to_string(n) + ".dae"), collada("", nested)));
  }
  std::string instanced;
  for (int i = 0; i < 20000; ++i)
    instanced += "<node id=\"n" + std::to_string(i) + "\">" +
                 (i + 1 < 20000 ? "<instance_node url=\"#n" + std::to_string(i + 1) + "\"/>" : "") + "</node>";
  ASSERT_TRUE(ossa::test::write_file(tree / "chars" / "chaini.dae",
                                     collada(instanced, "<node id=\"root\"><instance_node url=\"#n0\"/></node>")));
  // Within the limit: 999 nested nodes (a skeleton of 999 joints) cook.
  std::string ok;
  for (int i = 0; i < 999; ++i)
    ok += "<node id=\"j" + std::to_string(i) + "\" sid=\"j" + std::to_string(i) +
          "\" type=\"JOINT\"><translate>0 1 0</translate>";
  for (int i = 0; i < 999; ++i) ok += "</node>";
  ASSERT_TRUE(ossa::test::write_file(tree / "chars" / "deep999.dae", collada("", ok)));
  const auto r = run_command(cook_cmd() + " " + q(tree / "chars") + " -o " + q(dir / "out") + " --report " +
                             q(dir / "report.json"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("chain.gltf: its node tree is nested over 1000+ levels deep"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("chainb.bvh: its joint hierarchy is nested over 1000+ levels deep"), std::string::npos) << r.err;
  for (const char* dae : {"chain2000.dae", "chain20000.dae", "chaini.dae"})
    EXPECT_NE(
        r.err.find(std::string(dae) + ": its node tree (nested <node>s and the <instance_node>s they expand) is nested "
                                      "over 1000+ levels deep"),
        std::string::npos)
        << r.err;
  EXPECT_EQ(r.err.find("signal"), std::string::npos) << "refused, not crashed: " << r.err;
  EXPECT_EQ(r.err.find("deep999.dae: "), std::string::npos) << "within the limit: " << r.err;
  EXPECT_TRUE(fs::exists(dir / "out" / "deep999.ossa"));
}

TEST_F(CookSandbox, AGltfSkinWithoutInverseBindMatricesMeansIdentity) {
  // glTF 2.0: "When undefined, each matrix is a 4x4 identity matrix." Assimp 5.2 crashes on it;
  // the cooker supplies the identity matrices before Assimp reads the file.
  const fs::path shared = ossa::test::shared_assets() / "Khronos_embedded" / "rigged_simple.gltf";
  if (!fs::exists(shared)) GTEST_SKIP() << "../shared/assets not present";
  auto doc = nlohmann::json::parse(*ossa::test::read_text(shared));
  ASSERT_TRUE(doc.contains("skins"));
  for (auto& skin : doc["skins"]) skin.erase("inverseBindMatrices");
  ASSERT_TRUE(ossa::test::write_file(tree / "chars" / "noibm.gltf", doc.dump()));
  const auto r = run_command(cook_cmd() + " " + q(tree / "chars" / "noibm.gltf") + " -o " + q(dir / "out"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto a = ossa::Asset::open((dir / "out" / "noibm.ossa").string());
  ASSERT_TRUE(a.ok());
  ASSERT_GT(a->mesh_count(), 0u);
  ASSERT_GT(a->skeleton().joint_count(), 0u);
  // Every joint slot of the mesh binds with the identity.
  const auto* mesh = a->file().meshes()->Get(0);
  ASSERT_NE(mesh->inverse_bind(), nullptr);
  for (const auto* m : *mesh->inverse_bind())
    for (int k = 0; k < 16; ++k) EXPECT_FLOAT_EQ(m->m()->Get(k), k % 5 == 0 ? 1.0f : 0.0f) << k;
}

// Broken containers are described as what they are, not by Assimp's consequences ("No suitable
// reader found", "aiScene::mNumMeshes is 0", "4252017601 frames").
TEST_F(CookSandbox, BrokenContainersAreDescribedAsSuch) {
  const std::string gltf = triangle_gltf("tri.bin");
  ASSERT_TRUE(ossa::test::write_file(tree / "chars" / "cut.gltf", gltf.substr(0, gltf.size() / 2)));
  const auto glb = ossa::test::read_file(asset("RiggedSimple/RiggedSimple.glb"));
  ASSERT_TRUE(glb.has_value());
  ASSERT_TRUE(ossa::test::write_file(tree / "chars" / "cutb.glb", std::span<const uint8_t>(glb->data(), 5000)));
  ASSERT_TRUE(ossa::test::write_file(
      tree / "chars" / "zero.bvh",
      std::string_view(
          "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 3 Zrotation Xrotation Yrotation\n End Site\n {\n"
          "  OFFSET 0 1 0\n }\n}\nMOTION\nFrames: 0\nFrame Time: 0.033\n")));
  const auto r = run_command(cook_cmd() + " " + q(tree / "chars") + " -o " + q(dir / "out") + " --root " + q(tree));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("cut.gltf: is not valid glTF JSON (truncated? parse error"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("cutb.glb: is a GLB file that declares " + std::to_string(glb->size()) + " bytes but has 5000"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("zero.bvh: declares \"Frames: 0\": a BVH motion needs at least one frame"), std::string::npos)
      << r.err;
}

/// A minimal binary LightWave object (LWO2): one layer, the four corners of a unit square at
/// height `y`, two triangles. IFF: big-endian sizes, chunks padded to even length.
std::string lwo2_square(float y) {
  const auto be32 = [](uint32_t v) { return std::string{char(v >> 24), char(v >> 16), char(v >> 8), char(v)}; };
  const auto be16 = [](uint16_t v) { return std::string{char(v >> 8), char(v)}; };
  const auto f32 = [&](float f) {
    uint32_t u = 0;
    std::memcpy(&u, &f, 4);
    return be32(u);
  };
  const auto chunk = [&](const char* tag, std::string data) {
    if (data.size() % 2) data += '\0';
    return std::string(tag, 4) + be32(static_cast<uint32_t>(data.size())) + data;
  };
  std::string points;
  for (const auto& [x, z] : {std::pair{0.f, 0.f}, {1.f, 0.f}, {1.f, 1.f}, {0.f, 1.f}})
    points += f32(x) + f32(y) + f32(z);
  const std::string body = "LWO2" + chunk("TAGS", std::string("Default\0", 8)) +
                           chunk("LAYR", be16(0) + be16(0) + f32(0) + f32(0) + f32(0) + std::string("layer\0", 6)) +
                           chunk("PNTS", points) +
                           chunk("POLS", "FACE" + be16(3) + be16(0) + be16(1) + be16(2) +  // two triangles
                                             be16(3) + be16(0) + be16(2) + be16(3));
  return "FORM" + be32(static_cast<uint32_t>(body.size())) + body;
}

/// A LightWave scene that loads one object by the path `object`, as LoadObjectLayer names it.
std::string lws_scene(const std::string& object) {
  return "LWSC\n3\n\nFirstFrame 1\nLastFrame 1\nFrameStep 1\nFramesPerSecond 30\n\nLoadObjectLayer 1 " + object +
         "\nShowObject 8 7\n";
}

// LightWave scenes name their objects relative to the scene or to its content folder, and
// Assimp opens them as named: the same command used to cook from one directory and fail (or
// read another file) from the next. Every layout cooks the same bytes from any directory.
TEST_F(CookSandbox, LightWaveScenesCookTheSameFromAnyWorkingDirectory) {
  const fs::path content = tree / "lw";
  fs::create_directories(content / "Scenes" / "Objects");
  fs::create_directories(content / "Objects");
  fs::create_directories(dir / "elsewhere" / "Objects");
  ASSERT_TRUE(ossa::test::write_file(content / "Scenes" / "beside.lwo", lwo2_square(1)));
  ASSERT_TRUE(ossa::test::write_file(content / "Scenes" / "Objects" / "below.lwo", lwo2_square(2)));
  ASSERT_TRUE(ossa::test::write_file(content / "Objects" / "content.lwo", lwo2_square(3)));
  // Decoys where a working directory would find them: read, they would change the output.
  for (const fs::path& decoy : {dir / "elsewhere" / "beside.lwo", dir / "elsewhere" / "Objects" / "below.lwo",
                                dir / "elsewhere" / "Objects" / "content.lwo", content / "Objects" / "below.lwo"})
    ASSERT_TRUE(ossa::test::write_file(decoy, lwo2_square(9)));
  struct Scene {
    const char* file;
    const char* object;
    float height;  // of the object it must load
  };
  const Scene scenes[] = {{"beside.lws", "beside.lwo", 1},
                          {"below.lws", "Objects/below.lwo", 2},
                          {"content.lws", "Objects/content.lwo", 3}};
  for (const auto& [scene, object, height] : scenes) {
    SCOPED_TRACE(scene);
    const fs::path input = content / "Scenes" / scene;
    ASSERT_TRUE(ossa::test::write_file(input, lws_scene(object)));
    std::optional<std::vector<uint8_t>> first;
    for (const fs::path& cwd : {dir, content / "Scenes", content / "Objects", dir / "elsewhere"}) {
      SCOPED_TRACE(cwd.string());
      const fs::path out = dir / "out" / cwd.filename();
      const auto r = run_command("cd " + q(cwd) + " && " + cook_cmd() + " " + q(fs::relative(input, cwd)) + " -o " +
                                 q(out) + " -q --force --root " + q(fs::relative(tree, cwd)));
      ASSERT_EQ(r.exit_code, 0) << r.err;
      const auto bytes = ossa::test::read_file(out / "lw" / "Scenes" / (fs::path(scene).stem().string() + ".ossa"));
      ASSERT_TRUE(bytes);
      if (!first) {
        first = bytes;
        auto a = ossa::Asset::open((out / "lw" / "Scenes" / (fs::path(scene).stem().string() + ".ossa")).string());
        ASSERT_TRUE(a.ok() && a->file().meshes() && a->file().meshes()->size() == 1);
        EXPECT_FLOAT_EQ(a->file().meshes()->Get(0)->bounds_max()->y(), height) << "not the object the scene names";
      }
      EXPECT_EQ(*bytes, *first) << "another directory, another output";
    }
  }
  // Nothing but the tree: an object outside --root is refused by name, whichever way it is named.
  ASSERT_TRUE(ossa::test::write_file(secret / "box.lwo", lwo2_square(0)));
  for (const std::string& object : {std::string("../../../secret/box.lwo"), (secret / "box.lwo").string()}) {
    SCOPED_TRACE(object);
    ASSERT_TRUE(ossa::test::write_file(content / "Scenes" / "out.lws", lws_scene(object)));
    const auto r = run_command("cd " + q(secret) + " && " + cook_cmd() + " " + q(content / "Scenes" / "out.lws") +
                               " -o " + q(dir / "out") + " --root " + q(tree));
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find((secret / "box.lwo").string() + ": refused: outside the folders this cook may read"),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("out.lws"), std::string::npos) << r.err;
  }
}

}  // namespace
