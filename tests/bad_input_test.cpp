// bad_input_test.cpp — the loader never trusts a file (ARCHITECTURE.md, "Never trusted").
//
// Every case hands Asset::from_bytes / Asset::open / verify_buffer something wrong — cut short,
// bit-flipped, not an .ossa file at all, or well-formed FlatBuffers that break one semantic
// invariant of ossa/loader/validate.h — and asserts two things: it is rejected, and the message names
// the file and what is wrong (checked by distinctive words, case-insensitively, so wording can
// improve without breaking tests). Where damaged bytes are accepted (a flip inside vertex data is
// harmless), asset_walk.h reads every byte the views expose and re-checks the invariants, so
// "accepted" is held to "safe to use". CI runs this suite under ASan + UBSan (OSSA_SANITIZE):
// "never a crash, never undefined behaviour" is checked by the sanitizers, not by hope.
//
// Semantic cases start from the valid synthetic file (test_files.h) and change one field, so each
// test breaks exactly one invariant.
#include <gtest/gtest.h>

#if !defined(_WIN32)
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#endif

#include <algorithm>
#include <cctype>
#include <chrono>
#include <condition_variable>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <limits>
#include <mutex>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <flatbuffers/flatbuffers.h>

#include "asset_walk.h"
#include <ossa/format/hash.h>
#include <ossa/version.h>
#include <ossa/anim/vector_isa.h>
#include <ossa/loader/asset.h>
#include <ossa/loader/texture.h>
#include "test_files.h"

