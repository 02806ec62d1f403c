// reference_skeleton.cpp — see reference_skeleton.h.
#include "cooker/model/reference_skeleton.h"

#include <string>

#include <ossa/loader/asset.h>

namespace ossa::cook {
namespace fs = std::filesystem;

Result<SourceSkeleton> load_reference_skeleton(const fs::path& ossa_file, InputFile* as_read) {
  if (as_read != nullptr) {
    InputLog log;
    InputLogScope scope(&log);
    auto bytes = read_input(ossa_file);
    if (!bytes) return bytes.error();
    *as_read = log.files().front();
  }
  auto asset = Asset::open(ossa_file.string());
  if (!asset) return asset.error();
  const SkeletonView sk = asset->skeleton();
  if (sk.empty() || sk.joint_count() == 0) return Error{ossa_file.string() + ": holds no skeleton to cook against"};
  SourceSkeleton out;
  out.metres_per_unit = asset->file().metres_per_unit();
  out.joints.resize(sk.joint_count());
  for (size_t i = 0; i < sk.joint_count(); ++i) {
    SourceJoint& j = out.joints[i];
    j.name = std::string(sk.joint_name(i));
    j.parent = sk.parents()[i];
    const fb::Vec3& t = sk.bind_translations()[i];
    const fb::Quat& r = sk.bind_rotations()[i];
    const fb::Vec3& s = sk.bind_scales()[i];
    j.translation = {t.x(), t.y(), t.z()};
    j.rotation = glm::quat(r.w(), r.x(), r.y(), r.z());
    j.scale = {s.x(), s.y(), s.z()};
    const auto* m = sk.inverse_bind()[i].m();
    for (int c = 0; c < 4; ++c)
      for (int r4 = 0; r4 < 4; ++r4) j.inverse_bind[c][r4] = m->Get(static_cast<flatbuffers::uoffset_t>(c * 4 + r4));
  }
  return out;
}

}  // namespace ossa::cook
