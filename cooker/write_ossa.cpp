// write_ossa.cpp — SourceScene + CookedMeshes -> .ossa bytes (write_ossa.h).
//
// FlatBuffers builds back to front, so every child (string, vector, sub-table) is created before
// its parent table starts. The order of creation is fixed — skeleton, meshes in order, clips in
// order, materials in order, provenance, file — and every input is an ordered container, so the
// bytes depend only on the input. Nothing time- or address-dependent is written.
//
// The GPU byte vectors (vertices, indices), embedded texture data and clips' key_values get
// 16-byte alignment from ForceVectorAlignment right before CreateVector: flatc 2.0.8 accepts
// force_align on vectors in the schema but generates nothing for it. The builder raises its minimum alignment to 16 with it, and
// Finish pads the whole buffer to that, so "aligned from the end" is also "aligned from the start".
#include "cooker/write_ossa.h"

#include <flatbuffers/flatbuffers.h>

#include <string_view>

#include "format/clip_codec.h"
#include "format/hash.h"
#include "format/version.h"

namespace ossa::cook {
namespace {

using flatbuffers::FlatBufferBuilder;
using flatbuffers::Offset;
using flatbuffers::Vector;

constexpr size_t kGpuAlignment = 16;

fb::Vec3 vec3(const glm::vec3& v) { return fb::Vec3(v.x, v.y, v.z); }
fb::Quat quat(const glm::quat& q) { return fb::Quat(q.x, q.y, q.z, q.w); }

// glm::mat4 is column-major (m[column][row]); so is fb::Mat4.
fb::Mat4 mat4(const glm::mat4& m) {
  float values[16];
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) values[c * 4 + r] = m[c][r];
  return fb::Mat4(flatbuffers::span<const float, 16>(values));
}

Offset<Vector<uint8_t>> aligned_bytes(FlatBufferBuilder& fbb, const std::vector<uint8_t>& bytes) {
  fbb.ForceVectorAlignment(bytes.size(), 1, kGpuAlignment);
  return fbb.CreateVector(bytes.data(), bytes.size());
}

Offset<fb::Skeleton> write_skeleton(FlatBufferBuilder& fbb, const SourceSkeleton& skeleton) {
  std::vector<Offset<flatbuffers::String>> names;
  std::vector<int16_t> parents;
  std::vector<fb::Vec3> translations, scales;
  std::vector<fb::Quat> rotations;
  std::vector<fb::Mat4> inverse_bind;
  for (const SourceJoint& j : skeleton.joints) {
    names.push_back(fbb.CreateString(j.name));
    parents.push_back(static_cast<int16_t>(j.parent));
    translations.push_back(vec3(j.translation));
    rotations.push_back(quat(j.rotation));
    scales.push_back(vec3(j.scale));
    inverse_bind.push_back(mat4(j.inverse_bind));
  }
  const auto names_v = fbb.CreateVector(names);
  const auto parents_v = fbb.CreateVector(parents);
  const auto translations_v = fbb.CreateVectorOfStructs(translations);
  const auto rotations_v = fbb.CreateVectorOfStructs(rotations);
  const auto scales_v = fbb.CreateVectorOfStructs(scales);
  const auto inverse_bind_v = fbb.CreateVectorOfStructs(inverse_bind);
  return fb::CreateSkeleton(fbb, names_v, parents_v, translations_v, rotations_v, scales_v, inverse_bind_v,
                            skeleton_hash_of(skeleton));
}

Offset<fb::Mesh> write_mesh(FlatBufferBuilder& fbb, const CookedMesh& mesh) {
  const auto name = fbb.CreateString(mesh.name);
  const auto layout = fbb.CreateVectorOfStructs(mesh.layout);
  const auto vertices = aligned_bytes(fbb, mesh.vertices);
  const auto indices = aligned_bytes(fbb, mesh.indices);
  const auto submeshes = fbb.CreateVectorOfStructs(mesh.submeshes);
  const auto joints = fbb.CreateVector(mesh.joints);
  std::vector<fb::Mat4> inverse_bind;
  for (const glm::mat4& m : mesh.inverse_bind) inverse_bind.push_back(mat4(m));
  const auto inverse_bind_v = fbb.CreateVectorOfStructs(inverse_bind);
  const fb::Vec3 bounds_min = vec3(mesh.bounds_min), bounds_max = vec3(mesh.bounds_max);
  const fb::Vec3 offset = vec3(mesh.position_offset), scale = vec3(mesh.position_scale);
  return fb::CreateMesh(fbb, name, mesh.vertex_count, mesh.vertex_stride, layout, vertices, mesh.index_format,
                        indices, submeshes, &bounds_min, &bounds_max, &offset, &scale, joints, inverse_bind_v);
}

Offset<fb::RootMotion> write_root_motion(FlatBufferBuilder& fbb, const SourceRootMotion& rm) {
  std::vector<fb::Vec3> translations;
  translations.reserve(rm.translations.size());
  for (const glm::vec3& v : rm.translations) translations.push_back(vec3(v));
  const auto translations_v = fbb.CreateVectorOfStructs(translations);
  const auto yaws_v = fbb.CreateVector(rm.yaws);
  return fb::CreateRootMotion(fbb, translations_v, yaws_v, rm.up_axis);
}

// Every vector is written, empty or not, so readers see the same shape for every clip.
Offset<fb::Clip> write_clip(FlatBufferBuilder& fbb, const CompressedClip& clip, uint64_t skeleton_hash,
                            uint16_t joint_count) {
  const auto name = fbb.CreateString(clip.name);
  std::vector<fb::ConstantChannel> constants;
  constants.reserve(clip.constants.size());
  for (const CompressedConstant& c : clip.constants) {
    constants.emplace_back(c.joint, static_cast<fb::Channel>(c.channel),
                           fb::Quat(c.value[0], c.value[1], c.value[2], c.value[3]));
  }
  std::vector<fb::AnimatedChannel> animated;
  animated.reserve(clip.animated.size());
  for (const CompressedAnimated& a : clip.animated) {
    animated.emplace_back(a.joint, static_cast<fb::Channel>(a.channel), a.bits, a.dropped, a.first_key, a.key_count,
                          a.bit_offset, fb::Vec3(a.range_min[0], a.range_min[1], a.range_min[2]),
                          fb::Vec3(a.range_extent[0], a.range_extent[1], a.range_extent[2]));
  }
  const auto constants_v = fbb.CreateVectorOfStructs(constants);
  const auto animated_v = fbb.CreateVectorOfStructs(animated);
  const auto key_frames_v = fbb.CreateVector(clip.key_frames);
  // Decoders read 64 bits at a time: the stream ends with kKeyValuePadding zero bytes (the
  // compressor's BitWriter appends them; a hand-made clip without them gets them here).
  std::vector<uint8_t> key_values = clip.key_values;
  if (key_values.size() < kKeyValuePadding) key_values.resize(kKeyValuePadding, 0);
  const auto key_values_v = aligned_bytes(fbb, key_values);
  const auto compression = fb::CreateClipCompression(fbb, clip.tolerance, clip.probe_distance, clip.max_error,
                                                     clip.mean_error, clip.worst_joint, clip.raw_bytes);
  const auto root_motion = clip.has_root_motion ? write_root_motion(fbb, clip.root_motion) : Offset<fb::RootMotion>();
  return fb::CreateClip(fbb, name, clip.grid.duration(), clip.grid.sample_rate, clip.grid.frame_count, skeleton_hash,
                        joint_count, constants_v, animated_v, key_frames_v, key_values_v, compression, root_motion);
}

Offset<fb::Material> write_material(FlatBufferBuilder& fbb, const SourceMaterial& material) {
  const auto name = fbb.CreateString(material.name);
  std::vector<Offset<fb::Texture>> textures;
  for (const SourceTexture& t : material.textures) {
    // Absent rather than empty: a referenced texture has no data, an embedded one may have no path.
    const auto path = t.path.empty() ? Offset<flatbuffers::String>() : fbb.CreateString(t.path);
    const auto mime = t.mime.empty() ? Offset<flatbuffers::String>() : fbb.CreateString(t.mime);
    const auto data = t.data.empty() ? Offset<Vector<uint8_t>>() : aligned_bytes(fbb, t.data);
    textures.push_back(fb::CreateTexture(fbb, static_cast<fb::TextureRole>(t.role), path, mime, data));
  }
  const auto textures_v = fbb.CreateVector(textures);
  const fb::Vec3 ambient = vec3(material.ambient), diffuse = vec3(material.diffuse), specular = vec3(material.specular);
  return fb::CreateMaterial(fbb, name, &ambient, &diffuse, &specular, material.shininess, material.opacity, textures_v);
}

}  // namespace

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

