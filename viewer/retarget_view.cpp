// retarget_view.cpp — see retarget_view.h.
#include "viewer/retarget_view.h"

#include <algorithm>
#include <fstream>
#include <iterator>
#include <optional>
#include <sstream>
#include <string_view>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include "tools/retarget/map_file.h"
#include <ossa/retarget/humanoid.h>

namespace ossa::view {
namespace {

constexpr glm::vec4 kLeftColor{0.2f, 0.85f, 1.0f, 1.0f};
constexpr glm::vec4 kRightColor{1.0f, 0.3f, 0.85f, 1.0f};
constexpr glm::vec4 kCentreColor{1.0f, 0.9f, 0.2f, 1.0f};

using Rig = tools::MappedRig;

/// A cooked skeleton's joints as tools::map_rig takes them (names view the file's strings).
Result<Rig> make_rig(const SkeletonView& sk, const tools::HumanoidMapFile* map, const std::string& map_file,
                     const char* role, std::string_view name) {
  std::vector<std::string_view> names;
  std::vector<int16_t> parents;
  std::vector<Transform> bind;
  for (size_t j = 0; j < sk.joint_count(); ++j) {
    names.push_back(sk.joint_name(j));
    parents.push_back(sk.parents()[j]);
    const fb::Vec3& t = sk.bind_translations()[j];
    const fb::Quat& q = sk.bind_rotations()[j];
    const fb::Vec3& s = sk.bind_scales()[j];
    bind.push_back(Transform{{t.x(), t.y(), t.z()}, glm::quat(q.w(), q.x(), q.y(), q.z()), {s.x(), s.y(), s.z()}});
  }
  return tools::map_rig(std::move(names), std::move(parents), std::move(bind), map, map_file, role, name);
}

Result<std::optional<tools::HumanoidMapFile>> read_map(const std::string& path) {
  if (path.empty()) return std::optional<tools::HumanoidMapFile>{};
  std::ifstream in(path, std::ios::binary);
  if (!in) return Error{path + ": cannot read the map file"};
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto parsed = tools::parse_humanoid_map_file(text, path);
  if (!parsed) return parsed.error();
  return std::optional<tools::HumanoidMapFile>(std::move(*parsed));
}

}  // namespace

Result<std::unique_ptr<RetargetView>> make_retarget_view(const Scene& target, std::span<const std::string> files,
                                                         const std::string& map_file, const std::string& clip) {
  if (files.empty()) return Error{"--retarget-from: no source file"};
  auto scene = load_scene(files);
  if (!scene) return scene.error();
  if (scene->skeleton().empty()) return Error{files.front() + ": has no skeleton to retarget from"};
  if (scene->clips.empty()) return Error{files.front() + ": the source files hold no clip to retarget"};
  int index = 0;
  if (!clip.empty()) {
    index = find_clip(*scene, clip);
    if (index < 0) {
      std::string names;
      for (const SceneClip& c : scene->clips) names += (names.empty() ? "'" : ", '") + c.label + "'";
      return Error{files.front() + ": no clip named '" + clip + "' to retarget (clips: " + names + ")"};
    }
  }
  auto map = read_map(map_file);
  if (!map) return map.error();
  const tools::HumanoidMapFile* spec = *map ? &**map : nullptr;
  const std::string source_name = files.front() + " (source rig)";
  const std::string target_name = target.paths.empty() ? std::string("the character") : target.paths.front();
  auto source = make_rig(scene->skeleton(), spec, map_file, "source", source_name);
  if (!source) return source.error();
  auto dest = make_rig(target.skeleton(), spec, map_file, "target", target_name);
  if (!dest) return dest.error();
  tools::finish_mapped_rig(*source, source_name);
  tools::finish_mapped_rig(*dest, target_name);
  if (Status st = check_humanoid(source->rig.humanoid, source->parents, source_name); !st) return st.error();
  if (Status st = check_humanoid(dest->rig.humanoid, dest->parents, target_name); !st) return st.error();
  auto built = make_retarget_map(source->rig, dest->rig);
  if (!built) return built.error();

  auto view = std::make_unique<RetargetView>();
  view->map = std::move(*built);
  view->scratch = make_retarget_scratch(view->map);
  view->files.assign(files.begin(), files.end());
  view->map_file = map_file;
  auto renderer = create_renderer();
  if (!renderer) return renderer.error();
  view->renderer = std::move(*renderer);
  std::vector<std::string> warnings;
  if (Status st = upload_scene(view->renderer, *scene, warnings); !st) {
    destroy_renderer(view->renderer);
    return st.error();
  }
  view->source = std::move(*scene);
  view->animator = make_animator(view->source, 1);
  if (Status st = select_clip(view->source, view->animator, index, false); !st) {
    release_retarget_view(*view);
    return st.error();
  }
  return view;
}

void release_retarget_view(RetargetView& view) {
  release_scene(view.renderer);
  destroy_renderer(view.renderer);
}

void retarget_poses(RetargetView& view, Animator& target, const Box& one, float dt) {
  advance(view.source, view.animator, dt);
  PoseTimings ignored;
  produce_local_poses(view.source, view.animator, ignored);
  compute_model_poses(view.source, view.animator, ignored);
  AnimInstance& source = view.animator.instances.front();
  RetargetInput in;
  in.source = source.local.span();
  for (AnimInstance& instance : target.instances) (void)retarget(view.map, in, view.scratch, instance.local);

  // The source beside the character: map_point as a matrix, then moved to the character's left
  // (on the right of a front view) by a character's width, along the ground.
  const RetargetMap& m = view.map;
  const glm::vec3 size = one.empty() ? glm::vec3(1.0f) : one.size();
  const float aside = 1.25f * std::max(std::max(size.x, size.z), 0.6f * size.y);
  const glm::vec3 up = m.target_pose.up;
  glm::vec3 left = glm::inverse(m.target_pose.frame) * glm::vec3(1.0f, 0.0f, 0.0f);
  left -= glm::dot(left, up) * up;
  left = glm::length(left) > 1e-6f ? glm::normalize(left) : glm::vec3(1.0f, 0.0f, 0.0f);
  view.place = glm::translate(glm::mat4(1.0f), m.target_pose.origin + aside * left) * glm::mat4_cast(m.rotation) *
               glm::scale(glm::mat4(1.0f), glm::vec3(m.scale)) * glm::translate(glm::mat4(1.0f), -m.source_pose.origin);
  for (glm::mat4& x : source.model) x = view.place * x;
}

void build_mapping_lines(const RetargetView& view, const Animator& target, const glm::vec3& offset,
                         OverlayGeometry& out) {
  if (target.instances.empty() || view.animator.instances.empty()) return;
  const auto& from = view.animator.instances.front().model;
  const auto& to = target.instances.front().model;
  for (size_t b = 0; b < kHumanoidBoneCount; ++b) {
    const int16_t s = view.map.source_humanoid.joints[b], t = view.map.target_humanoid.joints[b];
    if (s < 0 || t < 0 || static_cast<size_t>(s) >= from.size() || static_cast<size_t>(t) >= to.size()) continue;
    const std::string_view name = humanoid_bone_name(static_cast<HumanoidBone>(b));
    const glm::vec4 color = name.starts_with("left")    ? kLeftColor
                            : name.starts_with("right") ? kRightColor
                                                        : kCentreColor;
    out.on_top.push_back({glm::vec3(from[static_cast<size_t>(s)][3]), color});
    out.on_top.push_back({glm::vec3(to[static_cast<size_t>(t)][3]) + offset, color});
  }
}

Box source_bounds(const RetargetView& view) {
  if (view.animator.instances.empty()) return Box{};
  const auto& model = view.animator.instances.front().model;
  if (shows_bones_only(view.source)) return joint_bounds(model);
  return posed_bounds(view.source.character(), model);
}

}  // namespace ossa::view
