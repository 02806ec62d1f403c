// runtime_view_test.cpp — the loader's promises to a game: what was written is what the views
// read, byte ranges are spans into the file (16-byte aligned, no copies), an Asset owns its bytes
// exactly once across moves, and open() and from_bytes() see the same file.
//
// Files come from test_files.h's synthetic writer (independent of the cooker), plus one tiny
// hand-built file for what that writer always writes (a mesh without joint vectors, a file
// without a skeleton). Invalid files are the bad-input suite's business, not this one's.
#include <gtest/gtest.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <new>
#include <string>
#include <utility>
#include <vector>

#include <flatbuffers/flatbuffers.h>

#include <ossa/format/clip_codec.h>
#include <ossa/format/hash.h>
#include <ossa/version.h>
#include <ossa/anim/pose.h>
#include <ossa/anim/sample.h>
#include <ossa/loader/allocator.h>
#include <ossa/loader/asset.h>
#include <ossa/loader/texture.h>
#include "test_files.h"

namespace ossa {
namespace {

using test::make_valid_file;
using test::SyntheticSpec;

bool aligned16(const void* p) { return reinterpret_cast<uintptr_t>(p) % 16 == 0; }

Asset load(std::span<const uint8_t> bytes, std::string name = "synthetic.ossa") {
  auto asset = Asset::from_bytes(bytes, std::move(name));
  EXPECT_TRUE(asset.ok()) << (asset.ok() ? "" : asset.error().message);
  if (!asset.ok()) std::abort();  // every caller needs an asset; nothing sensible follows
  return std::move(asset).value();
}

/// A file with no skeleton, no clips, no materials and one static mesh whose optional vectors
/// (name, joints, inverse_bind, bounds) are all left out.
std::vector<uint8_t> make_static_mesh_file() {
  flatbuffers::FlatBufferBuilder fbb;
  const fb::VertexAttribute layout[] = {{fb::VertexSemantic::Position, fb::VertexFormat::Float32x3, 0}};
  const float positions[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const uint16_t indices[] = {0, 1, 2};
  const fb::Submesh submesh(0, 3, 0);
  const auto layout_vector = fbb.CreateVectorOfStructs(layout, 1);
  fbb.ForceVectorAlignment(sizeof positions, 1, 16);
  const auto vertices = fbb.CreateVector(reinterpret_cast<const uint8_t*>(positions), sizeof positions);
  fbb.ForceVectorAlignment(sizeof indices, 1, 16);
  const auto index_vector = fbb.CreateVector(reinterpret_cast<const uint8_t*>(indices), sizeof indices);
  const auto submeshes = fbb.CreateVectorOfStructs(&submesh, 1);
  fb::MeshBuilder mesh(fbb);
  mesh.add_vertex_count(3);
  mesh.add_vertex_stride(12);
  mesh.add_layout(layout_vector);
  mesh.add_vertices(vertices);
  mesh.add_index_format(fb::IndexFormat::Uint16);
  mesh.add_indices(index_vector);
  mesh.add_submeshes(submeshes);
  const auto mesh_offset = mesh.Finish();
  const std::vector<flatbuffers::Offset<fb::Mesh>> meshes = {mesh_offset};
  fb::FinishFileBuffer(fbb, fb::CreateFileDirect(fbb, kFormatVersion, 0.01f, 0, &meshes));
  return {fbb.GetBufferPointer(), fbb.GetBufferPointer() + fbb.GetSize()};
}

// ---- what was written is what is read ----------------------------------------------------------

TEST(RuntimeView, SkeletonViewsReturnWhatWasWritten) {
  const SyntheticSpec spec;
  const auto bytes = make_valid_file(spec);
  const Asset asset = load(bytes);
  const SkeletonView s = asset.skeleton();
  const test::SyntheticSkeleton& want = *spec.skeleton;

  ASSERT_FALSE(s.empty());
  ASSERT_EQ(s.joint_count(), want.names.size());
  for (size_t i = 0; i < want.names.size(); ++i) {
    EXPECT_EQ(s.joint_name(i), want.names[i]);
    EXPECT_EQ(s.parents()[i], want.parents[i]);
    EXPECT_EQ(s.find_joint(want.names[i]), static_cast<int>(i));
    EXPECT_EQ(s.bind_translations()[i].y(), want.translations[i].y());
    EXPECT_EQ(s.bind_rotations()[i].z(), want.rotations[i].z());
    EXPECT_EQ(s.bind_rotations()[i].w(), want.rotations[i].w());
    EXPECT_EQ(s.bind_scales()[i].x(), want.scales[i].x());
  }
  EXPECT_EQ(s.parents().size(), want.names.size());
  EXPECT_EQ(s.bind_translations().size(), want.names.size());
  EXPECT_EQ(s.bind_rotations().size(), want.names.size());
  EXPECT_EQ(s.bind_scales().size(), want.names.size());
  EXPECT_EQ(s.inverse_bind().size(), want.names.size());
  EXPECT_EQ(s.find_joint("no such joint"), -1);
  EXPECT_EQ(s.find_joint(""), -1);
  EXPECT_EQ(s.joint_name(want.names.size()), "");  // out of range: empty, not a crash

  std::vector<std::string_view> names(want.names.begin(), want.names.end());
  EXPECT_EQ(s.hash(), skeleton_hash(names, want.parents));

  // The spans point into the asset's bytes: no copies were made.
  const auto file = asset.bytes();
  EXPECT_GE(reinterpret_cast<const uint8_t*>(s.parents().data()), file.data());
  EXPECT_LE(reinterpret_cast<const uint8_t*>(s.inverse_bind().data() + s.inverse_bind().size()),
            file.data() + file.size());
}

TEST(RuntimeView, MeshViewsReturnWhatWasWritten) {
  const SyntheticSpec spec;
  const auto bytes = make_valid_file(spec);
  const Asset asset = load(bytes);
  const test::SyntheticMesh& want = spec.meshes[0];
  ASSERT_EQ(asset.mesh_count(), 1u);
  const MeshView m = asset.mesh(0);

  EXPECT_EQ(m.name(), want.name);
  EXPECT_EQ(m.vertex_count(), want.vertices.size());
  EXPECT_EQ(m.vertex_stride(), want.vertex_stride);
  ASSERT_EQ(m.layout().size(), want.layout.size());
  for (size_t i = 0; i < want.layout.size(); ++i) {
    EXPECT_EQ(m.layout()[i].semantic(), want.layout[i].semantic());
    EXPECT_EQ(m.layout()[i].format(), want.layout[i].format());
    EXPECT_EQ(m.layout()[i].offset(), want.layout[i].offset());
  }
  const fb::VertexAttribute* joints = m.attribute(fb::VertexSemantic::Joints);
  ASSERT_NE(joints, nullptr);
  EXPECT_EQ(joints->format(), fb::VertexFormat::Uint8x4);
  EXPECT_EQ(joints->offset(), 16);
  ASSERT_NE(m.attribute(fb::VertexSemantic::Position), nullptr);
  EXPECT_EQ(m.attribute(fb::VertexSemantic::Position)->format(), fb::VertexFormat::Unorm16x4);
  EXPECT_EQ(m.attribute(fb::VertexSemantic::Tangent), nullptr);
  EXPECT_EQ(m.attribute(fb::VertexSemantic::Color0), nullptr);

  // Vertex bytes: vertex_count * stride, 16-byte aligned in memory and in the file, and the
  // joint slots written for each vertex are where the layout says.
  ASSERT_EQ(m.vertex_bytes().size(), size_t{m.vertex_count()} * m.vertex_stride());
  EXPECT_TRUE(aligned16(m.vertex_bytes().data()));
  EXPECT_EQ((m.vertex_bytes().data() - asset.bytes().data()) % 16, 0);
  for (size_t v = 0; v < want.vertices.size(); ++v)
    for (size_t k = 0; k < 4; ++k) {
      EXPECT_EQ(m.vertex_bytes()[v * m.vertex_stride() + joints->offset() + k], want.vertices[v].slots[k]);
      EXPECT_EQ(m.vertex_bytes()[v * m.vertex_stride() + 20 + k], want.vertices[v].weights[k]);
    }

  // Index bytes: the indices as written, 16-byte aligned.
  EXPECT_EQ(m.index_format(), fb::IndexFormat::Uint16);
  ASSERT_EQ(m.index_count(), want.indices.size());
  ASSERT_EQ(m.index_bytes().size(), want.indices.size() * 2);
  EXPECT_TRUE(aligned16(m.index_bytes().data()));
  EXPECT_EQ((m.index_bytes().data() - asset.bytes().data()) % 16, 0);
  for (size_t i = 0; i < want.indices.size(); ++i) {
    uint16_t index;
    std::memcpy(&index, m.index_bytes().data() + 2 * i, 2);
    EXPECT_EQ(index, want.indices[i]);
  }

  ASSERT_EQ(m.submeshes().size(), want.submeshes.size());
  for (size_t i = 0; i < want.submeshes.size(); ++i) {
    EXPECT_EQ(m.submeshes()[i].first_index(), want.submeshes[i].first_index());
    EXPECT_EQ(m.submeshes()[i].index_count(), want.submeshes[i].index_count());
    EXPECT_EQ(m.submeshes()[i].material(), want.submeshes[i].material());
  }
  ASSERT_EQ(m.joints().size(), want.joints.size());
  for (size_t i = 0; i < want.joints.size(); ++i) EXPECT_EQ(m.joints()[i], want.joints[i]);
  // Default inverse binds are the skeleton's for each slot's joint.
  ASSERT_EQ(m.inverse_bind().size(), want.joints.size());
  const SkeletonView s = asset.skeleton();
  for (size_t i = 0; i < want.joints.size(); ++i)
    EXPECT_EQ(std::memcmp(&m.inverse_bind()[i], &s.inverse_bind()[want.joints[i]], sizeof(fb::Mat4)), 0);
}

TEST(RuntimeView, ClipAndMaterialViewsReturnWhatWasWritten) {
  const SyntheticSpec spec;
  const auto bytes = make_valid_file(spec);
  const Asset asset = load(bytes);
  const test::SyntheticClip& want = spec.clips[0];
  ASSERT_EQ(asset.clip_count(), 1u);
  const ClipView c = asset.clip(0);

  EXPECT_EQ(c.name(), want.name);
  EXPECT_EQ(c.duration(), want.duration_value());
  EXPECT_EQ(c.sample_rate(), want.sample_rate);
  EXPECT_EQ(c.frame_count(), want.frame_count);
  EXPECT_EQ(c.skeleton_hash(), asset.skeleton().hash());
  EXPECT_EQ(c.joint_count(), asset.skeleton().joint_count());
  ASSERT_EQ(c.constants().size(), want.constants.size());
  for (size_t i = 0; i < want.constants.size(); ++i) {
    EXPECT_EQ(c.constants()[i].joint(), want.constants[i].joint);
    EXPECT_EQ(c.constants()[i].channel(), want.constants[i].channel);
    float v[4];
    constant_value(c.constants()[i], v);
    const fb::Quat& q = want.constants[i].value;
    const float w[4] = {q.x(), q.y(), q.z(), want.constants[i].channel == fb::Channel::Rotation ? q.w() : 0.0f};
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(v[k], w[k], 1e-6f) << i << " " << k;
  }
  ASSERT_EQ(c.animated().size(), want.animated.size());
  size_t keys = want.constants.size(), frames = 0;
  for (size_t i = 0; i < want.animated.size(); ++i) {
    const fb::AnimatedChannel& a = c.animated()[i];
    const test::SyntheticAnimated& w = want.animated[i];
    EXPECT_EQ(a.joint(), w.joint);
    EXPECT_EQ(a.channel(), w.channel);
    EXPECT_EQ(widths_of(a), KeyWidths::uniform(w.bits));
    const bool every_frame = keyed_every_frame(a.key_count(), c.frame_count());
    EXPECT_EQ(a.first_key(), every_frame ? 0 : frames);
    ASSERT_EQ(a.key_count(), w.frames.size());
    for (size_t k = 0; k < w.frames.size(); ++k)
      EXPECT_EQ(
          key_frame(c.key_frames().data(), a.first_key(), a.key_count(), c.frame_count(), static_cast<uint32_t>(k)),
          w.frames[k]);
    // Keys decode to the written values within the quantization step (exactly for raw floats).
    const float lo[3] = {a.range_min().x(), a.range_min().y(), a.range_min().z()};
    const float ex[3] = {a.range_extent().x(), a.range_extent().y(), a.range_extent().z()};
    for (uint32_t k = 0; k < a.key_count(); ++k) {
      float v[3];
      decode_key(c.key_values().data(), a.bit_offset(), widths_of(a), a.segment_offset_bits(), lo, ex, k, v);
      for (int j = 0; j < 3; ++j) {
        const float step = w.bits == kRawFloatBits ? 0.0f : 0.5f / static_cast<float>(quant_max(w.bits));
        EXPECT_NEAR(v[j], w.values[k][j], step * ex[j] + 1e-7f) << i << " " << k << " " << j;
      }
    }
    keys += w.frames.size();
    if (!every_frame) frames += w.frames.size();
  }
  EXPECT_EQ(c.key_frames().size(), frames);
  EXPECT_GE(c.key_values().size(), kKeyValuePadding);
  EXPECT_EQ(c.key_count(), keys);
  ASSERT_NE(c.compression(), nullptr);
  EXPECT_GT(c.compression()->raw_bytes(), 0u);
  EXPECT_EQ(c.root_motion(), nullptr);
  EXPECT_TRUE(check_clip_binding(c, asset.skeleton(), asset.name()).ok());

  ASSERT_EQ(asset.material_count(), 1u);
  const fb::Material& m = asset.material(0);
  EXPECT_EQ(m.name()->str(), spec.materials[0].name);
  EXPECT_EQ(m.shininess(), spec.materials[0].shininess);
  ASSERT_NE(m.textures(), nullptr);
  ASSERT_EQ(m.textures()->size(), 3u);
  const fb::Texture& png = *m.textures()->Get(0);
  ASSERT_NE(png.data(), nullptr);
  EXPECT_EQ(png.data()->size(), spec.materials[0].textures[0].data->size());
  EXPECT_TRUE(aligned16(png.data()->Data()));
  EXPECT_EQ(m.textures()->Get(1)->path()->str(), "textures/skin_normal.png");
  EXPECT_FALSE(TextureView{&png}.gpu_ready());
  EXPECT_EQ(TextureView{&png}.mip_count(), 0u);

  // The cooked BC4 chain: 8 x 4, 4 x 2, 2 x 1, 1 x 1, each a span into the file right after the last.
  const TextureView bc4{m.textures()->Get(2)};
  ASSERT_TRUE(bc4.gpu_ready());
  EXPECT_EQ(bc4.encoding(), fb::TextureEncoding::Bc4);
  EXPECT_FALSE(bc4.srgb());
  ASSERT_EQ(bc4.mip_count(), 4u);
  EXPECT_EQ(bc4.data().size(), test::kBc4Chain.size());
  EXPECT_TRUE(aligned16(bc4.data().data()));
  const uint32_t sizes[4][3] = {{8, 4, 16}, {4, 2, 8}, {2, 1, 8}, {1, 1, 8}};
  size_t offset = 0;
  for (uint32_t k = 0; k < 4; ++k) {
    const TextureLevel level = bc4.level(k);
    EXPECT_EQ(level.width, sizes[k][0]);
    EXPECT_EQ(level.height, sizes[k][1]);
    ASSERT_EQ(level.bytes.size(), sizes[k][2]);
    EXPECT_EQ(level.bytes.data(), bc4.data().data() + offset);
    EXPECT_TRUE(
        std::equal(level.bytes.begin(), level.bytes.end(), test::kBc4Chain.begin() + static_cast<ptrdiff_t>(offset)));
    offset += level.bytes.size();
  }
  EXPECT_TRUE(bc4.level(4).bytes.empty());  // past the chain
  EXPECT_EQ(texture_chain_bytes(fb::TextureEncoding::Bc4, 8, 4, 4), test::kBc4Chain.size());
}

TEST(RuntimeView, AbsentOptionalPartsGiveEmptyViews) {
  const auto bytes = make_static_mesh_file();
  const Asset asset = load(bytes);
  EXPECT_EQ(asset.file().metres_per_unit(), 0.01f);

  const SkeletonView s = asset.skeleton();
  EXPECT_TRUE(s.empty());
  EXPECT_EQ(s.joint_count(), 0u);
  EXPECT_TRUE(s.parents().empty());
  EXPECT_TRUE(s.bind_rotations().empty());
  EXPECT_TRUE(s.inverse_bind().empty());
  EXPECT_EQ(s.find_joint("root"), -1);
  EXPECT_EQ(s.joint_name(0), "");
  EXPECT_EQ(s.hash(), 0u);
  EXPECT_EQ(asset.clip_count(), 0u);
  EXPECT_EQ(asset.material_count(), 0u);

  ASSERT_EQ(asset.mesh_count(), 1u);
  const MeshView m = asset.mesh(0);
  EXPECT_EQ(m.name(), "");
  EXPECT_TRUE(m.joints().empty());
  EXPECT_TRUE(m.inverse_bind().empty());
  EXPECT_EQ(m.attribute(fb::VertexSemantic::Joints), nullptr);
  EXPECT_EQ(m.index_count(), 3u);
  EXPECT_EQ(m.vertex_bytes().size(), 36u);
  EXPECT_TRUE(aligned16(m.vertex_bytes().data()));
  EXPECT_TRUE(aligned16(m.index_bytes().data()));

  // A clip cannot be bound to a missing skeleton.
  const auto with_clip = make_valid_file();
  const Asset clip_asset = load(with_clip);
  const Status st = check_clip_binding(clip_asset.clip(0), s, "rig.ossa");
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("rig.ossa"), std::string::npos) << st.message();
  EXPECT_NE(st.message().find("'walk'"), std::string::npos) << st.message();
}

TEST(RuntimeView, ClipBindingRejectsAnotherRig) {
  const auto bytes = make_valid_file();
  const Asset asset = load(bytes);
  SyntheticSpec other;
  other.skeleton->names[3] = "left_arm";  // a different rig: a different hash
  const auto other_bytes = make_valid_file(other);
  const Asset other_asset = load(other_bytes, "other.ossa");
  ASSERT_NE(asset.skeleton().hash(), other_asset.skeleton().hash());

  EXPECT_TRUE(check_clip_binding(other_asset.clip(0), other_asset.skeleton(), "x").ok());
  const Status st = check_clip_binding(asset.clip(0), other_asset.skeleton(), "other.ossa");
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("other.ossa: clip 'walk'"), std::string::npos) << st.message();
}

// ---- ownership -----------------------------------------------------------------------------------

TEST(RuntimeView, MoveTransfersOwnershipOnce) {
  const auto bytes = make_valid_file();
  Asset a = load(bytes, "a.ossa");
  const uint8_t* data = a.bytes().data();
  const size_t size = a.bytes().size();
  const MeshView mesh_before = a.mesh(0);

  Asset b = std::move(a);
  EXPECT_EQ(b.bytes().data(), data);
  EXPECT_EQ(b.bytes().size(), size);
  EXPECT_EQ(b.name(), "a.ossa");
  EXPECT_EQ(b.mesh(0).fb, mesh_before.fb);  // views survive a move: the bytes did not move
  EXPECT_TRUE(a.bytes().empty());           // NOLINT(bugprone-use-after-move): the moved-from state is specified
  EXPECT_EQ(a.mesh_count(), 0u);
  EXPECT_EQ(a.clip_count(), 0u);
  EXPECT_EQ(a.material_count(), 0u);
  EXPECT_TRUE(a.skeleton().empty());

  // Assigning over a live asset releases that one's bytes (ASan reports a leak or double free
  // if not), and a moved-from asset can be assigned to again.
  Asset c = load(bytes, "c.ossa");
  c = std::move(b);
  EXPECT_EQ(c.bytes().data(), data);
  EXPECT_EQ(c.name(), "a.ossa");
  a = std::move(c);
  EXPECT_EQ(a.bytes().data(), data);
  Asset& self = a;
  a = std::move(self);  // self-move keeps the asset intact
  EXPECT_EQ(a.bytes().data(), data);
  EXPECT_EQ(a.skeleton().joint_count(), 4u);

  // Result<Asset> and containers move Assets around; each still owns exactly one copy.
  std::vector<Asset> assets;
  for (int i = 0; i < 8; ++i) assets.push_back(load(bytes));
  assets.erase(assets.begin() + 2);
  for (const Asset& x : assets) EXPECT_EQ(x.skeleton().joint_count(), 4u);
}

TEST(RuntimeView, FromBytesCopiesIntoAlignedStorage) {
  const auto bytes = make_valid_file();
  // An unaligned source: from_bytes copies, so it still loads; verify_buffer on the unaligned
  // bytes themselves says why it refuses.
  std::vector<uint8_t> shifted(1, 0);
  shifted.insert(shifted.end(), bytes.begin(), bytes.end());
  const std::span<const uint8_t> unaligned(shifted.data() + 1, bytes.size());
  ASSERT_FALSE(aligned16(unaligned.data()));
  const Status st = verify_buffer(unaligned, "u.ossa");
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("16-byte aligned"), std::string::npos) << st.message();

