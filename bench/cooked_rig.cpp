// cooked_rig.cpp — cooked_rig.h.
#include "bench/cooked_rig.h"

#include <unistd.h>

#include <atomic>
#include <string>

#include "cooker/cook.h"

namespace ossa::bench {

Result<cook::SourceSkeleton> cooked_rig(const std::filesystem::path& source) {
  namespace fs = std::filesystem;
  static std::atomic<unsigned> counter{0};
  const fs::path dir =
      fs::temp_directory_path() / ("ossa-bench-rig-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
  const fs::path out = dir / (source.stem().string() + ".ossa");
  const cook::CookRecord record = cook::cook_file(source, out, cook::CookOptions{});
  Result<cook::SourceSkeleton> skeleton =
      record.ok ? cook::load_reference_skeleton(out) : Result<cook::SourceSkeleton>(Error{record.error});
  std::error_code ec;
  fs::remove_all(dir, ec);
  return skeleton;
}

}  // namespace ossa::bench
