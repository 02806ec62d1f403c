// cook_depfile_test.cpp — ossa-cook --depfile read by the build tools that consume it, for real:
// GNU make (`-include` of the depfile, absolute targets, as a studio Makefile does) and Ninja
// (`depfile =` with `deps = gcc`, as CMake's DEPFILE does), over every class of hostile file name
// a source tree can hold. For each class, a texture named with it (and, where Make can take the
// output's name as a target, a source named with it) is cooked by each tool and:
// - a name both tools can read back (space, '#', '$', ':', backslash, '(', '~', UTF-8, ...) must
//   be recorded exactly (Ninja's `-t deps`), a rebuild with nothing changed runs nothing, and a
//   changed source re-runs the cook once;
// - a name no depfile spells alike for both (';', '&', '|', quotes, '*?[', '=', '%' in a target,
//   LF, TAB, CR, ESC, ...) fails the cook with a message naming the input and the name, and no
//   depfile is left; and nothing ever runs a command the name carries (`x;touch${IFS}MAKEPWNED;y`).
// The counts (tried / wrong re-runs / commands run) are printed for the closing notes.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "cooker/cli/batch.h"
#include "test_files.h"

namespace fs = std::filesystem;
using ossa::test::run_command;

namespace {

struct NameClass {
  const char* label;
  std::string stem;              // the source is <stem>.obj, the output <stem>.ossa
  bool spellable;                // a depfile can name it for both Make and Ninja
  bool as_prerequisite = false;  // ... though not as a target (where Make reads '%' as a pattern)
};

std::vector<NameClass> hostile_names() {
  return {
      {"space", "a b", true},
      {"hash", "a#b", true},
      {"dollar", "a$b", true},
      {"dollar-paren", "a$(shell touch MAKEPWNED2)b", true},
      {"colon", "a:b", true},
      {"backslash", "a\\b", true},
      {"parens", "a(1)b", true},
      {"lone-bracket", "a[b", true},
      {"tilde-plus-at", "~a+b@c!d,e{f}", true},
      {"utf8", "caf\xc3\xa9", true},
      {"semicolon", "x;touch${IFS}MAKEPWNED;y", false},
      {"ampersand", "a&b", false},
      {"pipe", "a|b", false},
      {"backquote", "a`touch MAKEPWNED3`b", false},
      {"single-quote", "a'b", false},
      {"double-quote", "a\"b", false},
      {"star", "a*b", false},
      {"question", "a?b", false},
      {"bracket-glob", "a[1]b", false},
      {"equals", "a=b", false},
      {"percent", "a%b", false, true},  // in the output's name: a pattern rule for Make
      {"lf", "a\nb", false},
      {"tab", "a\tb", false},
      {"cr", "a\rb", false},
      {"esc", "a\x1b[31mb", false},
      {"lt-gt-caret", "a<b>c^d", false},
  };
}

std::string sh_quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

/// Ninja's manifest syntax for a path (not the depfile's): '$', ' ' and ':' take a '$'.
std::string ninja_manifest(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '$' || c == ' ' || c == ':') out += '$';
    out += c;
  }
  return out;
}

const std::string kObj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

/// A glTF triangle whose material's texture is `image` (beside it) and whose buffer is tri.bin.
std::string textured_gltf(const std::string& image) {
  const nlohmann::json j = {{"asset", {{"version", "2.0"}}},
                            {"scene", 0},
                            {"scenes", {{{"nodes", {0}}}}},
                            {"nodes", {{{"mesh", 0}}}},
                            {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}, {"material", 0}}}}}}},
                            {"materials", {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}}},
                            {"images", {{{"uri", image}}}},
                            {"textures", {{{"source", 0}}}},
                            {"buffers", {{{"uri", "tri.bin"}, {"byteLength", 36}}}},
                            {"bufferViews", {{{"buffer", 0}, {"byteLength", 36}}}},
                            {"accessors",
                             {{{"bufferView", 0},
                               {"componentType", 5126},
                               {"count", 3},
                               {"type", "VEC3"},
                               {"min", {0, 0, 0}},
                               {"max", {1, 1, 0}}}}}};
  return j.dump();
}