  const Asset asset = load(unaligned);
  EXPECT_TRUE(aligned16(asset.bytes().data()));
  EXPECT_NE(asset.bytes().data(), unaligned.data());
  EXPECT_EQ(std::memcmp(asset.bytes().data(), bytes.data(), bytes.size()), 0);
  EXPECT_TRUE(verify_buffer(asset.bytes(), "aligned.ossa").ok());
}

// ---- open() --------------------------------------------------------------------------------------

TEST(RuntimeView, OpenMissingFileNamesPathAndReason) {
  const std::string path = (test::make_temp_dir("view") / "no-such-file.ossa").string();
  const auto asset = Asset::open(path);
  ASSERT_FALSE(asset.ok());
  const std::string& message = asset.error().message;
  EXPECT_EQ(message.rfind(path + ": ", 0), 0u) << message;
#if defined(_WIN32)
  // The reason is the system's text for ERROR_FILE_NOT_FOUND (FormatMessage), which depends on the
  // Windows version and language: ask only that one is given.
  EXPECT_NE(message.find(": cannot open: "), std::string::npos) << message;
  EXPECT_GT(message.size(), path.size() + std::string(": cannot open: ").size()) << message;
#else
  EXPECT_NE(message.find(std::strerror(ENOENT)), std::string::npos) << message;
#endif
}

