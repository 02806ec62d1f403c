// main.cpp — the smallest game that uses ossa: open a cooked character, play its animation graph
// for a while, and print one joint's model-space position. It is built out of tree against an
// installed ossa (tests/install_test.cmake does that), so it may use only what a game gets from
// find_package(ossa): the <ossa/...> headers and ossa::runtime.
//
//   ossa_consumer FILE.ossa GRAPH JOINT [PARAM=VALUE ...] [--seconds S]
//
// Prints `ossa <version> (format N)`, then `JOINT x y z` in the file's units after S seconds
// (default 1) of 60 Hz updates. Exit 0 on success, 1 with a message naming what failed.
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>
#include <vector>

#include <ossa/anim/pose_ops.h>
#include <ossa/graph/graph.h>
#include <ossa/loader/asset.h>
#include <ossa/version.h>

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: %s FILE.ossa GRAPH JOINT [PARAM=VALUE ...] [--seconds S]\n", argv[0]);
    return 2;
  }
  std::printf("ossa %s (format %u)\n", OSSA_VERSION_STRING, ossa::kFormatVersion);

  auto asset = ossa::Asset::open(argv[1]);
  if (!asset) return std::fprintf(stderr, "%s\n", asset.error().message.c_str()), 1;
  auto definition = ossa::GraphDefinition::create(*asset, argv[2]);
  if (!definition) return std::fprintf(stderr, "%s\n", definition.error().message.c_str()), 1;
  auto character = ossa::GraphInstance::create(*definition);
  if (!character) return std::fprintf(stderr, "%s\n", character.error().message.c_str()), 1;
  const int joint = asset->skeleton().find_joint(argv[3]);
  if (joint < 0) return std::fprintf(stderr, "%s: no joint named '%s'\n", argv[1], argv[3]), 1;

  double seconds = 1.0;
  for (int i = 4; i < argc; ++i) {
    const std::string_view arg = argv[i];
    if (arg == "--seconds" && i + 1 < argc) {
      seconds = std::strtod(argv[++i], nullptr);
      continue;
    }
    const size_t eq = arg.find('=');
    const int parameter = definition->find_parameter(arg.substr(0, eq));
    if (eq == std::string_view::npos || parameter < 0)
      return std::fprintf(stderr, "%s: graph '%s' has no parameter '%s'\n", argv[1], argv[2], argv[i]), 1;
    const std::string value(arg.substr(eq + 1));
    if (value == "true" || value == "false") character->set_bool(parameter, value == "true");
    else character->set_float(parameter, std::strtof(value.c_str(), nullptr));
  }

  for (int frame = 0; frame < static_cast<int>(seconds * 60.0 + 0.5); ++frame) character->update(1.0f / 60.0f);

  std::vector<glm::mat4> model(definition->joint_count());
  ossa::local_to_model(asset->skeleton().parents(), character->pose(), model);
  const glm::vec3 p = model[static_cast<size_t>(joint)][3];
  std::printf("%s %.4f %.4f %.4f\n", argv[3], p.x, p.y, p.z);
  return 0;
}
