// source_scene.cpp — see source_scene.h.
#include "cooker/model/source_scene.h"

#include <string_view>

#include <ossa/format/hash.h>

namespace ossa::cook {

uint64_t skeleton_hash_of(const SourceSkeleton& skeleton) {
  std::vector<std::string_view> names;
  std::vector<int16_t> parents;
  names.reserve(skeleton.joints.size());
  parents.reserve(skeleton.joints.size());
  for (const SourceJoint& j : skeleton.joints) {
    names.push_back(j.name);
    parents.push_back(static_cast<int16_t>(j.parent));
  }
  return skeleton_hash(names, parents);
}

}  // namespace ossa::cook