TEST(RuntimeView, OpenRejectsDirectoriesAndEmptyFiles) {
  const auto dir = test::make_temp_dir("view");
  const auto as_dir = Asset::open(dir.string());
  ASSERT_FALSE(as_dir.ok());
  EXPECT_NE(as_dir.error().message.find("not a regular file"), std::string::npos) << as_dir.error().message;

  const auto empty = dir / "empty.ossa";
  ASSERT_TRUE(test::write_file(empty, std::string_view()));
  const auto as_empty = Asset::open(empty.string());
  ASSERT_FALSE(as_empty.ok());
  EXPECT_EQ(as_empty.error().message, empty.string() + ": empty file");
}

TEST(RuntimeView, OpenedFileGivesTheSameViewsAsFromBytes) {
  const auto bytes = make_valid_file();
  const auto path = test::make_temp_dir("view") / "synthetic.ossa";
  ASSERT_TRUE(test::write_file(path, std::span<const uint8_t>(bytes)));

  auto opened = Asset::open(path.string());
  ASSERT_TRUE(opened.ok()) << opened.error().message;
  const Asset mapped = std::move(opened).value();
  const Asset copied = load(bytes);

  EXPECT_EQ(mapped.name(), path.string());
  ASSERT_EQ(mapped.bytes().size(), bytes.size());
  EXPECT_EQ(std::memcmp(mapped.bytes().data(), bytes.data(), bytes.size()), 0);
  EXPECT_TRUE(aligned16(mapped.bytes().data()));  // page-aligned, in fact

  // Same views, at the same offsets into each buffer.
  const auto offset = [](const Asset& a, const void* p) { return static_cast<const uint8_t*>(p) - a.bytes().data(); };
  const SkeletonView ms = mapped.skeleton(), cs = copied.skeleton();
  ASSERT_EQ(ms.joint_count(), cs.joint_count());
  for (size_t i = 0; i < ms.joint_count(); ++i) EXPECT_EQ(ms.joint_name(i), cs.joint_name(i));
  EXPECT_EQ(offset(mapped, ms.parents().data()), offset(copied, cs.parents().data()));
  EXPECT_EQ(ms.hash(), cs.hash());

  ASSERT_EQ(mapped.mesh_count(), copied.mesh_count());
  const MeshView mm = mapped.mesh(0), cm = copied.mesh(0);
  EXPECT_EQ(offset(mapped, mm.vertex_bytes().data()), offset(copied, cm.vertex_bytes().data()));
  EXPECT_EQ(offset(mapped, mm.index_bytes().data()), offset(copied, cm.index_bytes().data()));
  ASSERT_EQ(mm.vertex_bytes().size(), cm.vertex_bytes().size());
  EXPECT_EQ(std::memcmp(mm.vertex_bytes().data(), cm.vertex_bytes().data(), mm.vertex_bytes().size()), 0);
  EXPECT_TRUE(aligned16(mm.vertex_bytes().data()));
  EXPECT_TRUE(aligned16(mm.index_bytes().data()));

  ASSERT_EQ(mapped.clip_count(), copied.clip_count());
  EXPECT_EQ(mapped.clip(0).name(), copied.clip(0).name());
  EXPECT_EQ(mapped.clip(0).key_count(), copied.clip(0).key_count());
  EXPECT_EQ(mapped.material_count(), copied.material_count());

  // A mapped asset moves like a copied one.
  Asset moved = load(bytes);
  const uint8_t* data = mapped.bytes().data();
  moved = Asset::open(path.string()).value();
  EXPECT_NE(moved.bytes().data(), data);  // a second mapping
  EXPECT_EQ(moved.skeleton().hash(), ms.hash());
}

