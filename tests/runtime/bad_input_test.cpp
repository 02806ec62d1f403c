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
// test breaks exactly one invariant. The cases are split over three files by what they break (this
// one: damaged bytes, not an .ossa file, hostile names; bad_input_mesh_test.cpp: skeleton, mesh and
// morph invariants; bad_input_clip_test.cpp: clip and texture invariants), one program.
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

#include "bad_input.h"

namespace ossa::test {
namespace {

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
      else if (const std::string problem = walk_asset(*asset); !problem.empty())
        failures.push_back(name + ": " + problem);
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
  const auto mesh =
      fb::CreateMeshDirect(fbb, "shared", 3, 12, &layout, &vertices, fb::IndexFormat::Uint16, &indices, &submeshes);
  const std::vector<flatbuffers::Offset<fb::Mesh>> meshes(2000, mesh);
  fb::FinishFileBuffer(fbb, fb::CreateFileDirect(fbb, kFormatVersion, 1.0f, 0, &meshes));
  const std::vector<uint8_t> bytes(fbb.GetBufferPointer(), fbb.GetBufferPointer() + fbb.GetSize());
  EXPECT_TRUE(rejects(bytes, {{"shared", "refusing", "far more"}}));
  // The same mesh referenced once is fine.
  flatbuffers::FlatBufferBuilder once;
  const auto single =
      fb::CreateMeshDirect(once, "shared", 3, 12, &layout, &vertices, fb::IndexFormat::Uint16, &indices, &submeshes);
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
      {"first section",
       [](SyntheticMontage& m) {
         m.section_starts = {0.1f, 0.25f};
       },
       {"first section starts at 0"}},
      {"section order",
       [](SyntheticMontage& m) {
         m.section_starts = {0.0f, 0.0f};
       },
       {"not after the section before"}},
      {"section past the end",
       [](SyntheticMontage& m) {
         m.section_starts = {0.0f, 5.0f};
       },
       {"before the montage's end"}},
      {"section start NaN",
       [=](SyntheticMontage& m) {
         m.section_starts = {0.0f, nan};
       },
       {"section 1"}},
      {"next section",
       [](SyntheticMontage& m) {
         m.section_next = {1, 7};
       },
       {"next section 7 is out of range"}},
      {"next section negative",
       [](SyntheticMontage& m) {
         m.section_next = {-2, 1};
       },
       {"next section -2"}},
      {"no sections", [](SyntheticMontage& m) { m.section_starts.clear(); }, {"0 sections"}},
      {"section name",
       [](SyntheticMontage& m) {
         m.section_names = {"start", ""};
       },
       {"section 1: has an empty name"}},
      {"notify time", [](SyntheticMontage& m) { m.notify_time = 5.0f; }, {"outside the montage"}},
      {"notify time NaN", [=](SyntheticMontage& m) { m.notify_time = nan; }, {"notify 0: time nan"}},
      {"window duration", [](SyntheticMontage& m) { m.notify_duration = 0.0f; }, {"above 0 for a window"}},
      {"notify duration inf", [=](SyntheticMontage& m) { m.notify_duration = inf; }, {"duration inf"}},
      {"notify kind",
       [](SyntheticMontage& m) { m.notify_kind = static_cast<fb::MontageNotifyKind>(9); },
       {"unknown kind 9"}},
      {"notify name", [](SyntheticMontage& m) { m.notify.clear(); }, {"notify 0: has an empty name"}},
      {"montage rate", [](SyntheticMontage& m) { m.rate = 0.0f; }, {"'wave': rate 0"}},
      {"montage rate huge", [](SyntheticMontage& m) { m.rate = 1e9f; }, {"rate 1e+09"}},
      {"blend in", [](SyntheticMontage& m) { m.blend_in = -1.0f; }, {"blend in -1"}},
      {"blend out NaN", [=](SyntheticMontage& m) { m.blend_out = nan; }, {"blend out nan"}},
      {"blend curve",
       [](SyntheticMontage& m) { m.blend_in_curve = static_cast<fb::MontageCurve>(7); },
       {"unknown blend curve 7"}},
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
// Retarget nodes (format v10): every stored field refused by name when hostile.

TEST(RetargetNode, HostileFieldsRejectedByName) {
  const Keywords kNode = {{"graph 0 'g'"}, {"node 16"}};
  struct Case {
    const char* what;
    std::function<void(SyntheticRetarget&)> spoil;
    std::vector<std::string> words;
  };
  const float nan = kNaN, inf = kInf;
  const std::vector<Case> cases = {
      {"clip", [](SyntheticRetarget& r) { r.clip = 9; }, {"retarget clip 9 is out of range"}},
      {"rate", [=](SyntheticRetarget& r) { r.rate = inf; }, {"retarget rate inf"}},
      {"rate NaN", [=](SyntheticRetarget& r) { r.rate = nan; }, {"retarget rate nan"}},
      {"start", [](SyntheticRetarget& r) { r.start = -1.0f; }, {"retarget start offset"}},
      {"rate parameter", [](SyntheticRetarget& r) { r.rate_parameter = 2; }, {"rate", "'go'"}},
      {"no source joints", [](SyntheticRetarget& r) { r.source_joints = 0; }, {"source rig has no joints"}},
      {"source bone count",
       [](SyntheticRetarget& r) { r.source_bones.resize(51, -1); },
       {"retarget source bones: 51 entries"}},
      {"target bone count",
       [](SyntheticRetarget& r) { r.target_bones.resize(53, -1); },
       {"retarget target bones: 53 entries"}},
      {"source bone joint", [](SyntheticRetarget& r) { r.source_bones[3] = 30; }, {"source bone 3 names joint 30"}},
      {"source bone negative", [](SyntheticRetarget& r) { r.source_bones[0] = -7; }, {"source bone 0 names joint -7"}},
      {"target bone joint", [](SyntheticRetarget& r) { r.target_bones[5] = 900; }, {"target bone 5 names joint 900"}},
      {"rest mode", [](SyntheticRetarget& r) { r.source_rest = 7; }, {"source rest mode 7 is unknown"}},
      {"rest rotation joint", [](SyntheticRetarget& r) { r.rest_joint = 400; }, {"target rest rotation joint 400"}},
      {"rest rotation NaN",
       [=](SyntheticRetarget& r) { r.rest_rotation = fb::Quat(nan, 0, 0, 1); },
       {"not a unit quaternion"}},
      {"rest rotation length",
       [](SyntheticRetarget& r) { r.rest_rotation = fb::Quat(0, 0, 0, 2); },
       {"not a unit quaternion"}},
      {"clip also on a clip node",
       [](SyntheticRetarget& r) { r.clip_node_plays_it = true; },
       {"node 0: clip 1 is played by a retarget node"}},
  };
  SyntheticSpec spec;
  spec.graph = true;
  spec.retarget = SyntheticRetarget{};
  ASSERT_TRUE(accepts(make_valid_file(spec)));
  for (const Case& c : cases) {
    SyntheticSpec bad = spec;
    c.spoil(*bad.retarget);
    const Keywords words =
        c.what == std::string("clip also on a clip node") ? Keywords{{"graph 0 'g'"}, c.words} : with(kNode, c.words);
    EXPECT_TRUE(rejects(bad, words)) << c.what;
  }
  // A montage playing the retarget clip is refused too.
  SyntheticSpec montage = spec;
  montage.montage = SyntheticMontage{};
  montage.montage->clip = 1;
  EXPECT_TRUE(rejects(montage, {{"graph 0 'g'"}, {"montage 0: clip 1 is played by a retarget node"}}));
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
