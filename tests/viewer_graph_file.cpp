// viewer_graph_file.cpp — writes the Pab sample graph file the viewer tests open with --graph.
//
//   viewer_graph_file OUT.ossa
//
// ossa-cook cannot cook graph JSON yet, so the file is made the way the graph runtime tests make
// theirs (tests/graph_fixture.h): Pab's skeleton and its walk / jog / run / crossarms clips, plus
// the sample graph "pab" (speed -> walk/jog/run blend space, sprint and pose states, crossed_arms
// layer, stop trigger), through the cooker's writer; then verified by the runtime's loader. Pab's
// arnaud.ossa, cooked against the same skeleton, is the mesh it animates.
#include <cstdio>

#include "graph_fixture.h"
#include "test_files.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: viewer_graph_file OUT.ossa\n");
    return 2;
  }
  const ossa::test::PabRig* rig = ossa::test::pab_rig();
  if (rig == nullptr) return 1;  // pab_rig printed why
  ossa::Result<ossa::Asset> file = ossa::test::make_graph_file(*rig, {ossa::test::pab_sample_graph(*rig)});
  if (!file) {
    std::fprintf(stderr, "viewer_graph_file: %s\n", file.error().message.c_str());
    return 1;
  }
  if (!ossa::test::write_file(argv[1], file->bytes())) {
    std::fprintf(stderr, "viewer_graph_file: cannot write %s\n", argv[1]);
    return 1;
  }
  return 0;
}