// ---- open modes, borrow(), the allocator --------------------------------------------------------

TEST(RuntimeView, ReadAndMapModesGiveEqualViews) {
  const auto bytes = make_valid_file();
  const auto path = test::make_temp_dir("view") / "modes.ossa";
  ASSERT_TRUE(test::write_file(path, std::span<const uint8_t>(bytes)));
  const Asset reference = load(bytes);
  for (const OpenMode mode : {OpenMode::kAuto, OpenMode::kRead, OpenMode::kMap}) {
    SCOPED_TRACE(static_cast<int>(mode));
    auto asset = Asset::open(path.string(), mode);
    ASSERT_TRUE(asset.ok()) << asset.error().message;
    ASSERT_EQ(asset->bytes().size(), bytes.size());
    EXPECT_EQ(std::memcmp(asset->bytes().data(), bytes.data(), bytes.size()), 0);
    EXPECT_TRUE(aligned16(asset->bytes().data()));
    EXPECT_EQ(asset->skeleton().hash(), reference.skeleton().hash());
    EXPECT_EQ(asset->mesh(0).vertex_bytes().data() - asset->bytes().data(),
              reference.mesh(0).vertex_bytes().data() - reference.bytes().data());
    EXPECT_EQ(asset->clip(0).name(), reference.clip(0).name());
    EXPECT_EQ(asset->clip(0).key_count(), reference.clip(0).key_count());
  }
  // The same refusals in every mode.
  for (const OpenMode mode : {OpenMode::kRead, OpenMode::kMap}) {
    const auto missing = Asset::open((path.parent_path() / "missing.ossa").string(), mode);
    EXPECT_FALSE(missing.ok());
    const auto dir = Asset::open(path.parent_path().string(), mode);
    ASSERT_FALSE(dir.ok());
    EXPECT_NE(dir.error().message.find("not a regular file"), std::string::npos) << dir.error().message;
  }
}