namespace ossa::test {
namespace {

using Keywords = std::vector<std::vector<std::string>>;  // every group must match; any word of a group

std::string lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

bool contains_any(const std::string& message, const std::vector<std::string>& words) {
  const std::string m = lower(message);
  return std::any_of(words.begin(), words.end(), [&](const std::string& w) { return m.find(lower(w)) != std::string::npos; });
}

std::string join(const std::vector<std::string>& words) {
  std::string out;
  for (const std::string& w : words) out += (out.empty() ? "\"" : " | \"") + w + "\"";
  return out;
}

// A message that names the file and says what is wrong.
::testing::AssertionResult explains(const std::string& message, const std::string& name, const Keywords& groups) {
  if (message.empty()) return ::testing::AssertionFailure() << "empty error message";
  if (message.find(name) == std::string::npos)
    return ::testing::AssertionFailure() << "message does not name \"" << name << "\": " << message;
  for (const auto& group : groups)
    if (!contains_any(message, group))
      return ::testing::AssertionFailure() << "message mentions none of " << join(group) << ": " << message;
  return ::testing::AssertionSuccess() << message;
}

::testing::AssertionResult rejected(const Result<Asset>& result, const std::string& name, const Keywords& groups) {
  if (result.ok()) return ::testing::AssertionFailure() << name << " was accepted";
  return explains(result.error().message, name, groups);
}

std::string current_test_file_name() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  return std::string(info->test_suite_name()) + "." + info->name() + ".ossa";
}

// Both entry points over the same bytes must reject them and explain why.
::testing::AssertionResult rejects(const std::vector<uint8_t>& bytes, const Keywords& groups) {
  const std::string name = current_test_file_name();
  auto loaded = rejected(Asset::from_bytes(bytes, name), name, groups);
  if (!loaded) return ::testing::AssertionFailure() << "Asset::from_bytes: " << loaded.message();
  const AlignedBytes aligned(bytes);
  const Status status = verify_buffer(aligned.span(), name);
  if (status.ok()) return ::testing::AssertionFailure() << "verify_buffer accepted what from_bytes rejected";
  auto verified = explains(status.message(), name, groups);
  if (!verified) return ::testing::AssertionFailure() << "verify_buffer: " << verified.message();
  return ::testing::AssertionSuccess() << loaded.message();
}

::testing::AssertionResult rejects(const SyntheticSpec& spec, const Keywords& groups) {
  return rejects(make_valid_file(spec), groups);
}

::testing::AssertionResult accepts(const std::vector<uint8_t>& bytes) {
  const std::string name = current_test_file_name();
  const Result<Asset> asset = Asset::from_bytes(bytes, name);
  if (!asset) return ::testing::AssertionFailure() << "rejected: " << asset.error().message;
  const std::string problem = walk_asset(*asset);
  if (!problem.empty()) return ::testing::AssertionFailure() << "accepted, but " << problem;
  const AlignedBytes aligned(bytes);
  const Status status = verify_buffer(aligned.span(), name);
  if (!status) return ::testing::AssertionFailure() << "verify_buffer rejected: " << status.message();
  return ::testing::AssertionSuccess();
}

const Keywords kMesh = {{"body", "mesh 0", "mesh[0]", "meshes[0]"}};
const Keywords kClip = {{"walk", "clip 0", "clip[0]", "clips[0]"}};

Keywords with(Keywords base, std::vector<std::string> words) {
  base.push_back(std::move(words));
  return base;
}
Keywords with(Keywords base, std::vector<std::string> words, std::vector<std::string> more) {
  base.push_back(std::move(words));
  base.push_back(std::move(more));
  return base;
}

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

// ---------------------------------------------------------------------------------------------
// The valid file, and variants that must stay valid (the checks must not over-reject).

TEST(ValidFile, AcceptedFromBytes) {
  const std::vector<uint8_t> bytes = make_valid_file();
  ASSERT_TRUE(accepts(bytes));
  const Result<Asset> asset = Asset::from_bytes(bytes, "valid.ossa");
  ASSERT_TRUE(asset.ok());
  const SyntheticSpec spec;
  EXPECT_EQ(asset->name(), "valid.ossa");
  EXPECT_EQ(asset->bytes().size(), bytes.size());
  EXPECT_TRUE(std::equal(bytes.begin(), bytes.end(), asset->bytes().begin()));
  EXPECT_EQ(asset->file().version(), kFormatVersion);
  EXPECT_EQ(asset->skeleton().joint_count(), spec.skeleton->names.size());
  EXPECT_EQ(asset->skeleton().joint_name(3), "arm");
  EXPECT_EQ(asset->skeleton().find_joint("head"), 2);
  EXPECT_EQ(asset->skeleton().find_joint("tail"), -1);
  ASSERT_EQ(asset->mesh_count(), 1u);
  EXPECT_EQ(asset->mesh(0).vertex_count(), spec.meshes[0].vertices.size());
  EXPECT_EQ(asset->mesh(0).vertex_bytes().size(), spec.meshes[0].vertices.size() * 24);
  EXPECT_EQ(asset->mesh(0).index_count(), spec.meshes[0].indices.size());
  EXPECT_EQ(asset->mesh(0).submeshes().size(), 2u);
  ASSERT_EQ(asset->clip_count(), 1u);
  EXPECT_EQ(asset->clip(0).name(), "walk");
  EXPECT_EQ(asset->clip(0).constants().size(), 2u);
  EXPECT_EQ(asset->clip(0).animated().size(), 3u);
  EXPECT_EQ(asset->clip(0).key_count(), 2u + 3u + 2u + 4u);
  EXPECT_TRUE(check_clip_binding(asset->clip(0), asset->skeleton(), "valid.ossa").ok());
  ASSERT_EQ(asset->material_count(), 1u);
  ASSERT_NE(asset->material(0).textures(), nullptr);
  EXPECT_EQ(asset->material(0).textures()->size(), 3u);
}

TEST(ValidFile, AcceptedFromDisk) {
  const std::vector<uint8_t> bytes = make_valid_file();
  const std::filesystem::path path = make_temp_dir("bad_input") / "valid.ossa";
  ASSERT_TRUE(write_file(path, bytes));
  const Result<Asset> asset = Asset::open(path.string());
  ASSERT_TRUE(asset.ok()) << asset.error().message;
  EXPECT_EQ(asset->bytes().size(), bytes.size());
  EXPECT_TRUE(std::equal(bytes.begin(), bytes.end(), asset->bytes().begin()));
  EXPECT_EQ(walk_asset(*asset), "");
  // Moving keeps the views valid; the moved-from asset is not used again.
  Result<Asset> moved_from = Asset::open(path.string());
  ASSERT_TRUE(moved_from.ok());
  const Asset moved = std::move(*moved_from);
  EXPECT_EQ(walk_asset(moved), "");
}

TEST(ValidFile, VariantsAccepted) {
  for (const auto& [name, spec] : valid_variants()) EXPECT_TRUE(accepts(make_valid_file(spec))) << name;
}

// ---------------------------------------------------------------------------------------------
// Damaged bytes

// Trailing zero bytes can be FlatBuffers alignment padding that nothing references; cutting
// them off may leave a complete file. Any shorter prefix lacks referenced bytes.
size_t referenced_size(const std::vector<uint8_t>& bytes) {
  size_t n = bytes.size();
  while (n > 0 && bytes[n - 1] == 0) --n;
  return n;
}

/// The file every damage test starts from: the default, and the variant with an animation graph
/// and clip events (whose accepted damaged forms are also played through the graph evaluator).
std::vector<uint8_t> damage_base(bool graph) {
  if (!graph) return make_valid_file();
  for (const auto& [name, spec] : valid_variants())
    if (name == "graph") return make_valid_file(spec);
  return {};
}

class DamagedBytes : public ::testing::TestWithParam<bool> {};
INSTANTIATE_TEST_SUITE_P(File, DamagedBytes, ::testing::Values(false, true),
                         [](const ::testing::TestParamInfo<bool>& p) { return p.param ? "WithGraph" : "Default"; });

TEST_P(DamagedBytes, EveryTruncationRejected) {
  const std::vector<uint8_t> bytes = damage_base(GetParam());
  ASSERT_FALSE(bytes.empty());
  const size_t complete = referenced_size(bytes);
  std::vector<size_t> lengths;
  for (size_t n = 0; n <= std::min<size_t>(bytes.size(), 512); ++n) lengths.push_back(n);
  for (size_t n = 513; n < bytes.size(); n += 37) lengths.push_back(n);
  lengths.push_back(bytes.size() - 1);
  std::vector<std::string> failures;
  for (size_t n : lengths) {
    const std::vector<uint8_t> prefix(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(n));
    const std::string name = "truncated-" + std::to_string(n) + ".ossa";
    const Result<Asset> asset = Asset::from_bytes(prefix, name);
    if (asset.ok()) {
      if (n < complete) failures.push_back(name + ": accepted although referenced bytes are missing");
      else if (const std::string problem = walk_asset(*asset); !problem.empty()) failures.push_back(name + ": " + problem);
    } else if (auto e = explains(asset.error().message, name, {}); !e) {
      failures.push_back(e.message());
    }
  }
  EXPECT_TRUE(failures.empty()) << failures.size() << " failures, first: " << failures.front();
}

TEST(DamagedFile, TruncatedFileOnDiskRejected) {
  const std::vector<uint8_t> bytes = make_valid_file();
  const std::filesystem::path dir = make_temp_dir("bad_input");
  for (size_t n : {size_t{1}, size_t{7}, size_t{8}, size_t{64}, bytes.size() / 2, referenced_size(bytes) - 1}) {
    const std::filesystem::path path = dir / ("cut-" + std::to_string(n) + ".ossa");
    ASSERT_TRUE(write_file(path, std::span<const uint8_t>(bytes.data(), n)));
    EXPECT_TRUE(rejected(Asset::open(path.string()), path.string(), {})) << "length " << n;
  }
}

// Every byte, several masks: accepted (then safe to walk) or rejected with a message; never UB.
TEST_P(DamagedBytes, EveryByteFlipped) {
  const std::vector<uint8_t> bytes = damage_base(GetParam());
  ASSERT_FALSE(bytes.empty());
  std::vector<std::string> failures;
  size_t accepted = 0, refused = 0;
  for (size_t offset = 0; offset < bytes.size(); ++offset) {
    for (uint8_t mask : {uint8_t{0x01}, uint8_t{0x02}, uint8_t{0x10}, uint8_t{0x80}, uint8_t{0xFF}}) {
      std::vector<uint8_t> damaged = bytes;
      damaged[offset] ^= mask;
      const std::string name = "flip-" + std::to_string(offset) + "-" + std::to_string(mask) + ".ossa";
      const Result<Asset> asset = Asset::from_bytes(damaged, name);
      const AlignedBytes aligned(damaged);
      const Status status = verify_buffer(aligned.span(), name);
      if (status.ok() != asset.ok()) failures.push_back(name + ": verify_buffer and from_bytes disagree");
      if (asset.ok()) {
        ++accepted;
        if (const std::string problem = walk_asset(*asset); !problem.empty())
          failures.push_back(name + ": accepted, but " + problem);
      } else {
        ++refused;
        if (auto e = explains(asset.error().message, name, {}); !e) failures.push_back(e.message());
      }
    }
  }
  EXPECT_GT(refused, 0u);
  EXPECT_TRUE(failures.empty()) << failures.size() << " failures, first: " << failures.front();
  std::printf("flips: %zu accepted, %zu rejected\n", accepted, refused);
}

TEST(DamagedFile, RandomBytesRejected) {
  std::mt19937 rng(20240601);  // fixed seed: reproducible
  for (int round = 0; round < 200; ++round) {
    std::vector<uint8_t> bytes(8 + rng() % 4096);
    for (uint8_t& b : bytes) b = static_cast<uint8_t>(rng());
    if (round % 2 == 0) std::copy_n("OSSA", 4, bytes.begin() + 4);  // past the identifier check
    EXPECT_TRUE(rejected(Asset::from_bytes(bytes, "random.ossa"), "random.ossa", {})) << "round " << round;
  }
}

// FlatBuffers tables form a DAG: one big index vector reached through thousands of mesh entries
// must not cost thousands of scans (validate.h: the checks bound their work by the buffer size).
TEST(DamagedFile, SharedTablesDoNotMultiplyWork) {
  flatbuffers::FlatBufferBuilder fbb;
  const std::vector<fb::VertexAttribute> layout = {{fb::VertexSemantic::Position, fb::VertexFormat::Float32x3, 0}};
  const std::vector<uint8_t> vertices(3 * 12, 0);
  const std::vector<uint8_t> indices(60000 * 2, 0);  // 20000 degenerate triangles over vertex 0
  const std::vector<fb::Submesh> submeshes = {{0, 60000, 0}};
  const auto mesh = fb::CreateMeshDirect(fbb, "shared", 3, 12, &layout, &vertices, fb::IndexFormat::Uint16,
                                         &indices, &submeshes);
  const std::vector<flatbuffers::Offset<fb::Mesh>> meshes(2000, mesh);
  fb::FinishFileBuffer(fbb, fb::CreateFileDirect(fbb, kFormatVersion, 1.0f, 0, &meshes));
  const std::vector<uint8_t> bytes(fbb.GetBufferPointer(), fbb.GetBufferPointer() + fbb.GetSize());
  EXPECT_TRUE(rejects(bytes, {{"shared", "refusing", "far more"}}));
  // The same mesh referenced once is fine.
  flatbuffers::FlatBufferBuilder once;
  const auto single = fb::CreateMeshDirect(once, "shared", 3, 12, &layout, &vertices, fb::IndexFormat::Uint16,
                                           &indices, &submeshes);
  const std::vector<flatbuffers::Offset<fb::Mesh>> one = {single};
  fb::FinishFileBuffer(once, fb::CreateFileDirect(once, kFormatVersion, 1.0f, 0, &one));
  EXPECT_TRUE(accepts({once.GetBufferPointer(), once.GetBufferPointer() + once.GetSize()}));
}

// ---------------------------------------------------------------------------------------------
// Not an .ossa file at all

TEST(NotOssa, WrongIdentifier) {
  SyntheticSpec spec;
  spec.identifier = "OSSB";
  EXPECT_TRUE(rejects(spec, {{"identifier", "not an ossa", "not a .ossa"}}));
}

TEST(NotOssa, WrongVersion) {
  SyntheticSpec spec;
  spec.version = kFormatVersion + 1;
  EXPECT_TRUE(rejects(spec, {{"version"}, {std::to_string(kFormatVersion + 1)}}));
  spec.version = 0;
  EXPECT_TRUE(rejects(spec, {{"version"}}));
}

TEST(NotOssa, EmptyBytes) {
  EXPECT_TRUE(rejected(Asset::from_bytes({}, "empty.ossa"), "empty.ossa",
                       {{"empty", "small", "short", "truncated", "too few", "0 bytes", "size"}}));
  const Status status = verify_buffer({}, "empty.ossa");
  EXPECT_FALSE(status.ok());
  EXPECT_NE(status.message().find("empty.ossa"), std::string::npos) << status.message();
}

TEST(NotOssa, EmptyFileOnDisk) {
  const std::filesystem::path path = make_temp_dir("bad_input") / "empty.ossa";
  ASSERT_TRUE(write_file(path, std::string_view()));
  EXPECT_TRUE(rejected(Asset::open(path.string()), path.string(),
                       {{"empty", "small", "short", "truncated", "too few", "0 bytes", "size"}}));
}

TEST(NotOssa, Directory) {
  const std::filesystem::path path = make_temp_dir("bad_input");
  EXPECT_TRUE(rejected(Asset::open(path.string()), path.string(), {{"directory", "not a regular", "not a file"}}));
}

TEST(NotOssa, DeviceFile) {
#if defined(_WIN32)
  const std::string device = "NUL";  // Windows' null device: GetFileType says FILE_TYPE_CHAR
#else
  const std::string device = "/dev/null";
#endif
  EXPECT_TRUE(rejected(Asset::open(device), device, {{"not a regular", "not a file"}}));
}

// open(2) on a FIFO waits for a writer; a loader that opens before it checks the file type hangs
// on `ossa-view some.fifo`. A helper thread stands by to play the writer so that such a loader
// fails this test instead of hanging the suite; the generous wait is a liveness bound, not a
// performance expectation.
TEST(NotOssa, NamedPipeDoesNotBlock) {
#if defined(_WIN32)
  GTEST_SKIP() << "FIFOs (mkfifo) are POSIX; Windows named pipes live in \\\\.\\pipe\\, not in the file "
                  "system, and GetFileType refuses them like the NUL device (NotOssa.DeviceFile)";
#else
  const std::filesystem::path path = make_temp_dir("bad_input") / "pipe.ossa";
  ASSERT_EQ(mkfifo(path.c_str(), 0600), 0);
  std::mutex mutex;
  std::condition_variable done_cv;
  bool done = false, had_to_release = false;
  std::thread writer([&] {
    std::unique_lock lock(mutex);
    if (done_cv.wait_for(lock, std::chrono::seconds(10), [&] { return done; })) return;
    had_to_release = true;
    const int fd = ::open(path.c_str(), O_WRONLY | O_NONBLOCK);  // unblocks a reader stuck in open
    if (fd >= 0) ::close(fd);
  });
  const Result<Asset> asset = Asset::open(path.string());
  {
    std::lock_guard lock(mutex);
    done = true;
  }
  done_cv.notify_one();
  writer.join();
  EXPECT_FALSE(had_to_release) << "Asset::open blocked on a FIFO until a writer appeared (open with O_NONBLOCK, "
                                  "or check the file type before opening)";
  EXPECT_TRUE(rejected(asset, path.string(), {{"not a regular", "not a file"}}));
#endif
}

TEST(NotOssa, MissingPath) {
  const std::filesystem::path path = make_temp_dir("bad_input") / "no-such-file.ossa";
  EXPECT_TRUE(rejected(Asset::open(path.string()), path.string(),
                       {{"no such", "not found", "does not exist", "cannot open", "can't open"}}));
}

TEST(NotOssa, GlbFile) {
  const std::filesystem::path path = source_dir() / "assets" / "CesiumMan" / "CesiumMan.glb";
  ASSERT_TRUE(std::filesystem::exists(path)) << path;
  EXPECT_TRUE(rejected(Asset::open(path.string()), path.string(), {{"identifier", "not an ossa", "not a .ossa"}}));
}

// ---------------------------------------------------------------------------------------------
// Skeleton invariants

TEST(Skeleton, ParentNotBeforeChild) {
  for (int16_t parent : {int16_t{2}, int16_t{3}}) {  // itself, a later joint
    SyntheticSpec spec;
    spec.skeleton->parents[2] = parent;
    EXPECT_TRUE(rejects(spec, {{"parent"}})) << "parent " << parent;
  }
}

TEST(Skeleton, ParentBelowMinusOne) {
  SyntheticSpec spec;
  spec.skeleton->parents[1] = -2;
  EXPECT_TRUE(rejects(spec, {{"parent"}}));
}

TEST(Skeleton, HashMismatch) {
  SyntheticSpec spec;
  const SyntheticSkeleton& s = *spec.skeleton;
  const std::vector<std::string_view> names(s.names.begin(), s.names.end());
  spec.skeleton->hash = skeleton_hash(names, s.parents) ^ 1;
  EXPECT_TRUE(rejects(spec, {{"hash"}}));
}

TEST(Skeleton, PerJointArrayLengthMismatch) {
  const auto mismatched = [](auto edit, const char* word) {
    SyntheticSpec spec;
    edit(*spec.skeleton);
    EXPECT_TRUE(rejects(spec, {{word}})) << word;
  };
  mismatched([](SyntheticSkeleton& s) { s.parents.pop_back(); }, "parent");
  mismatched([](SyntheticSkeleton& s) { s.translations.pop_back(); }, "translation");
  mismatched([](SyntheticSkeleton& s) { s.rotations.pop_back(); }, "rotation");
  mismatched([](SyntheticSkeleton& s) { s.scales.push_back(fb::Vec3(1, 1, 1)); }, "scale");
  mismatched(
      [](SyntheticSkeleton& s) {
        s.inverse_bind = std::vector<fb::Mat4>(3);
      },
      "inverse");
}

/// The synthetic rig grown to 11 joints (a chain off the head), so the loader's whole-array scans
/// of the bind pose (8-float blocks and a scalar tail) see bad values in blocks and tails alike.
SyntheticSpec eleven_joints() {
  SyntheticSpec spec;
  SyntheticSkeleton& s = *spec.skeleton;
  for (int i = 4; i < 11; ++i) {
    s.names.push_back("extra" + std::to_string(i));
    s.parents.push_back(static_cast<int16_t>(i == 4 ? 2 : i - 1));
    s.translations.push_back(fb::Vec3(0, 0.1f, 0));
    s.rotations.push_back(fb::Quat(0, 0, 0, 1));
    s.scales.push_back(fb::Vec3(1, 1, 1));
  }
  return spec;
}

fb::Mat4 identity_mat4() {
  const float m[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  return fb::Mat4(flatbuffers::make_span(m));
}
fb::Mat4 identity_with(int k, float v) {
  float m[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  m[k] = v;
  return fb::Mat4(flatbuffers::make_span(std::as_const(m)));
}

TEST(Skeleton, BadBindValueFoundAtEveryJointAndComponent) {
  // A valid file passes the array scans; a bad value at any joint and component, of each kind,
  // fails them and the per-joint walk then names that joint (both paths must agree on every value).
  ASSERT_TRUE(accepts(make_valid_file(eleven_joints())));
  const auto joint_words = [](size_t j, const char* what) {
    return Keywords{{"skeleton"}, {"joint " + std::to_string(j) + " "}, {what}};
  };
  for (size_t j = 0; j < 11; ++j) {
    for (int c = 0; c < 3; ++c)
      for (float bad : {kNaN, kInf, -kInf, 2e7f, -2e7f}) {
        float v[3] = {0, 0.1f, 0};
        v[c] = bad;
        SyntheticSpec t = eleven_joints();
        t.skeleton->translations[j] = fb::Vec3(v[0], v[1], v[2]);
        EXPECT_TRUE(rejects(t, joint_words(j, "translation"))) << j << " " << c << " " << bad;
        float w[3] = {1, 1, 1};
        w[c] = bad;
        SyntheticSpec sc = eleven_joints();
        sc.skeleton->scales[j] = fb::Vec3(w[0], w[1], w[2]);
        EXPECT_TRUE(rejects(sc, joint_words(j, "scale"))) << j << " " << c << " " << bad;
      }
    // Not normalizable: a non-finite component, a zero norm, a squared norm that underflows or
    // overflows float.
    for (int c = 0; c < 4; ++c)
      for (float bad : {kNaN, kInf, 1e20f}) {
        float q[4] = {0, 0, 0, 1};
        q[c] = bad;
        SyntheticSpec r = eleven_joints();
        r.skeleton->rotations[j] = fb::Quat(q[0], q[1], q[2], q[3]);
        EXPECT_TRUE(rejects(r, joint_words(j, "rotation"))) << j << " " << c << " " << bad;
      }
    for (const fb::Quat& bad : {fb::Quat(0, 0, 0, 0), fb::Quat(1e-25f, 0, 0, 0)}) {
      SyntheticSpec r = eleven_joints();
      r.skeleton->rotations[j] = bad;
      EXPECT_TRUE(rejects(r, joint_words(j, "rotation"))) << j;
    }
    for (int k = 0; k < 16; ++k) {
      SyntheticSpec m = eleven_joints();
      m.skeleton->inverse_bind = std::vector<fb::Mat4>(11, identity_mat4());
      (*m.skeleton->inverse_bind)[j] = identity_with(k, k % 2 ? kNaN : -kInf);
      m.meshes[0].inverse_bind = std::vector<fb::Mat4>(m.meshes[0].joints.size(), identity_mat4());
      EXPECT_TRUE(rejects(m, joint_words(j, "inverse bind"))) << j << " " << k;
    }
  }
  // The largest finite bind values the loader admits are admitted by both paths.
  SyntheticSpec edge = eleven_joints();
  edge.skeleton->translations[10] = fb::Vec3(1e7f, -1e7f, 0);
  edge.skeleton->rotations[10] = fb::Quat(0, 0, 2e-19f, 0);  // squared norm 4e-38 >= FLT_MIN
  EXPECT_TRUE(accepts(make_valid_file(edge)));
}

TEST(Mesh, InverseBindNotFiniteFoundAtEverySlot) {
  for (size_t slot = 0; slot < 3; ++slot)
    for (int k = 0; k < 16; ++k) {
      SyntheticSpec spec;
      spec.meshes[0].inverse_bind = std::vector<fb::Mat4>(3, identity_mat4());
      (*spec.meshes[0].inverse_bind)[slot] = identity_with(k, k % 2 ? kInf : kNaN);
      EXPECT_TRUE(rejects(spec, with(kMesh, {"joint slot " + std::to_string(slot)}, {"inverse bind"}))) << slot << " " << k;
    }
}

// ---------------------------------------------------------------------------------------------
// Mesh invariants

TEST(Mesh, IndexPastVertexCount) {
  SyntheticSpec spec;
  spec.meshes[0].indices[4] = 6;  // 6 vertices: 0..5
  EXPECT_TRUE(rejects(spec, with(kMesh, {"index", "indices"})));
  spec.meshes[0].index_format = fb::IndexFormat::Uint32;
  spec.meshes[0].indices[4] = 0xFFFFFFFFu;
  EXPECT_TRUE(rejects(spec, with(kMesh, {"index", "indices"})));
}

TEST(Mesh, IndexPastVertexCountFoundAnywhereInEitherCopy) {
  // The index scan runs in whole 32-index blocks and a scalar tail, compiled for AVX2 and the
  // baseline (vector_isa.h): one bad index is found in a block's first or last lane, between
  // blocks and in the tail, in 16- and 32-bit buffers, by both copies; the same buffer without it
  // is accepted.
  std::vector<VectorIsa> isas = {VectorIsa::Baseline};
  if (best_vector_isa() == VectorIsa::Avx2) isas.push_back(VectorIsa::Avx2);
  for (const VectorIsa isa : isas) {
    ASSERT_TRUE(set_vector_isa(isa));
    for (const fb::IndexFormat format : {fb::IndexFormat::Uint16, fb::IndexFormat::Uint32}) {
      SyntheticSpec spec;
      spec.meshes[0].index_format = format;
      std::vector<uint32_t>& indices = spec.meshes[0].indices;
      const std::vector<uint32_t> triangle(indices.begin(), indices.begin() + 3);
      indices.clear();
      for (int t = 0; t < 100; ++t) indices.insert(indices.end(), triangle.begin(), triangle.end());  // 300
      EXPECT_TRUE(accepts(make_valid_file(spec)));
      for (const size_t at : {size_t(0), size_t(31), size_t(32), size_t(150), size_t(287), size_t(299)}) {
        SyntheticSpec bad = spec;
        bad.meshes[0].indices[at] = 6;  // 6 vertices: 0..5
        EXPECT_TRUE(rejects(bad, with(kMesh, {"index " + std::to_string(at) + " is 6"})))
            << "index " << at << (isa == VectorIsa::Avx2 ? " avx2" : " baseline");
      }
    }
  }
  set_vector_isa(best_vector_isa());
}

TEST(Mesh, IndexBytesNotMultipleOfIndexSize) {
  SyntheticSpec spec;
  spec.meshes[0].index_padding_bytes = 1;
  EXPECT_TRUE(rejects(spec, with(kMesh, {"index", "indices"})));
  spec.meshes[0].index_format = fb::IndexFormat::Uint32;
  spec.meshes[0].index_padding_bytes = 2;
  EXPECT_TRUE(rejects(spec, with(kMesh, {"index", "indices"})));
}

TEST(Mesh, IndexCountNotMultipleOf3) {
  SyntheticSpec spec;
  spec.meshes[0].indices.push_back(0);  // 13 indices; the submeshes still cover 0..11
  EXPECT_TRUE(rejects(spec, with(kMesh, {"index", "indices", "triangle"})));
}

TEST(Mesh, SubmeshPastIndexRange) {
  SyntheticSpec spec;
  spec.meshes[0].submeshes[1] = fb::Submesh(6, 9, 0);  // 15 > 12
  EXPECT_TRUE(rejects(spec, with(kMesh, {"submesh"})));
  spec.meshes[0].submeshes[1] = fb::Submesh(0xFFFFFFF0u, 0x20u, 0);  // wraps in 32 bits
  EXPECT_TRUE(rejects(spec, with(kMesh, {"submesh"})));
}

TEST(Mesh, SubmeshMaterialOutOfRange) {
  SyntheticSpec spec;
  spec.meshes[0].submeshes[1] = fb::Submesh(6, 6, 1);  // one material
  EXPECT_TRUE(rejects(spec, with(kMesh, {"material"})));
  // Without materials, material 0 means "the default material"; anything else is out of range.
  spec.materials.clear();
  EXPECT_TRUE(rejects(spec, with(kMesh, {"material"})));
}

TEST(Mesh, AttributePastStride) {
  SyntheticSpec spec;
  spec.meshes[0].layout[4] = fb::VertexAttribute(fb::VertexSemantic::Weights, fb::VertexFormat::Unorm8x4, 22);
  EXPECT_TRUE(rejects(spec, with(kMesh, {"stride", "offset"})));
  spec.meshes[0].layout[4] = fb::VertexAttribute(fb::VertexSemantic::Weights, fb::VertexFormat::Unorm8x4, 0xFFFF);
  EXPECT_TRUE(rejects(spec, with(kMesh, {"stride", "offset"})));
}

TEST(Mesh, UnknownVertexFormat) {
  SyntheticSpec spec;
  spec.meshes[0].layout[2] = fb::VertexAttribute(fb::VertexSemantic::TexCoord0, static_cast<fb::VertexFormat>(42), 12);
  EXPECT_TRUE(rejects(spec, with(kMesh, {"format"})));
}

TEST(Mesh, DuplicateSemantic) {
  SyntheticSpec spec;
  spec.meshes[0].layout[2] = fb::VertexAttribute(fb::VertexSemantic::Normal, fb::VertexFormat::Snorm16x2, 12);
  EXPECT_TRUE(rejects(spec, with(kMesh, {"two Normal", "duplicate", "twice", "more than once", "repeated"})));
}

TEST(Mesh, UnknownSemantic) {
  SyntheticSpec spec;
  spec.meshes[0].layout[2] = fb::VertexAttribute(static_cast<fb::VertexSemantic>(42), fb::VertexFormat::Float16x2, 12);
  EXPECT_TRUE(rejects(spec, with(kMesh, {"semantic"})));
}

TEST(Mesh, VertexBytesNotCountTimesStride) {
  for (uint32_t count : {5u, 7u}) {
    SyntheticSpec spec;
    spec.meshes[0].vertex_count = count;
    EXPECT_TRUE(rejects(spec, with(kMesh, {"vertex", "vertices"}))) << "vertex_count " << count;
  }
}

// count * stride wraps to the real byte size in 32-bit arithmetic; a loader that multiplies in
// 32 bits accepts a mesh that claims 2^27 more vertices than it holds.
TEST(Mesh, VertexCountOverflow) {
  SyntheticSpec spec;
  spec.meshes[0].vertex_stride = 32;
  spec.meshes[0].vertex_count = 6u + (1u << 27);
  EXPECT_TRUE(rejects(spec, with(kMesh, {"vertex", "vertices"})));
}

TEST(Mesh, JointSlotPastSlotCount) {
  SyntheticSpec spec;
  spec.meshes[0].vertices[5].slots[1] = 3;  // slots 0..2; weight 55 on that slot
  EXPECT_TRUE(rejects(spec, with(kMesh, {"slot"})));
}

TEST(Mesh, JointSlotPastSlotCountFoundAtEveryVertexStrideAndCopy) {
  // The 8-bit slot scan reads whole 64-byte chunks through a mask that repeats every
  // lcm(stride, 64) bytes, then the vertices of the last partial chunk one by one (a stride past
  // 256 bytes: one by one throughout); compiled for AVX2 and the baseline. Every valid mesh is
  // accepted (positions, normals and weights around the slots hold bytes up to 255, so a mask
  // that let them through would reject it) and slot 3 (of 0..2) is found in the first, a middle
  // and the last vertex, in each of the four components.
  std::vector<VectorIsa> isas = {VectorIsa::Baseline};
  if (best_vector_isa() == VectorIsa::Avx2) isas.push_back(VectorIsa::Avx2);
  const std::vector<SyntheticVertex> grid = SyntheticMesh::default_vertices();
  for (const VectorIsa isa : isas) {
    ASSERT_TRUE(set_vector_isa(isa));
    for (const uint16_t stride : {24, 28, 32, 40, 60, 64, 100, 260}) {
      for (const size_t count : {1, 2, 3, 5, 8, 11, 16, 33, 70}) {
        SyntheticSpec spec;
        SyntheticMesh& mesh = spec.meshes[0];
        mesh.vertex_stride = stride;
        mesh.vertices.clear();
        for (size_t v = 0; v < count; ++v) {
          SyntheticVertex x = grid[v % grid.size()];
          x.position = fb::Vec3(x.position.x() + 0.01f * static_cast<float>(v), x.position.y(), x.position.z());
          mesh.vertices.push_back(x);
        }
        const auto last = static_cast<uint32_t>(count - 1);
        mesh.indices = {0, std::min(1u, last), std::min(2u, last)};
        mesh.submeshes = {{0, 3, 0}};
        mesh.morph_targets.clear();
        ASSERT_TRUE(accepts(make_valid_file(spec))) << "stride " << stride << " count " << count;
        for (const size_t v : {size_t{0}, count / 2, count - 1})
          for (size_t k = 0; k < 4; ++k) {
            SyntheticSpec bad = spec;
            bad.meshes[0].vertices[v].slots[k] = 3;
            EXPECT_TRUE(rejects(bad, with(kMesh, {"vertex " + std::to_string(v) + " uses joint slot 3"})))
                << "stride " << stride << " count " << count << " vertex " << v << " slot " << k;
          }
      }
    }
  }
  ASSERT_TRUE(set_vector_isa(best_vector_isa()));
}

TEST(Mesh, MeshJointPastSkeletonJointCount) {
  SyntheticSpec spec;
  spec.meshes[0].joints[2] = 4;  // 4 joints: 0..3
  EXPECT_TRUE(rejects(spec, with(kMesh, {"joint"})));
  // Skinned mesh in a file without a skeleton: every slot is out of range.
  spec.meshes[0].joints[2] = 3;
  spec.skeleton.reset();
  spec.clips.clear();
  EXPECT_TRUE(rejects(spec, with(kMesh, {"joint", "skeleton"})));
}

TEST(Mesh, JointsInverseBindLengthMismatch) {
  SyntheticSpec spec;
  spec.meshes[0].inverse_bind = std::vector<fb::Mat4>(2);  // 3 slots
  EXPECT_TRUE(rejects(spec, with(kMesh, {"inverse"})));
}

// ---------------------------------------------------------------------------------------------
// Morph targets and weight tracks (format v5): the "morph" variant of test_files.h is valid; each
// case breaks one thing apply_morphs or sample_morph_weights would otherwise index with.

SyntheticSpec morph_spec() {
  for (auto& [name, spec] : valid_variants())
    if (name == "morph") return spec;
  ADD_FAILURE() << "no morph variant";
  return {};
}

TEST(Morph, TheMorphVariantIsAccepted) {
  const std::vector<uint8_t> bytes = make_valid_file(morph_spec());
  const auto asset = Asset::from_bytes(bytes, "morph.ossa");
  ASSERT_TRUE(asset.ok()) << asset.error().message;
  EXPECT_EQ(asset->mesh(0).morph_target_count(), 2u);
  EXPECT_EQ(asset->clip(0).morph_track_count(), 2u);
}

TEST(Morph, TargetVertexPastVertexCount) {
  SyntheticSpec spec = morph_spec();
  spec.meshes[0].morph_targets[0].vertices = {4, 6};  // 6 vertices: 0..5
  EXPECT_TRUE(rejects(spec, with(kMesh, {"morph target 0 'smile'"}, {"vertex 6", "past the vertex count"})));
}

TEST(Morph, TargetVerticesNotIncreasing) {
  SyntheticSpec spec = morph_spec();
  spec.meshes[0].morph_targets[1].vertices = {2, 4, 3};
  EXPECT_TRUE(rejects(spec, with(kMesh, {"frown"}, {"strictly increase"})));
  spec.meshes[0].morph_targets[1].vertices = {2, 2, 3};
  EXPECT_TRUE(rejects(spec, with(kMesh, {"frown"}, {"strictly increase"})));
}

TEST(Morph, DeltaCountNotThreePerVertex) {
  SyntheticSpec spec = morph_spec();
  spec.meshes[0].morph_targets[0].position_deltas.pop_back();
  EXPECT_TRUE(rejects(spec, with(kMesh, {"position deltas"}, {"3 per vertex"})));
  spec = morph_spec();
  spec.meshes[0].morph_targets[1].normal_deltas.resize(12, 0);
  EXPECT_TRUE(rejects(spec, with(kMesh, {"normal deltas"}, {"3 per vertex"})));
}

TEST(Morph, StepOrWeightNotFinite) {
  for (float bad : {kNaN, kInf, -1.0f, 1e9f}) {
    SyntheticSpec spec = morph_spec();
    spec.meshes[0].morph_targets[0].position_step = fb::Vec3(0.001f, bad, 0.001f);
    EXPECT_TRUE(rejects(spec, with(kMesh, {"position step"})));
  }
  for (float bad : {kNaN, kInf, 1e6f}) {
    SyntheticSpec spec = morph_spec();
    spec.meshes[0].morph_targets[0].default_weight = bad;
    EXPECT_TRUE(rejects(spec, with(kMesh, {"default weight"})));
  }
}

TEST(Morph, TargetNamesEmptyOrRepeated) {
  SyntheticSpec spec = morph_spec();
  spec.meshes[0].morph_targets[1].name = "";
  EXPECT_TRUE(rejects(spec, with(kMesh, {"empty name"})));
  spec.meshes[0].morph_targets[1].name = "smile";
  EXPECT_TRUE(rejects(spec, with(kMesh, {"two morph targets named 'smile'"})));
}

TEST(Morph, WeightTrackValuesNotOnePerKey) {
  SyntheticSpec spec = morph_spec();
  spec.clips[0].morph_weights[1].values = {0};  // 2 key frames
  EXPECT_TRUE(rejects(spec, with(kClip, {"morph weight track 1 'smile'"}, {"2 key frames but 1 values"})));
  spec = morph_spec();
  spec.clips[0].morph_weights[0].values.clear();
  spec.clips[0].morph_weights[0].key_frames.clear();
  EXPECT_TRUE(rejects(spec, with(kClip, {"frown"}, {"no keys"})));
}

TEST(Morph, WeightTrackKeysOffTheClip) {
  SyntheticSpec spec = morph_spec();
  spec.clips[0].morph_weights[1].key_frames = {0, 31};  // 31 frames: 0..30
  EXPECT_TRUE(rejects(spec, with(kClip, {"smile"}, {"last key"})));
  spec.clips[0].morph_weights[1].key_frames = {1, 30};
  EXPECT_TRUE(rejects(spec, with(kClip, {"smile"}, {"first key"})));
  spec.clips[0].morph_weights[1].key_frames = {15, 15};
  EXPECT_TRUE(rejects(spec, with(kClip, {"smile"}, {"first key", "strictly increase"})));
}

TEST(Morph, WeightTracksNotSortedOrRangeUnbounded) {
  SyntheticSpec spec = morph_spec();
  std::swap(spec.clips[0].morph_weights[0], spec.clips[0].morph_weights[1]);
  EXPECT_TRUE(rejects(spec, with(kClip, {"sorted by name"})));
  for (float bad : {kNaN, kInf, 1e5f}) {
    spec = morph_spec();
    spec.clips[0].morph_weights[1].range_min = bad;
    EXPECT_TRUE(rejects(spec, with(kClip, {"weight range"})));
  }
  spec = morph_spec();
  spec.clips[0].morph_weights[1].range_extent = -1.0f;
  EXPECT_TRUE(rejects(spec, with(kClip, {"weight range"})));
}

// ---------------------------------------------------------------------------------------------
// Clip invariants

// The default clip (test_files.h): 31 frames at 30/s; constants spine translation, head
// rotation; animated spine rotation (16 bits, frames 0 15 30), arm translation (12 bits, 0 30),
// arm scale (raw floats, 0 8 23 30), packed in that order: 144 + 72 bits, then the raw keys from
// bit 216 (byte 27) to bit 600, then 8 padding bytes.

TEST(Clip, SampleRateInvalid) {
  for (float rate : {0.0f, -30.0f, kNaN, kInf}) {
    SyntheticSpec spec;
    spec.clips[0].sample_rate = rate;
    spec.clips[0].duration = 1.0f;
    EXPECT_TRUE(rejects(spec, with(kClip, {"sample rate"}))) << rate;
  }
}

TEST(Clip, FrameCountInvalid) {
  for (uint32_t frames : {0u, 65537u, 0xFFFFFFFFu}) {
    SyntheticSpec spec;
    spec.clips[0].frame_count = frames;
    spec.clips[0].duration = 1.0f;
    EXPECT_TRUE(rejects(spec, with(kClip, {"frame count"}))) << frames;
  }
}

TEST(Clip, DurationDoesNotMatchFrames) {
  for (float d : {2.0f, 1.001f, -1.0f, kNaN, kInf}) {
    SyntheticSpec spec;
    spec.clips[0].duration = d;  // 31 frames at 30/s: 1 s
    EXPECT_TRUE(rejects(spec, with(kClip, {"duration"}))) << d;
  }
  SyntheticSpec single;
  single.clips[0].frame_count = 1;
  single.clips[0].animated.clear();
  single.clips[0].duration = 0.5f;  // one frame lasts 0 s
  EXPECT_TRUE(rejects(single, with(kClip, {"duration"})));
}

TEST(Clip, ConstantsNotSortedOrRepeated) {
  SyntheticSpec spec;
  std::swap(spec.clips[0].constants[0], spec.clips[0].constants[1]);
  EXPECT_TRUE(rejects(spec, with(kClip, {"sorted"})));
  spec.clips[0].constants = {{1, fb::Channel::Translation, fb::Quat(0, 1, 0, 0)},
                             {1, fb::Channel::Translation, fb::Quat(0, 2, 0, 0)}};
  EXPECT_TRUE(rejects(spec, with(kClip, {"sorted", "at most once"})));
}

TEST(Clip, AnimatedNotSortedOrRepeated) {
  SyntheticSpec spec;
  std::swap(spec.clips[0].animated[1], spec.clips[0].animated[2]);  // arm scale before arm translation
  EXPECT_TRUE(rejects(spec, with(kClip, {"sorted"})));
  SyntheticSpec repeated;
  repeated.clips[0].animated[2].channel = fb::Channel::Translation;
  EXPECT_TRUE(rejects(repeated, with(kClip, {"sorted", "at most once"})));
}

TEST(Clip, ChannelJointPastJointCount) {
  SyntheticSpec constant;
  constant.clips[0].constants[1].joint = 4;  // joint_count 4
  EXPECT_TRUE(rejects(constant, with(kClip, {"joint count"})));
  SyntheticSpec animated;
  animated.clips[0].animated[1].joint = 4;
  animated.clips[0].animated[2].joint = 4;
  EXPECT_TRUE(rejects(animated, with(kClip, {"joint count"})));
}

TEST(Clip, ChannelEnumUnknown) {
  SyntheticSpec constant;
  constant.clips[0].constants[1].channel = static_cast<fb::Channel>(3);
  EXPECT_TRUE(rejects(constant, with(kClip, {"unknown channel"})));
  SyntheticSpec animated;
  animated.clips[0].animated[2].channel = static_cast<fb::Channel>(200);
  EXPECT_TRUE(rejects(animated, with(kClip, {"unknown channel"})));
}

TEST(Clip, ChannelBothConstantAndAnimated) {
  SyntheticSpec spec;
  // spine rotation is animated; also make it constant (constants stay sorted).
  spec.clips[0].constants.insert(spec.clips[0].constants.begin() + 1,
                                 {1, fb::Channel::Rotation, fb::Quat(0, 0, 0, 1)});
  EXPECT_TRUE(rejects(spec, with(kClip, {"also constant"})));
}

TEST(Clip, AnimatedWithFewerThanTwoKeys) {
  for (uint32_t n : {0u, 1u}) {
    SyntheticSpec spec;
    spec.clips[0].animated[1].key_count = n;
    EXPECT_TRUE(rejects(spec, with(kClip, {"at least 2"}))) << n;
  }
}

TEST(Clip, KeysPastKeyFrames) {
  SyntheticSpec spec;
  spec.clips[0].animated[2].first_key = 6;  // 9 key frames; 6 + 4 > 9
  EXPECT_TRUE(rejects(spec, with(kClip, {"key frames"})));
  // first_key + key_count wraps in 32 bits: the check must not.
  SyntheticSpec wraps;
  wraps.clips[0].animated[1].first_key = 0xFFFFFFFFu;
  EXPECT_TRUE(rejects(wraps, with(kClip, {"key frames"})));
  SyntheticSpec huge;
  huge.clips[0].animated[1].key_count = 0xFFFFFFF0u;
  EXPECT_TRUE(rejects(huge, with(kClip, {"key frames"})));
}

TEST(Clip, KeyFramesNotIncreasing) {
  SyntheticSpec spec;
  spec.clips[0].animated[0].frames = {0, 20, 10};
  EXPECT_TRUE(rejects(spec, with(kClip, {"strictly increase"})));
  spec.clips[0].animated[0].frames = {0, 30, 30};
  EXPECT_TRUE(rejects(spec, with(kClip, {"strictly increase"})));
}

TEST(Clip, FirstKeyNotAtFrameZero) {
  SyntheticSpec spec;
  spec.clips[0].animated[0].frames = {1, 15, 30};
  EXPECT_TRUE(rejects(spec, with(kClip, {"first key"}, {"frame 0", "must be 0"})));
}

TEST(Clip, LastKeyNotAtLastFrame) {
  SyntheticSpec spec;
  spec.clips[0].animated[0].frames = {0, 15, 29};
  EXPECT_TRUE(rejects(spec, with(kClip, {"last key"})));
  SyntheticSpec past;
  past.clips[0].animated[0].frames = {0, 15, 31};
  EXPECT_TRUE(rejects(past, with(kClip, {"last key"})));
}

TEST(Clip, BitsInvalid) {
  for (uint8_t bits : {0, 20, 31, 33, 255}) {
    SyntheticSpec spec;
    spec.clips[0].animated[1].bits = bits;
    EXPECT_TRUE(rejects(spec, with(kClip, {"bits"}))) << int(bits);
  }
}

TEST(Clip, DroppedComponentInvalid) {
  SyntheticSpec rotation;
  rotation.clips[0].animated[0].dropped = 4;  // x, y, z, w are 0..3
  EXPECT_TRUE(rejects(rotation, with(kClip, {"dropped"})));
  // Other channels ignore the field.
  SyntheticSpec translation;
  translation.clips[0].animated[1].dropped = 3;
  EXPECT_TRUE(accepts(make_valid_file(translation)));
  for (uint8_t d = 0; d < 4; ++d) {
    SyntheticSpec valid;
    valid.clips[0].animated[0].dropped = d;
    EXPECT_TRUE(accepts(make_valid_file(valid))) << int(d);
  }
}

TEST(Clip, RawKeysNotByteAligned) {
  SyntheticSpec spec;
  spec.clips[0].animated[2].bit_offset = 217;
  EXPECT_TRUE(rejects(spec, with(kClip, {"byte boundary"})));
}

TEST(Clip, KeyBitsPastKeyValues) {
  SyntheticSpec spec;
  spec.clips[0].animated[0].bit_offset = 1000;
  EXPECT_TRUE(rejects(spec, with(kClip, {"key value bits"})));
  // Keys that end inside the padding: the decoder's 64-bit reads would leave the vector.
  SyntheticSpec short_padding;
  short_padding.clips[0].key_value_padding = 4;
  EXPECT_TRUE(rejects(short_padding, with(kClip, {"key value bits"})));
  // bit_offset + 3 * bits * key_count overflows 32 bits: the check must not.
  SyntheticSpec wraps;
  wraps.clips[0].animated[0].bit_offset = 0xFFFFFFF0u;
  EXPECT_TRUE(rejects(wraps, with(kClip, {"key value bits"})));
}

TEST(Clip, KeyValuesShorterThanPadding) {
  SyntheticSpec spec;
  spec.clips[0].key_values = std::vector<uint8_t>(4, 0);
  EXPECT_TRUE(rejects(spec, with(kClip, {"padding"})));
  SyntheticSpec missing;
  missing.clips[0].key_values = std::vector<uint8_t>();
  EXPECT_TRUE(rejects(missing, with(kClip, {"padding"})));
}

TEST(Clip, RangeNotFiniteOrNegative) {
  const std::pair<fb::Vec3, fb::Vec3> ranges[] = {
      {fb::Vec3(kNaN, 0, 0), fb::Vec3(1, 1, 1)},     {fb::Vec3(0, 0, 0), fb::Vec3(1, kInf, 1)},
      {fb::Vec3(0, 0, 0), fb::Vec3(1, 1, -0.5f)},    {fb::Vec3(3e38f, 0, 0), fb::Vec3(3e38f, 0, 0)},  // top overflows
  };
  for (const auto& [lo, extent] : ranges) {
    SyntheticSpec spec;
    spec.clips[0].animated[1].range_min = lo;
    spec.clips[0].animated[1].range_extent = extent;
    EXPECT_TRUE(rejects(spec, with(kClip, {"range"}))) << lo.x() << " " << extent.y();
  }
}

TEST(Clip, RotationRangeOutsideUnit) {
  SyntheticSpec spec;
  spec.clips[0].animated[0].range_min = fb::Vec3(-3, 0, 0);
  EXPECT_TRUE(rejects(spec, with(kClip, {"rotation"}, {"[-1, 1]"})));
  SyntheticSpec raw;
  raw.clips[0].animated[0].bits = 32;
  raw.clips[0].animated[0].values[1] = {0, 1.5f, 0};
  EXPECT_TRUE(rejects(raw, with(kClip, {"rotation"}, {"[-1, 1]"})));
}

TEST(Clip, RawKeyNotFinite) {
  for (float v : {kNaN, kInf, -kInf}) {
    SyntheticSpec spec;
    spec.clips[0].animated[2].values[3][1] = v;
    EXPECT_TRUE(rejects(spec, with(kClip, {"raw key"}, {"finite"}))) << v;
  }
}

TEST(Clip, ConstantNotFinite) {
  SyntheticSpec translation;
  translation.clips[0].constants[0].value = fb::Quat(kInf, 1, 0, 0);
  EXPECT_TRUE(rejects(translation, with(kClip, {"finite"})));
  SyntheticSpec rotation;
  rotation.clips[0].constants[1].value = fb::Quat(0, kNaN, 0, 1);
  EXPECT_TRUE(rejects(rotation, with(kClip, {"finite"}, {"quaternion"})));
  // w is unused for translation and scale constants: garbage there is harmless.
  SyntheticSpec unused_w;
  unused_w.clips[0].constants[0].value = fb::Quat(0, 1, 0, kNaN);
  EXPECT_TRUE(accepts(make_valid_file(unused_w)));
}

TEST(Clip, RotationConstantZero) {
  for (const fb::Quat& q : {fb::Quat(0, 0, 0, 0), fb::Quat(1e-30f, 0, 0, 0), fb::Quat(3e38f, 3e38f, 0, 0)}) {
    SyntheticSpec spec;
    spec.clips[0].constants[1].value = q;
    EXPECT_TRUE(rejects(spec, with(kClip, {"quaternion"}))) << q.x();
  }
}

SyntheticRootMotion valid_root_motion(uint32_t frames) {
  SyntheticRootMotion rm;
  rm.translations.assign(frames, fb::Vec3(0, 0, 0));
  rm.yaws.assign(frames, 0.0f);
  return rm;
}

TEST(Clip, RootMotionLengthMismatch) {
  SyntheticSpec spec;
  spec.clips[0].root_motion = valid_root_motion(30);  // 31 frames
  EXPECT_TRUE(rejects(spec, with(kClip, {"root motion"})));
  spec.clips[0].root_motion = valid_root_motion(31);
  spec.clips[0].root_motion->yaws.push_back(0.0f);
  EXPECT_TRUE(rejects(spec, with(kClip, {"root motion"})));
}

TEST(Clip, RootMotionNotFinite) {
  SyntheticSpec spec;
  spec.clips[0].root_motion = valid_root_motion(31);
  spec.clips[0].root_motion->translations[7] = fb::Vec3(0, kNaN, 0);
  EXPECT_TRUE(rejects(spec, with(kClip, {"root motion"}, {"finite"})));
  spec.clips[0].root_motion = valid_root_motion(31);
  spec.clips[0].root_motion->yaws[30] = kInf;
  EXPECT_TRUE(rejects(spec, with(kClip, {"root motion"}, {"finite"})));
}

TEST(Clip, RootMotionUpAxisInvalid) {
  SyntheticSpec spec;
  spec.clips[0].root_motion = valid_root_motion(31);
  spec.clips[0].root_motion->up_axis = 3;
  EXPECT_TRUE(rejects(spec, with(kClip, {"up axis"})));
}

TEST(Clip, JointCountDiffersFromItsSkeleton) {
  SyntheticSpec spec;
  spec.clips[0].joint_count = 5;  // bound by hash to the file's 4-joint skeleton
  EXPECT_TRUE(rejects(spec, with(kClip, {"joint"})));
}

TEST(Clip, BindingToAnotherRigRejected) {
  SyntheticSpec spec;
  spec.clips[0].skeleton_hash = 0xBADBADBADull;
  const Result<Asset> asset = Asset::from_bytes(make_valid_file(spec), "other-rig.ossa");
  ASSERT_TRUE(asset.ok()) << asset.error().message;  // a clip may belong to another rig
  const Status status = check_clip_binding(asset->clip(0), asset->skeleton(), "other-rig.ossa");
  EXPECT_FALSE(status.ok());
  EXPECT_TRUE(explains(status.message(), "other-rig.ossa", {{"walk"}, {"hash", "skeleton", "rig"}}));
}

// ---------------------------------------------------------------------------------------------
// Cooked textures (format v7): the chain's bytes must be exactly what its encoding and size give.

const Keywords kTexture = {{"skin", "material 0"}, {"texture 2", "Specular"}};

TEST(Texture, ChainBytesMustMatch) {
  SyntheticSpec spec;
  spec.materials[0].textures[2].data->push_back(0);  // one byte past the chain
  EXPECT_TRUE(rejects(spec, with(kTexture, {"40 bytes", "41"})));
  spec.materials[0].textures[2].data->resize(32);  // the last level missing
  EXPECT_TRUE(rejects(spec, with(kTexture, {"40 bytes", "32"})));
}

TEST(Texture, MipCountWithinTheFullChain) {
  SyntheticSpec spec;
  spec.materials[0].textures[2].mip_count = 5;  // 8 x 4 has 4 levels
  EXPECT_TRUE(rejects(spec, with(kTexture, {"mip levels"})));
  spec.materials[0].textures[2].mip_count = 0;
  EXPECT_TRUE(rejects(spec, with(kTexture, {"mip levels"})));
}

TEST(Texture, SizeWithinLimits) {
  SyntheticSpec spec;
  spec.materials[0].textures[2].width = 0;
  EXPECT_TRUE(rejects(spec, with(kTexture, {"texels"})));
  spec.materials[0].textures[2].width = 8;
  spec.materials[0].textures[2].height = 1u << 20;  // a huge claim over 40 bytes
  EXPECT_TRUE(rejects(spec, with(kTexture, {"texels"})));
}

TEST(Texture, UnknownEncodingAndSourceWithLevels) {
  SyntheticSpec spec;
  spec.materials[0].textures[2].encoding = static_cast<fb::TextureEncoding>(42);
  EXPECT_TRUE(rejects(spec, with(kTexture, {"encoding"})));
  SyntheticSpec source;
  source.materials[0].textures[0].mip_count = 3;  // PNG bytes do not have levels
  EXPECT_TRUE(rejects(source, {{"skin", "material 0"}, {"texture 0", "Diffuse"}, {"mip levels"}}));
}

TEST(Texture, EveryEncodingsChainAccepted) {
  // Each encoding at an odd size: level sizes round up to whole blocks (or texels for RGBA8).
  for (const auto e : {fb::TextureEncoding::Rgba8, fb::TextureEncoding::Bc1, fb::TextureEncoding::Bc3,
                       fb::TextureEncoding::Bc4, fb::TextureEncoding::Bc5}) {
    SyntheticSpec spec;
    SyntheticTexture& t = spec.materials[0].textures[2];
    t.encoding = e;
    t.width = 13;
    t.height = 5;
    t.mip_count = static_cast<uint8_t>(texture_full_mip_count(13, 5));
    t.data = std::vector<uint8_t>(static_cast<size_t>(texture_chain_bytes(e, 13, 5, t.mip_count)), 0x5a);
    EXPECT_TRUE(accepts(make_valid_file(spec))) << fb::EnumNameTextureEncoding(e);
    t.data->pop_back();
    EXPECT_TRUE(rejects(spec, with(kTexture, {"bytes"}))) << fb::EnumNameTextureEncoding(e);
  }
}

// ---------------------------------------------------------------------------------------------
// Montages and slot nodes (format v9): every stored field refused by name when hostile.

TEST(Montage, HostileFieldsRejectedByName) {
  const Keywords kMontage = {{"graph 0 'g'"}, {"montage 0", "node 16"}};
  struct Case {
    const char* what;
    std::function<void(SyntheticMontage&)> spoil;
    std::vector<std::string> words;
  };
  const float nan = kNaN, inf = kInf;
  const std::vector<Case> cases = {
      {"montage name", [](SyntheticMontage& m) { m.name.clear(); }, {"empty name"}},
      {"group", [](SyntheticMontage& m) { m.group.clear(); }, {"empty group"}},
      {"segment clip", [](SyntheticMontage& m) { m.clip = 5; }, {"clip 5 is out of range"}},
      {"segment start", [](SyntheticMontage& m) { m.start = -1.0f; }, {"start -1"}},
      {"segment end before start", [](SyntheticMontage& m) { m.end = 0.0f; }, {"end after start"}},
      {"segment end NaN", [=](SyntheticMontage& m) { m.end = nan; }, {"end nan"}},
      {"segment end huge", [](SyntheticMontage& m) { m.end = 1e7f; }, {"within [0, 1e6]"}},
      {"segment rate 0", [](SyntheticMontage& m) { m.segment_rate = 0.0f; }, {"segment 0: rate 0"}},
      {"segment rate inf", [=](SyntheticMontage& m) { m.segment_rate = inf; }, {"segment 0: rate inf"}},
      {"first section", [](SyntheticMontage& m) { m.section_starts = {0.1f, 0.25f}; }, {"first section starts at 0"}},
      {"section order", [](SyntheticMontage& m) { m.section_starts = {0.0f, 0.0f}; }, {"not after the section before"}},
      {"section past the end", [](SyntheticMontage& m) { m.section_starts = {0.0f, 5.0f}; }, {"before the montage's end"}},
      {"section start NaN", [=](SyntheticMontage& m) { m.section_starts = {0.0f, nan}; }, {"section 1"}},
      {"next section", [](SyntheticMontage& m) { m.section_next = {1, 7}; }, {"next section 7 is out of range"}},
      {"next section negative", [](SyntheticMontage& m) { m.section_next = {-2, 1}; }, {"next section -2"}},
      {"no sections", [](SyntheticMontage& m) { m.section_starts.clear(); }, {"0 sections"}},
      {"section name", [](SyntheticMontage& m) { m.section_names = {"start", ""}; }, {"section 1: has an empty name"}},
      {"notify time", [](SyntheticMontage& m) { m.notify_time = 5.0f; }, {"outside the montage"}},
      {"notify time NaN", [=](SyntheticMontage& m) { m.notify_time = nan; }, {"notify 0: time nan"}},
      {"window duration", [](SyntheticMontage& m) { m.notify_duration = 0.0f; }, {"above 0 for a window"}},
      {"notify duration inf", [=](SyntheticMontage& m) { m.notify_duration = inf; }, {"duration inf"}},
      {"notify kind", [](SyntheticMontage& m) { m.notify_kind = static_cast<fb::MontageNotifyKind>(9); }, {"unknown kind 9"}},
      {"notify name", [](SyntheticMontage& m) { m.notify.clear(); }, {"notify 0: has an empty name"}},
      {"montage rate", [](SyntheticMontage& m) { m.rate = 0.0f; }, {"'wave': rate 0"}},
      {"montage rate huge", [](SyntheticMontage& m) { m.rate = 1e9f; }, {"rate 1e+09"}},
      {"blend in", [](SyntheticMontage& m) { m.blend_in = -1.0f; }, {"blend in -1"}},
      {"blend out NaN", [=](SyntheticMontage& m) { m.blend_out = nan; }, {"blend out nan"}},
      {"blend curve", [](SyntheticMontage& m) { m.blend_in_curve = static_cast<fb::MontageCurve>(7); }, {"unknown blend curve 7"}},
      {"trigger", [=](SyntheticMontage& m) { m.trigger = nan; }, {"trigger nan"}},
      {"trigger huge", [](SyntheticMontage& m) { m.trigger = 1e7f; }, {"trigger 1e+07"}},
      {"track slot", [](SyntheticMontage& m) { m.track_slot.clear(); }, {"track 0: names no slot"}},
      {"slot name", [](SyntheticMontage& m) { m.slot.clear(); }, {"(slot): has an empty slot name"}},
      {"slot mask joint", [](SyntheticMontage& m) { m.mask_joint = 200; }, {"mask joint 200 is out of range"}},
      {"slot mask depth", [](SyntheticMontage& m) { m.mask_depth = -5; }, {"mask depth -5"}},
  };
  SyntheticSpec spec;
  spec.graph = true;
  spec.montage = SyntheticMontage{};
  ASSERT_TRUE(accepts(make_valid_file(spec)));
  for (const Case& c : cases) {
    SyntheticSpec bad = spec;
    c.spoil(*bad.montage);
    EXPECT_TRUE(rejects(bad, with(kMontage, c.words))) << c.what;
  }
}

// ---------------------------------------------------------------------------------------------
// Messages quote untrusted names: they must come out printable and bounded.

TEST(Messages, HostileNamesAreQuotedSafely) {
  SyntheticSpec spec;
  spec.clips.clear();  // only the skeleton is wrong
  spec.skeleton->names[2] = "\x1b[2J\x1b]0;pwned\x07" + std::string(100000, 'x');
  spec.skeleton->parents[2] = 3;
  const Result<Asset> asset = Asset::from_bytes(make_valid_file(spec), "hostile.ossa");
  ASSERT_FALSE(asset.ok());
  const std::string& message = asset.error().message;
  EXPECT_LT(message.size(), 2000u);
  EXPECT_TRUE(std::none_of(message.begin(), message.end(), [](char c) { return c == '\x1b' || c == '\x07'; }))
      << message.substr(0, 200);
}

}  // namespace
}  // namespace ossa::test
