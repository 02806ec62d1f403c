// cook_isolation_test.cpp — each input of an ossa-cook batch is cooked in a worker process of its
// own (cooker/cli/worker.h): an input whose worker aborts, crashes, hangs, runs out of its memory
// limit or sends back a broken record fails alone, named with the cause; the rest of the batch is
// cooked exactly as it would be alone; nothing is left behind for the failed inputs.
//
// The failing inputs are made here: sample copies that the worker test hook (OSSA_COOK_TEST_FAULT)
// makes misbehave, and two real sources that Debian's Assimp 5.2 cannot take — a binary FBX nested
// 100000 scopes deep (its tokenizer recurses once per scope and overflows the stack; the cooker
// now refuses it by name before Assimp reads it, cooker/import/source_precheck.h) and a BVH that
// announces 100 million frames (the importer reserves room for all of them at once).
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include <nlohmann/json.hpp>

#include "cooker/cli/worker.h"
#include "test_files.h"

namespace fs = std::filesystem;
using ossa::test::run_command;

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define OSSA_TEST_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
#define OSSA_TEST_SANITIZER 1
#endif
#endif

namespace {

std::string cook_cmd() { return (ossa::test::bin_dir() / "ossa-cook").string(); }
fs::path asset(const char* rel) { return ossa::test::source_dir() / "assets" / rel; }
std::string q(const fs::path& p) { return "'" + p.string() + "'"; }

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

std::vector<std::string> files_below(const fs::path& dir) {
  std::vector<std::string> names;
  std::error_code ec;
  for (fs::recursive_directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
    if (it->is_regular_file()) names.push_back(fs::relative(it->path(), dir).string());
  std::sort(names.begin(), names.end());
  return names;
}

template <class T>
constexpr bool kIsRecord = std::is_same_v<T, ossa::cook::CookRecord> || std::is_same_v<T, ossa::cook::ClipRecord> ||
                           std::is_same_v<T, ossa::cook::TextureRecord> || std::is_same_v<T, ossa::cook::MorphRecord> ||
                           std::is_same_v<T, ossa::cook::InputFile> || std::is_same_v<T, ossa::cook::RetargetRecord> ||
                           std::is_same_v<T, ossa::cook::RetargetContactRecord>;
template <class T>
struct RecordList : std::false_type {};
template <class T>
struct RecordList<std::vector<T>> : std::bool_constant<kIsRecord<T>> {};

/// Every field in the records' field lists (cooker/model/cook_record.h) equal, named on failure.
template <class Record>
void expect_same_fields(const Record& got, const Record& want, const std::string& where) {
  ossa::cook::record_fields(
      [&](const char* key, const auto& x, const auto& y) {
        if constexpr (RecordList<std::decay_t<decltype(x)>>::value) {
          ASSERT_EQ(x.size(), y.size()) << where << key;
          for (size_t i = 0; i < x.size(); ++i)
            expect_same_fields(x[i], y[i], where + key + "[" + std::to_string(i) + "].");
        } else {
          EXPECT_EQ(x, y) << where << key;
        }
      },
      got, want);
}

/// Every listed field of `r` differs from its default (a list: is not empty, and so for its first
/// record), except `left_empty`: a round trip of `r` then proves something for every field.
template <class Record>
void expect_every_field_set(const Record& r, const std::string& where, std::string_view left_empty = {}) {
  const Record unset{};
  ossa::cook::record_fields(
      [&](const char* key, const auto& x, const auto& d) {
        if (key == left_empty) return;
        if constexpr (RecordList<std::decay_t<decltype(x)>>::value) {
          ASSERT_FALSE(x.empty()) << where << key << " is left empty";
          expect_every_field_set(x.front(), where + key + "[0].");
        } else {
          EXPECT_NE(x, d) << where << key << " is left at its default";
        }
      },
      r, unset);
}

nlohmann::json read_json(const fs::path& path) {
  const auto text = ossa::test::read_text(path);
  EXPECT_TRUE(text.has_value()) << path;
  return text ? nlohmann::json::parse(*text) : nlohmann::json();
}

const nlohmann::json* record_for(const nlohmann::json& report, const std::string& file_name) {
  for (const nlohmann::json& r : report["records"])
    if (fs::path(r["input"].get<std::string>()).filename() == file_name) return &r;
  return nullptr;
}

/// A binary FBX (version 7400) whose nodes nest `depth` deep, each with its end offset and the
/// 13-byte null record that closes a nested list: well formed, and too deep for a recursive reader.
std::vector<uint8_t> deeply_nested_fbx(uint32_t depth) {
  const std::string magic = "Kaydara FBX Binary";
  std::vector<uint8_t> bytes(magic.begin(), magic.end());
  for (uint8_t b : {0x20, 0x20, 0x00, 0x1a, 0x00}) bytes.push_back(b);
  const auto put32 = [&bytes](uint32_t v) {
    for (int i = 0; i < 4; ++i) bytes.push_back(static_cast<uint8_t>(v >> (8 * i)));
  };
  put32(7400);
  constexpr uint32_t kHeader = 14, kNullRecord = 13;  // end, property count, property bytes, name length, "N"
  for (uint32_t level = 0; level < depth; ++level) {
    const uint32_t start = static_cast<uint32_t>(bytes.size());
    put32(start + kHeader + (depth - 1 - level) * (kHeader + kNullRecord) + kNullRecord);
    put32(0);
    put32(0);
    bytes.push_back(1);
    bytes.push_back('N');
  }
  bytes.resize(bytes.size() + size_t{kNullRecord} * (depth + 1), 0);  // each level's close, then the file's
  return bytes;
}

/// A BVH with one joint that announces `frames` frames and holds one.
std::string bvh_announcing(uint64_t frames) {
  return "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation "
         "Yrotation\n  End Site\n  {\n    OFFSET 0 1 0\n  }\n}\nMOTION\nFrames: " +
         std::to_string(frames) + "\nFrame Time: 0.033333\n0 0 0 0 0 0\n";
}

TEST(CookIsolation, BatchAroundFailingWorkersCooksEverythingElseExactly) {
#if defined(OSSA_TEST_SANITIZER)
  GTEST_SKIP() << "sanitizer build: the memory limit is not enforced and the sanitizer catches the crashes itself";
#endif
  const fs::path dir = ossa::test::make_temp_dir("iso-batch");
  const fs::path src = dir / "src", out = dir / "out", alone = dir / "alone", report_path = dir / "report.json";
  fs::create_directories(src);
  // Good inputs, and copies of a good one that the test hook makes misbehave.
  const std::vector<std::string> good = {"Fox.glb", "RiggedSimple.glb", "walk.fbx"};
  fs::copy_file(asset("Fox/Fox.glb"), src / "Fox.glb");
  fs::copy_file(asset("RiggedSimple/RiggedSimple.glb"), src / "RiggedSimple.glb");
  fs::copy_file(asset("Pab/walk.fbx"), src / "walk.fbx");
  for (const char* name : {"aborts.glb", "crashes.glb", "hangs.glb", "allocates.glb", "garbles.glb"})
    fs::copy_file(asset("RiggedSimple/RiggedSimple.glb"), src / name);
  // Real sources that end an importer.
  ASSERT_TRUE(ossa::test::write_file(src / "deep.fbx", deeply_nested_fbx(100000)));
  ASSERT_TRUE(ossa::test::write_file(src / "frames.bvh", bvh_announcing(100000000)));

  const std::string faults = "aborts.glb:abort,crashes.glb:segv,hangs.glb:hang,allocates.glb:alloc,garbles.glb:garble";
  // --timeout 20: long enough that no good input reaches it on a loaded machine, short enough that
  // the hang ends soon. No -q: the batch prints a line per input as it ends, in that order.
  const auto r = run_command("OSSA_COOK_TEST_FAULT=" + faults + " " + cook_cmd() + " " + q(src) + " -o " + q(out) +
                             " --jobs 2 --timeout 20 --max-memory 512M --report " + q(report_path));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  // One worker hangs until its time limit while the other slot cooks the rest: walk.fbx, after
  // hangs.glb in input order, ends before the hang is ended, so the batch is not serialized
  // behind it (an order of events, not a time).
  const size_t walk_done = r.err.find("walk.fbx -> "), hang_ended = r.err.find("hangs.glb: exceeded the time limit");
  ASSERT_NE(walk_done, std::string::npos) << r.err;
  ASSERT_NE(hang_ended, std::string::npos) << r.err;
  EXPECT_LT(walk_done, hang_ended) << "the batch waited for the hanging worker:\n" << r.err;

  // stderr names each bad input with what ended it.
  EXPECT_TRUE(contains(r.err, "aborts.glb: worker killed by signal 6 (SIGABRT")) << r.err;
  EXPECT_TRUE(contains(r.err, "crashes.glb: worker killed by signal 11 (SIGSEGV")) << r.err;
  EXPECT_TRUE(contains(r.err, "hangs.glb: exceeded the time limit (--timeout 20 s)")) << r.err;
  EXPECT_TRUE(contains(r.err, "allocates.glb: exceeded the memory limit (--max-memory 512 MiB)")) << r.err;
  EXPECT_TRUE(contains(r.err, "garbles.glb: worker sent an unreadable record")) << r.err;
  EXPECT_TRUE(contains(r.err, "frames.bvh: exceeded the memory limit (--max-memory 512 MiB)")) << r.err;
  EXPECT_TRUE(contains(r.err, "deep.fbx: its record tree is nested over 1000+ levels deep")) << r.err;
  EXPECT_TRUE(contains(r.err, "7 of 10 inputs failed")) << r.err;

  // Only the good outputs exist (no output and no temporary file for the bad ones), each
  // byte-identical to the same input cooked alone.
  EXPECT_EQ(files_below(out), (std::vector<std::string>{"Fox.ossa", "RiggedSimple.ossa", "walk.ossa"}));
  for (const std::string& name : good) {
    const auto single = run_command(cook_cmd() + " " + q(src / name) + " -o " + q(alone) + " -q");
    ASSERT_EQ(single.exit_code, 0) << single.err;
    const std::string cooked = fs::path(name).stem().string() + ".ossa";
    const auto batch_bytes = ossa::test::read_file(out / cooked), alone_bytes = ossa::test::read_file(alone / cooked);
    ASSERT_TRUE(batch_bytes && alone_bytes) << name;
    EXPECT_TRUE(*batch_bytes == *alone_bytes) << name << " cooked in the batch differs from cooked alone";
  }

  // The report: complete, in input order, valid, with the limits and each cause.
  const nlohmann::json report = read_json(report_path);
  EXPECT_EQ(report["inputs"], 10);
  EXPECT_EQ(report["failed"], 7);
  EXPECT_EQ(report["limits"]["max_memory_bytes"], 512u << 20);
  EXPECT_EQ(report["limits"]["timeout_seconds"], 20);
  ASSERT_EQ(report["records"].size(), 10u);
  std::vector<std::string> inputs;
  for (const nlohmann::json& rec : report["records"]) inputs.push_back(rec["input"].get<std::string>());
  EXPECT_TRUE(std::is_sorted(inputs.begin(), inputs.end())) << "records in input order";
  for (const std::string& name : good) {
    const nlohmann::json* rec = record_for(report, name);
    ASSERT_NE(rec, nullptr) << name;
    EXPECT_EQ((*rec)["status"], "ok") << name;
  }
  const std::vector<std::pair<std::string, std::string>> causes = {{"aborts.glb", "signal 6"},
                                                                   {"crashes.glb", "signal 11"},
                                                                   {"hangs.glb", "time limit"},
                                                                   {"allocates.glb", "memory limit"},
                                                                   {"garbles.glb", "unreadable record"},
                                                                   {"frames.bvh", "memory limit"},
                                                                   {"deep.fbx", "nested over 1000+ levels deep"}};
  for (const auto& [name, cause] : causes) {
    const nlohmann::json* rec = record_for(report, name);
    ASSERT_NE(rec, nullptr) << name;
    EXPECT_EQ((*rec)["status"], "failed") << name;
    const std::string error = (*rec).value("error", "");
    EXPECT_TRUE(contains(error, name)) << error;
    EXPECT_TRUE(contains(error, cause)) << error;
    EXPECT_FALSE(rec->contains("output")) << name;
  }
  const nlohmann::json* hung = record_for(report, "hangs.glb");
  ASSERT_NE(hung, nullptr);
  // Ended by its limit: not before it, and not long after it (a bound that only a lost kill breaks).
  EXPECT_GE((*hung)["seconds"].get<double>(), 20.0);
  EXPECT_LT((*hung)["seconds"].get<double>(), 60.0);

  const auto check = run_command(
      "/usr/bin/python3 " + q(ossa::test::source_dir() / "tests" / "support" / "json_schema_check.py") + " " +
      q(ossa::test::source_dir() / "docs" / "schemas" / "ossa-cook-report.schema.json") + " " + q(report_path));
  EXPECT_EQ(check.exit_code, 0) << check.out << check.err;
}

TEST(CookIsolation, DeadWorkerLeavesNothingAndKeepsAPreviousOutput) {
  const fs::path dir = ossa::test::make_temp_dir("iso-leftovers");
  const fs::path src = dir / "src", out = dir / "out";
  fs::create_directories(src);
  fs::create_directories(out);
  for (const char* name : {"after.glb", "writing.glb", "kept.glb"})
    fs::copy_file(asset("RiggedSimple/RiggedSimple.glb"), src / name);
  // kept.glb's worker dies before cooking: the file already at its output must stay as it was.
  ASSERT_TRUE(ossa::test::write_file(out / "kept.ossa", std::string_view("previous output")));
  const auto r = run_command("OSSA_COOK_TEST_FAULT=after.glb:abort-after,writing.glb:abort-writing,kept.glb:abort " +
                             cook_cmd() + " " + q(src) + " -o " + q(out) + " --jobs 2 -q");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_TRUE(contains(r.err, "after.glb: worker killed by signal 6")) << r.err;
  EXPECT_TRUE(contains(r.err, "writing.glb: worker killed by signal 6")) << r.err;
  EXPECT_TRUE(contains(r.err, "kept.glb: worker killed by signal 6")) << r.err;
  // after.glb's worker died with its output renamed into place, writing.glb's with a temporary
  // beside it: both are gone, since their records say failed.
  EXPECT_EQ(files_below(out), std::vector<std::string>{"kept.ossa"});
  EXPECT_EQ(ossa::test::read_text(out / "kept.ossa").value_or(""), "previous output");
}

TEST(CookIsolation, JobsOneAndTwoGiveIdenticalBytes) {
  const fs::path dir = ossa::test::make_temp_dir("iso-jobs");
  const fs::path assets = ossa::test::source_dir() / "assets";
  for (const char* jobs : {"1", "2"}) {
    const auto r = run_command(cook_cmd() + " " + q(assets) + " --root " + q(assets) + " -o " + q(dir / jobs) +
                               " -q --jobs " + jobs + " --report " + q(dir / (std::string(jobs) + ".json")));
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  const std::vector<std::string> one = files_below(dir / "1"), two = files_below(dir / "2");
  EXPECT_EQ(one, two);
  EXPECT_GE(one.size(), 10u);
  for (const std::string& name : one) {
    const auto a = ossa::test::read_file(dir / "1" / name), b = ossa::test::read_file(dir / "2" / name);
    ASSERT_TRUE(a && b) << name;
    EXPECT_TRUE(*a == *b) << name << " differs between --jobs 1 and --jobs 2";
  }
  // The reports agree too, but for the time each input took and the output directory.
  nlohmann::json r1 = read_json(dir / "1.json"), r2 = read_json(dir / "2.json");
  for (auto [report, jobs] : {std::pair{&r1, "1"}, std::pair{&r2, "2"}}) {
    for (nlohmann::json& rec : (*report)["records"]) {
      rec.erase("seconds");
      rec["output"] = fs::relative(rec["output"].get<std::string>(), dir / jobs).string();
    }
  }
  r1["limits"].erase("max_memory_bytes");  // the default share depends on the number of workers
  r2["limits"].erase("max_memory_bytes");
  EXPECT_EQ(r1, r2);
}

TEST(CookIsolation, LimitOptions) {
  const fs::path dir = ossa::test::make_temp_dir("iso-options");
  const fs::path input = asset("RiggedSimple/RiggedSimple.glb");
  auto r = run_command(cook_cmd() + " " + q(input) + " -o " + q(dir / "a") +
                       " -q --max-memory 1.5GiB --timeout 0 --report " + q(dir / "a.json"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  nlohmann::json report = read_json(dir / "a.json");
  EXPECT_EQ(report["limits"]["max_memory_bytes"], uint64_t{3} << 29);
  EXPECT_EQ(report["limits"]["timeout_seconds"], 0);
  EXPECT_FALSE(contains(report["options"].get<std::string>(), "memory")) << "limits are not cook options";

  // Defaults: a share of the machine's memory, never below 1 GiB, and 600 s.
  r = run_command(cook_cmd() + " " + q(input) + " -o " + q(dir / "b") + " -q --report " + q(dir / "b.json"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  report = read_json(dir / "b.json");
  EXPECT_GE(report["limits"]["max_memory_bytes"].get<uint64_t>(), uint64_t{1} << 30);
  EXPECT_EQ(report["limits"]["timeout_seconds"], 600);

  for (const char* bad : {"lots", "12X", "-1G", "1e9", "0x10", ""}) {
    r = run_command(cook_cmd() + " " + q(input) + " -o " + q(dir / "c") + " --max-memory '" + bad + "'");
    EXPECT_EQ(r.exit_code, 2) << bad << ": " << r.err;
    EXPECT_FALSE(fs::exists(dir / "c")) << bad;
  }
  for (const auto& [text, bytes] : std::vector<std::pair<std::string, uint64_t>>{{"512M", 512u << 20},
                                                                                 {"4g", uint64_t{4} << 30},
                                                                                 {"2097152k", uint64_t{2} << 30},
                                                                                 {"3000MB", uint64_t{3000} << 20},
                                                                                 {"1073741824", uint64_t{1} << 30},
                                                                                 {"0", 0}}) {
    r = run_command(cook_cmd() + " " + q(input) + " -o " + q(dir / "d") + " -q --max-memory " + text + " --report " +
                    q(dir / "d.json"));
    ASSERT_EQ(r.exit_code, 0) << text << ": " << r.err;
    EXPECT_EQ(read_json(dir / "d.json")["limits"]["max_memory_bytes"], bytes) << text;
  }
#if !defined(OSSA_TEST_SANITIZER)
  // A limit below what a worker already maps fails the input cleanly, naming the limit.
  r = run_command(cook_cmd() + " " + q(input) + " -o " + q(dir / "e") + " -q --max-memory 100k");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_TRUE(contains(r.err, "RiggedSimple.glb: exceeded the memory limit (--max-memory 100 KiB)")) << r.err;
  EXPECT_EQ(ossa::test::count_files(dir / "e"), 0u);
#endif
}

// ---------------------------------------------------------------------------------------------
// The record's wire form (cooker/cli/worker.h): every field survives, broken bytes are refused.

TEST(CookIsolation, RecordRoundTripsEveryField) {
  ossa::cook::CookRecord r;
  r.input = "in/\xff\xfe not UTF-8.fbx";  // paths and joint names are bytes, not always UTF-8
  r.output = "out/x.ossa";
  r.ok = true;
  r.error = "an error";
  r.warnings = {"first", "second \xc3\xa9"};
  r.joints = 1;
  r.clips = 2;
  r.materials = 3;
  r.textures = 4;
  r.vertices_over_4_influences = 5;
  r.meshes = 6;
  r.submeshes = std::nullopt;
  r.vertices = 8;
  r.triangles = 9;
  r.source_bytes = (uint64_t{1} << 40) + 7;
  r.cooked_bytes = 1234;
  r.seconds = 0.1 + 0.2;
  ossa::cook::ClipRecord c;
  c.name = "walk";
  c.joints = 68;
  c.frames = 31;
  c.raw_bytes = 100000;
  c.cooked_bytes = 999;
  c.max_error_mm = 0.0999f;
  c.mean_error_mm = 1.0f / 3.0f;
  c.worst_joint = "LeftHand";
  r.clip_records = {c, ossa::cook::ClipRecord{}};
  ossa::cook::MorphRecord m;
  m.mesh = "head";
  m.name = "jawOpen";
  m.vertices = 1234;
  m.raw_bytes = 56789;
  m.stored_bytes = 9876;
  m.position_error_mm = 0.0199f;
  m.position_bound_mm = 0.0283f;
  m.normal_error_deg = 0.0625f;
  r.morph_records = {m, ossa::cook::MorphRecord{}};
  ossa::cook::TextureRecord t;
  t.name = "skin.png";
  t.role = "normal";
  t.encoding = "BC5";
  t.srgb = true;
  t.width = 1024;
  t.height = 512;
  t.mips = 11;
  t.source_bytes = 123456;
  t.cooked_bytes = 699064;
  t.gpu_rgba8_bytes = 2796200;
  t.psnr_db = 41.25f;
  t.normal_mean_deg = 0.5f;
  t.normal_max_deg = 3.75f;
  r.texture_records = {t, ossa::cook::TextureRecord{}};
  ossa::cook::RetargetContactRecord contact;
  contact.foot = 1;
  contact.start = 0.25f;
  contact.end = 0.75f;
  contact.held_mm = 0.5f;
  contact.slide_mm = 1.5f;
  contact.source_slide_mm = 2.25f;
  ossa::cook::RetargetRecord rt;
  rt.clip = "walk";
  rt.frames = 31;
  rt.hips_ratio = 1.125f;
  rt.floor_mm = 3.5f;
  rt.limb_max_deg = 4.5f;
  rt.guard_max_deg = 5.5f;
  rt.hand_max_deg = 6.5f;
  rt.foot_max_deg = 7.5f;
  rt.crossing_frames = 2;
  rt.guarded_frames = 3;
  rt.contacts = {contact, ossa::cook::RetargetContactRecord{}};
  r.retarget_records = {rt, ossa::cook::RetargetRecord{}};
  r.inputs_read = {{"/src/walk.fbx", 0xfedcba9876543210ull, (uint64_t{1} << 33) + 1, true},
                   {"/src/walk.events.json", 0, 0, false}};
  r.cook_key = 0x8000000000000001ull;
  r.up_to_date = true;
  r.cache_hit = true;
  r.cache_note = "http://cache: ac/0123: Timeout was reached";
  r.cache_down = true;
  r.cache_bytes_fetched = 0x100000001ull;
  r.cache_bytes_stored = 0x200000002ull;

  // The test means nothing for a field it leaves at its default: every listed field is set (the
  // one optional left empty checks that null crosses too), and each record list holds a record with
  // every field set and a default one.
  expect_every_field_set(r, "record.", "submeshes");

  const std::vector<uint8_t> wire = nlohmann::json::to_cbor(ossa::cook::record_to_json(r));
  const auto back = ossa::cook::record_from_json(nlohmann::json::from_cbor(wire));
  ASSERT_TRUE(back.has_value());
  expect_same_fields(*back, r, "record.");

  // Broken: every truncation of the wire bytes, a missing field, a field of another type.
  for (size_t n = 0; n < wire.size(); ++n) {
    const auto parsed = nlohmann::json::from_cbor(
        std::vector<uint8_t>(wire.begin(), wire.begin() + static_cast<ptrdiff_t>(n)), true, false);
    EXPECT_TRUE(parsed.is_discarded() || !ossa::cook::record_from_json(parsed)) << "truncated at " << n;
  }
  nlohmann::json missing = ossa::cook::record_to_json(r);
  missing.erase("seconds");
  EXPECT_FALSE(ossa::cook::record_from_json(missing));
  nlohmann::json wrong = ossa::cook::record_to_json(r);
  wrong["joints"] = "many";
  EXPECT_FALSE(ossa::cook::record_from_json(wrong));
  EXPECT_FALSE(ossa::cook::record_from_json(nlohmann::json::array()));
}

}  // namespace