TEST(RuntimeView, BorrowVerifiesWithoutCopying) {
  const auto bytes = make_valid_file();
  const test::AlignedBytes aligned(bytes);
  auto borrowed = Asset::borrow(aligned.span(), "borrowed.ossa");
  ASSERT_TRUE(borrowed.ok()) << borrowed.error().message;
  EXPECT_EQ(borrowed->bytes().data(), aligned.span().data());  // no copy
  EXPECT_EQ(borrowed->bytes().size(), bytes.size());
  EXPECT_EQ(borrowed->name(), "borrowed.ossa");
  const Asset reference = load(bytes);
  EXPECT_EQ(borrowed->skeleton().joint_count(), reference.skeleton().joint_count());
  EXPECT_EQ(borrowed->mesh(0).vertex_bytes().data() - aligned.span().data(),
            reference.mesh(0).vertex_bytes().data() - reference.bytes().data());
  // Moving a borrowed asset moves the borrow, never the bytes; destroying it frees nothing.
  Asset moved = std::move(borrowed).value();
  EXPECT_EQ(moved.bytes().data(), aligned.span().data());

  // Unaligned bytes are refused, not copied.
  std::vector<uint8_t> shifted(1, 0);
  shifted.insert(shifted.end(), bytes.begin(), bytes.end());
  const std::span<const uint8_t> unaligned(shifted.data() + 1, bytes.size());
  ASSERT_FALSE(aligned16(unaligned.data()));
  const auto refused = Asset::borrow(unaligned, "u.ossa");
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().message.find("16-byte aligned"), std::string::npos) << refused.error().message;
  EXPECT_EQ(refused.error().message.rfind("u.ossa: ", 0), 0u) << refused.error().message;

  // Aligned but corrupt bytes get the ordinary verification errors.
  std::vector<uint8_t> damaged = bytes;
  damaged.resize(damaged.size() / 2);
  const test::AlignedBytes damaged_aligned(damaged);
  EXPECT_FALSE(Asset::borrow(damaged_aligned.span(), "half.ossa").ok());
}

