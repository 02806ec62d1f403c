// viewer_unit_common.h — what the viewer_unit_test sources share: where the fixture's cooked
// samples are (viewer_cook.cmake writes them; CTest passes OSSA_VIEWER_COOKED, the build the
// compile-time default). Header-only: the unit tests link the viewer library, not the harness.
#pragma once
#include <filesystem>

#include "test_files.h"

#ifndef OSSA_TEST_VIEWER_COOKED_DIR
#define OSSA_TEST_VIEWER_COOKED_DIR "viewer-cooked"
#endif

namespace ossa::test {

/// A cooked sample by its path under the fixture's quantized/ folder.
inline std::filesystem::path viewer_unit_cooked(const char* rel) {
  return std::filesystem::path(env_or("OSSA_VIEWER_COOKED", OSSA_TEST_VIEWER_COOKED_DIR)) / "quantized" / rel;
}

}  // namespace ossa::test