std::vector<uint8_t> write_ossa(const SourceScene& scene, std::span<const CookedMesh> meshes,
                                std::span<const CompressedClip> clips, const WriteProvenance& provenance,
                                const WriteOptions& options) {
  FlatBufferBuilder fbb(1 << 16);

  // A file without joints has no skeleton table (readers see "no skeleton", not an empty one).
  Offset<fb::Skeleton> skeleton;
  if (options.include_skeleton && !scene.skeleton.joints.empty()) skeleton = write_skeleton(fbb, scene.skeleton);

  std::vector<Offset<fb::Mesh>> mesh_offsets;
  for (const CookedMesh& mesh : meshes) mesh_offsets.push_back(write_mesh(fbb, mesh));
  const auto meshes_v = fbb.CreateVector(mesh_offsets);

  const uint64_t rig_hash = skeleton_hash_of(scene.skeleton);
  const auto joint_count = static_cast<uint16_t>(scene.skeleton.joints.size());
  std::vector<Offset<fb::Clip>> clip_offsets;
  for (const CompressedClip& clip : clips) clip_offsets.push_back(write_clip(fbb, clip, rig_hash, joint_count));
  const auto clips_v = fbb.CreateVector(clip_offsets);

  std::vector<Offset<fb::Material>> material_offsets;
  for (const SourceMaterial& material : scene.materials) material_offsets.push_back(write_material(fbb, material));
  const auto materials_v = fbb.CreateVector(material_offsets);

  // Named first: the order of evaluation of function arguments is unspecified, the bytes must not be.
  const auto source_name = fbb.CreateString(provenance.source_name);
  const auto cooker_version = fbb.CreateString(kCookerVersion);
  const auto options_text = fbb.CreateString(provenance.options);
  const auto prov = fb::CreateProvenance(fbb, source_name, provenance.source_hash, cooker_version, options_text);

  const auto root = fb::CreateFile(fbb, kFormatVersion, scene.metres_per_unit, skeleton, meshes_v, clips_v,
                                   materials_v, prov);
  fb::FinishFileBuffer(fbb, root);
  return std::vector<uint8_t>(fbb.GetBufferPointer(), fbb.GetBufferPointer() + fbb.GetSize());
}

}  // namespace ossa::cook