/// Counts what goes through the installed Allocator; installed for one test, then restored.
struct CountingAllocator {
  size_t allocations = 0, frees = 0, live_bytes = 0, max_alignment = 0;
  bool size_mismatch = false;

  static void* allocate(size_t size, size_t alignment, void* user) {
    auto* self = static_cast<CountingAllocator*>(user);
    ++self->allocations;
    self->live_bytes += size;
    self->max_alignment = std::max(self->max_alignment, alignment);
    return ::operator new (size, std::align_val_t{alignment});
  }
  static void deallocate(void* p, size_t size, size_t alignment, void* user) {
    auto* self = static_cast<CountingAllocator*>(user);
    ++self->frees;
    if (size > self->live_bytes) self->size_mismatch = true;
    self->live_bytes -= std::min(size, self->live_bytes);
    ::operator delete (p, std::align_val_t{alignment});
  }
};

class InstalledAllocator {
 public:
  explicit InstalledAllocator(CountingAllocator* counter) : previous_(allocator()) {
    set_allocator(Allocator{&CountingAllocator::allocate, &CountingAllocator::deallocate, counter});
  }
  ~InstalledAllocator() { set_allocator(previous_); }
  InstalledAllocator(const InstalledAllocator&) = delete;
  InstalledAllocator& operator=(const InstalledAllocator&) = delete;