/// Lines of `text` that are exactly `what` (the recipe's echo; Ninja also prints the command).
int count_of(const std::string& text, const std::string& what) {
  int n = 0;
  size_t start = 0;
  while (start <= text.size()) {
    const size_t end = text.find('\n', start);
    if (text.compare(start, (end == std::string::npos ? text.size() : end) - start, what) == 0) ++n;
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return n;
}

/// Where the hostile name is: a texture the source names (a prerequisite only, the output's name is
/// plain: the case that made Make run a command), or the source itself (target and prerequisite).
enum class Where { kTexture, kSource };

/// One name class through one tool: a first build, a rebuild with nothing changed, a rebuild after
/// the named file changed. Returns the wrong outcomes (a re-run missed or made, a dependency
/// recorded wrong), or -1 when the case cannot be built; checks the messages of a refused name.
int build_with(const std::string& tool, const NameClass& c, Where where, const fs::path& work) {
  const fs::path dir = work / "src";
  fs::create_directories(dir);
  fs::path named, src, out;
  if (where == Where::kTexture) {
    named = dir / (c.stem + ".png");
    src = dir / "m.gltf";
    out = work / "out" / "m.ossa";
    const float v[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    EXPECT_TRUE(ossa::test::write_file(dir / "tri.bin", std::string(reinterpret_cast<const char*>(v), sizeof v)));
    EXPECT_TRUE(ossa::test::write_file(src, textured_gltf(c.stem + ".png")));
    EXPECT_TRUE(ossa::test::write_file(named, ossa::test::tiny_png()));
    // What an attacker would add so that Make finds the prerequisite before a ';' and runs the rest.
    EXPECT_TRUE(ossa::test::write_file(dir / "x", std::string_view("")));
  } else {
    named = src = dir / (c.stem + ".obj");
    out = work / "out" / (c.stem + ".ossa");
    EXPECT_TRUE(ossa::test::write_file(src, kObj));
  }
  const std::string cook = (ossa::test::bin_dir() / "ossa-cook").string();
  std::string why;
  const std::string out_abs = fs::absolute(out).lexically_normal().string();
  const auto target = ossa::cook::depfile_spelling(out_abs, true, why);
  EXPECT_TRUE(target.has_value() || where == Where::kSource) << "the output's name is plain: " << why;
  if (!target) return -1;  // a source name Make cannot even take as a target: kTexture covers it
  // The source reaches the recipe through the environment: no quoting of the name in a command.
  const std::string env = "SRC_PATH=" + sh_quote(src.string()) + " ";
  std::string run;
  if (tool == "make") {
    std::ofstream mk(work / "Makefile");
    mk << *target << ":\n\t@echo COOKING; " << cook << " \"$$SRC_PATH\" -o out --depfile cook.d -q\n-include cook.d\n";
    run = "cd " + sh_quote(work.string()) + " && " + env + "make 2>&1";
  } else {
    std::ofstream nj(work / "build.ninja");
    nj << "rule cook\n  command = echo COOKING; " << cook << " \"$$SRC_PATH\" -o out --depfile cook.d -q\n"
       << "  depfile = cook.d\n  deps = gcc\nbuild " << ninja_manifest(out_abs) << ": cook\n";
    run = "cd " + sh_quote(work.string()) + " && " + env + "ninja 2>&1";
  }
  const std::string what = tool + " " + c.label + (where == Where::kTexture ? " (texture)" : " (source)");
  const auto first = run_command(run);
  int wrong = 0;
  const bool spellable = c.spellable || (c.as_prerequisite && where == Where::kTexture);
  if (!spellable) {
    EXPECT_NE(first.exit_code, 0) << what << ": the cook must fail: " << first.out;
    EXPECT_NE(first.out.find("a name no depfile spells alike for Make and Ninja"), std::string::npos)
        << what << ": " << first.out;
    EXPECT_NE(first.out.find(src.filename().string()), std::string::npos) << what << ": names the input: " << first.out;
    EXPECT_FALSE(fs::exists(work / "cook.d")) << what;
    if (first.exit_code != 0) return 0;
    ++wrong;  // written anyway: see what the tool makes of it
  }
  EXPECT_EQ(first.exit_code, 0) << what << ": " << first.out;
  EXPECT_EQ(count_of(first.out, "COOKING"), 1) << what << ": " << first.out;
  if (tool == "ninja") {
    // What Ninja recorded: the named file exactly.
    const auto deps = run_command("cd " + sh_quote(work.string()) + " && ninja -t deps");
    const bool recorded = deps.out.find("    " + named.string() + "\n") != std::string::npos;
    wrong += recorded ? 0 : 1;
    EXPECT_TRUE(recorded) << what << ": " << deps.out;
  }
  const auto again = run_command(run);
  wrong += count_of(again.out, "COOKING") != 0;
  EXPECT_EQ(count_of(again.out, "COOKING"), 0) << what << ": nothing changed: " << again.out;
  // File times come from the kernel's coarse clock (a tick of 1-4 ms): a change made within the
  // tick of the output's write would look no newer to either tool.
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  if (where == Where::kTexture) EXPECT_TRUE(ossa::test::write_file(named, ossa::test::tiny_png_with_text("changed")));
  else EXPECT_TRUE(ossa::test::write_file(src, kObj + "v 0 0 1\n"));
  const auto changed = run_command(run);
  wrong += count_of(changed.out, "COOKING") != 1;
  EXPECT_EQ(count_of(changed.out, "COOKING"), 1) << what << ": the named file changed: " << changed.out;
  if (where == Where::kTexture) {
    // The source changes too (a rule's recipe smuggled in by a name would run now).
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    EXPECT_TRUE(ossa::test::write_file(src, textured_gltf(c.stem + ".png") + "\n"));
    const auto source_changed = run_command(run);
    wrong += count_of(source_changed.out, "COOKING") != 1;
    EXPECT_EQ(count_of(source_changed.out, "COOKING"), 1) << what << ": the source changed: " << source_changed.out;
  }
  return wrong;
}

TEST(CookDepfile, EveryHostileNameIsReadBackOrRefusedByMakeAndNinja) {
  if (run_command("make --version && ninja --version").exit_code != 0) GTEST_SKIP() << "needs GNU make and ninja";
  const fs::path base = ossa::test::make_temp_dir("depfile");
  int tried = 0, wrong = 0, refused = 0, k = 0;
  for (const std::string tool : {"make", "ninja"})
    for (const Where where : {Where::kTexture, Where::kSource})
      for (const NameClass& c : hostile_names()) {
        // Assimp reads a backslash in a glTF URI as a folder separator: that class is a source name.
        if (where == Where::kTexture && c.stem.find('\\') != std::string::npos) continue;
        const int w = build_with(tool, c, where, base / (tool + "-" + std::to_string(k++)));
        if (w < 0) continue;
        wrong += w;
        tried += 1;
        refused += c.spellable || (c.as_prerequisite && where == Where::kTexture) ? 0 : 1;
      }
  // No name ran a command, with either tool, in any folder.
  int commands = 0;
  for (const auto& e : fs::recursive_directory_iterator(base))
    commands += e.path().filename().string().rfind("MAKEPWNED", 0) == 0 ? 1 : 0;
  std::printf(
      "depfile: %d builds (%zu name classes, as a texture and as the source, with make and ninja), "
      "%d with a name refused by the cook, %d wrong outcomes (re-runs or dependencies), %d commands run "
      "from a name\n",
      tried, hostile_names().size(), refused, wrong, commands);
  EXPECT_EQ(wrong, 0);
  EXPECT_EQ(commands, 0);
  fs::remove_all(base);
}

// The spelling itself, for the names the builds above do not reach (folders, deps-only rules).
TEST(CookDepfile, SpellingRules) {
  std::string why;
  EXPECT_EQ(ossa::cook::depfile_spelling("/a b/c#d$e:f", false, why), "/a\\ b/c\\#d$$e\\:f");
  EXPECT_EQ(ossa::cook::depfile_spelling("/a\\b/%x", false, why), "/a\\b/%x") << "'%' is plain outside a target";
  EXPECT_FALSE(ossa::cook::depfile_spelling("/a/%x.ossa", true, why));
  EXPECT_NE(why.find("pattern rule"), std::string::npos);
  for (const char* bad : {"/a/b:", "/a/lib(x)", "/a\\ b", "/a\\#b", "/a\\", "/a\\$b", "/a\x7f", "/a\n"})
    EXPECT_FALSE(ossa::cook::depfile_spelling(bad, false, why)) << bad;
  EXPECT_TRUE(ossa::cook::depfile_spelling("/a/(x)y", false, why));
}

}  // namespace