 private:
  Allocator previous_;
};

TEST(RuntimeView, AllocatorSeesOpenFromBytesPoseAndSamplingAllocations) {
  const auto bytes = make_valid_file();
  const auto path = test::make_temp_dir("view") / "alloc.ossa";
  ASSERT_TRUE(test::write_file(path, std::span<const uint8_t>(bytes)));
  const test::AlignedBytes aligned(bytes);

  CountingAllocator counter;
  {
    const InstalledAllocator installed(&counter);
    {
      auto read = Asset::open(path.string(), OpenMode::kRead);  // small file: one heap copy
      ASSERT_TRUE(read.ok()) << read.error().message;
      EXPECT_EQ(counter.allocations, 1u);
      EXPECT_EQ(counter.live_bytes, bytes.size());

      auto copied = Asset::from_bytes(bytes, "copy.ossa");
      ASSERT_TRUE(copied.ok()) << copied.error().message;
      EXPECT_EQ(counter.allocations, 2u);
      EXPECT_EQ(counter.live_bytes, 2 * bytes.size());

      const size_t before_borrow = counter.allocations;
      auto borrowed = Asset::borrow(aligned.span(), "borrowed.ossa");
      ASSERT_TRUE(borrowed.ok());
      auto mapped = Asset::open(path.string(), OpenMode::kMap);
      ASSERT_TRUE(mapped.ok()) << mapped.error().message;
      EXPECT_EQ(counter.allocations, before_borrow);  // neither borrow nor a mapping allocates bytes

      const SkeletonView skeleton = read->skeleton();
      Pose pose(static_cast<uint32_t>(skeleton.joint_count()));
      EXPECT_EQ(counter.allocations, before_borrow + 1);
      const size_t before_cache = counter.allocations;
      auto cache = make_sampling_cache(read->clip(0), skeleton);
      ASSERT_TRUE(cache.ok()) << cache.error().message;
      EXPECT_GT(counter.allocations, before_cache);
      sample(read->clip(0), 0.5f, SampleOptions{}, *cache, pose.span());
      EXPECT_EQ(counter.max_alignment, 32u);  // Pose and the cache's key blocks

      // A refused file frees what it allocated.
      std::vector<uint8_t> damaged = bytes;
      damaged[damaged.size() / 2] ^= 0xff;
      damaged.resize(damaged.size() - 8);
      EXPECT_FALSE(Asset::from_bytes(damaged, "bad.ossa").ok());
    }
    EXPECT_EQ(counter.frees, counter.allocations);
    EXPECT_EQ(counter.live_bytes, 0u);
    EXPECT_FALSE(counter.size_mismatch);
  }
  // Restored: the default allocator serves again and the counter sees nothing.
  const size_t total = counter.allocations;
  EXPECT_TRUE(Asset::from_bytes(bytes).ok());
  EXPECT_EQ(counter.allocations, total);
}

TEST(RuntimeView, NullAllocatorRestoresTheDefault) {
  const Allocator before = allocator();
  set_allocator(Allocator{});
  EXPECT_NE(allocator().allocate, nullptr);
  EXPECT_NE(allocator().deallocate, nullptr);
  EXPECT_EQ(allocator().allocate, before.allocate);
  Pose pose(5);
  EXPECT_EQ(reinterpret_cast<uintptr_t>(pose.span().base) % 32, 0u);
}

}  // namespace
}  // namespace ossa
