// cook_cache_test.cpp — ossa-cook --cache end to end: a tree cooked on "machine A" into a shared
// cache, then a second clone in another folder cooks nothing and gets outputs byte-identical to a
// local cook; over a folder and over a real nginx (WebDAV) on loopback. Then the faults a studio's
// cache meets: damaged, truncated and foreign entries; a server that goes down mid-batch, answers
// garbage or never answers (tests/support/cache_http_server.py); a full or write-refusing cache
// folder; two writers at once. In every case every output must equal the local cook's bytes and no
// cook may fail: the cache costs misses, never outputs.
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <grp.h>
#include <netinet/in.h>
#include <pwd.h>
#include <signal.h>
#include <sys/mount.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <map>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "test_files.h"

namespace fs = std::filesystem;
using nlohmann::json;
using ossa::test::run_command;

namespace {

std::string q(const fs::path& p) { return "'" + p.string() + "'"; }
fs::path asset(const char* rel) { return ossa::test::source_dir() / "assets" / rel; }

/// A tree with one input of each kind the key must cover: a GLB, an FBX rig, an FBX clip with its
/// event sidecar, a graph file naming another source, and (with ../shared) a .gltf whose buffer
/// and texture are known only once it is parsed.
void make_tree(const fs::path& root) {
  fs::create_directories(root / "chars");
  fs::create_directories(root / "pab");
  fs::create_directories(root / "fox");
  fs::copy_file(asset("RiggedSimple/RiggedSimple.glb"), root / "chars" / "RiggedSimple.glb");
  fs::copy_file(asset("Pab/skeleton.fbx"), root / "pab" / "skeleton.fbx");
  fs::copy_file(asset("Pab/walk.fbx"), root / "pab" / "walk.fbx");
  fs::copy_file(asset("Pab/walk.events.json"), root / "pab" / "walk.events.json");
  fs::copy_file(asset("Fox/Fox.glb"), root / "fox" / "Fox.glb");
  fs::copy_file(asset("Fox/fox_tail.graph.json"), root / "fox" / "fox_tail.graph.json");
  const fs::path shared = ossa::test::shared_assets() / "Khronos_embedded";
  if (fs::exists(shared / "interpolation_test.gltf")) {
    fs::create_directories(root / "gltf");
    fs::copy_file(shared / "interpolation_test.gltf", root / "gltf" / "interpolation_test.gltf");
    fs::copy_file(shared / "interpolation_test.bin", root / "gltf" / "interpolation_test.bin");
    EXPECT_TRUE(ossa::test::write_file(root / "gltf" / "l.jpg", ossa::test::tiny_png()));
  }
}

std::map<std::string, std::vector<uint8_t>> snapshot(const fs::path& dir) {
  std::map<std::string, std::vector<uint8_t>> out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) out[fs::relative(e.path(), dir).string()] = *ossa::test::read_file(e.path());
  return out;
}

struct Cook {
  ossa::test::CommandResult run;
  json report;
  const json& cache() const { return report.at("cache"); }
  size_t hits() const { return report.at("cache").at("hits").get<size_t>(); }
  size_t misses() const { return report.at("cache").at("misses").get<size_t>(); }
};

Cook cook(const fs::path& tree, const fs::path& out, const std::string& extra, unsigned jobs = 2) {
  const fs::path report = out.string() + ".report.json";
  Cook c;
  c.run = run_command("env -u OSSA_COOK_CACHE -u OSSA_COOK_CACHE_MODE " +
                      (ossa::test::bin_dir() / "ossa-cook").string() + " " + q(tree) + " -o " + q(out) + " --root " +
                      q(tree) + " -j" + std::to_string(jobs) + " --report " + q(report) + " " + extra);
  if (auto text = ossa::test::read_text(report)) c.report = json::parse(*text, nullptr, false);
  fs::remove(report);
  return c;
}

class CookCache : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = ossa::test::make_temp_dir("cook_cache");
    make_tree(dir_ / "clone1");
    fs::copy(dir_ / "clone1", dir_ / "clone2", fs::copy_options::recursive);
    fs::copy(dir_ / "clone1", dir_ / "clone3", fs::copy_options::recursive);
    const Cook local = cook(dir_ / "clone1", dir_ / "local", "");
    ASSERT_EQ(local.run.exit_code, 0) << local.run.err;
    local_ = snapshot(dir_ / "local");
    inputs_ = local.report.at("inputs").get<size_t>();
    ASSERT_GE(inputs_, 5u);
  }
  void TearDown() override {
    ::umount2((dir_ / "tiny").c_str(), MNT_DETACH);  // FullCacheFolder's, if an assertion left it mounted
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  /// Every output of `out` equals the local cook's, and nothing else is there (no temporaries).
  void expect_local_bytes(const fs::path& out) {
    const auto got = snapshot(out);
    ASSERT_EQ(got.size(), local_.size()) << out;
    for (const auto& [name, bytes] : local_) {
      const auto it = got.find(name);
      ASSERT_NE(it, got.end()) << name;
      EXPECT_TRUE(it->second == bytes) << name << " differs from the local cook";
    }
  }
  /// Cooks clone1 into `cache` (machine A), expecting every input cooked and stored.
  void populate(const std::string& cache) {
    const Cook a = cook(dir_ / "clone1", dir_ / "outA", "--cache " + cache);
    ASSERT_EQ(a.run.exit_code, 0) << a.run.err;
    EXPECT_EQ(a.hits(), 0u);
    EXPECT_EQ(a.misses(), inputs_);
    EXPECT_GT(a.cache().at("bytes_stored").get<uint64_t>(), 0u);
    EXPECT_FALSE(a.cache().contains("trouble")) << a.cache().dump();
    expect_local_bytes(dir_ / "outA");
  }
  /// Cooks clone2 from `cache` (machine B): nothing cooked, every output a verified hit.
  void expect_all_hits(const std::string& cache, const fs::path& out) {
    const Cook b = cook(dir_ / "clone2", out, "--cache " + cache);
    ASSERT_EQ(b.run.exit_code, 0) << b.run.err;
    EXPECT_EQ(b.hits(), inputs_) << b.cache().dump();
    EXPECT_EQ(b.misses(), 0u);
    EXPECT_EQ(b.cache().at("bytes_stored").get<uint64_t>(), 0u);
    for (const json& r : b.report.at("records")) EXPECT_TRUE(r.at("cache_hit").get<bool>()) << r.at("input");
    EXPECT_NE(b.run.out.find("cache_hit"), std::string::npos);
    expect_local_bytes(out);
  }
  /// A cook of clone2 that must succeed with local bytes whatever the cache does; returns it.
  Cook survive(const std::string& cache, const fs::path& out, const std::string& extra = "", unsigned jobs = 2) {
    Cook c = cook(dir_ / "clone2", out, "--cache " + cache + " " + extra, jobs);
    EXPECT_EQ(c.run.exit_code, 0) << c.run.err;
    expect_local_bytes(out);
    return c;
  }

  fs::path dir_;
  std::map<std::string, std::vector<uint8_t>> local_;
  size_t inputs_ = 0;
};

// ---------------------------------------------------------------------------------------------
// Servers

uint16_t free_port() {
  const int s = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ::bind(s, reinterpret_cast<sockaddr*>(&a), sizeof a);
  socklen_t len = sizeof a;
  ::getsockname(s, reinterpret_cast<sockaddr*>(&a), &len);
  ::close(s);
  return ntohs(a.sin_port);
}

bool listening(uint16_t port) {
  const int s = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = htons(port);
  const bool ok = ::connect(s, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
  ::close(s);
  return ok;
}

void stop_pid(pid_t pid) {
  if (pid <= 0) return;
  ::kill(pid, SIGTERM);
  for (int i = 0; i < 100 && ::kill(pid, 0) == 0; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  ::kill(pid, SIGKILL);
}

/// nginx serving a WebDAV folder on a free loopback port, everything it writes under `dir`.
struct Nginx {
  fs::path dir;
  uint16_t port = 0;
  std::string why_not;  // set when nginx cannot be run here
  std::string url() const { return "http://127.0.0.1:" + std::to_string(port); }

  explicit Nginx(const fs::path& d) : dir(d) {
    std::string exe;
    for (const char* c : {"/usr/sbin/nginx", "/usr/bin/nginx"})
      if (fs::exists(c)) exe = c;
    if (exe.empty()) {
      why_not = "nginx is not installed (Debian: nginx-light, which has the WebDAV module)";
      return;
    }
    if (run_command(exe + " -V 2>&1 | grep -q http_dav_module").exit_code != 0) {
      why_not = exe + " has no WebDAV module (ngx_http_dav_module)";
      return;
    }
    fs::create_directories(dir / "data");
    std::string user;  // a master started as root hands the workers to another user: keep ours
    if (::geteuid() == 0) {
      const passwd* pw = ::getpwuid(::geteuid());
      const group* gr = ::getgrgid(::getegid());
      if (pw != nullptr && gr != nullptr) user = std::string("user ") + pw->pw_name + " " + gr->gr_name + ";\n";
    }
    for (int attempt = 0; attempt < 3 && port == 0; ++attempt) {
      const uint16_t p = free_port();
      const std::string conf =
          user + "worker_processes 1;\npid " + (dir / "nginx.pid").string() + ";\nerror_log " +
          (dir / "error.log").string() +
          ";\nevents { worker_connections 256; }\nhttp {\n access_log off;\n"
          " client_body_temp_path " +
          (dir / "body").string() +
          ";\n"
          " server {\n  listen 127.0.0.1:" +
          std::to_string(p) + ";\n  root " + (dir / "data").string() +
          ";\n  client_max_body_size 0;\n"
          "  location / { dav_methods PUT; create_full_put_path on; dav_access user:rw; }\n }\n}\n";
      ossa::test::write_file(dir / "nginx.conf", conf);
      const auto r =
          run_command(exe + " -p " + q(dir) + " -e " + q(dir / "error.log") + " -c " + q(dir / "nginx.conf"));
      if (r.exit_code != 0) {
        why_not = "nginx did not start: " + r.err;
        continue;
      }
      for (int i = 0; i < 100 && !listening(p); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
      if (listening(p)) port = p, why_not.clear();
    }
    if (port == 0 && why_not.empty()) why_not = "nginx did not listen";
  }
  void stop() {
    if (auto text = ossa::test::read_text(dir / "nginx.pid")) stop_pid(static_cast<pid_t>(std::stol(*text)));
    port = 0;
  }
  ~Nginx() { stop(); }
};

/// tests/support/cache_http_server.py in one of its modes.
struct PyServer {
  pid_t pid = 0;
  uint16_t port = 0;
  std::string url() const { return "http://127.0.0.1:" + std::to_string(port); }

  PyServer(const fs::path& dir, const std::string& args) {
    const fs::path port_file = dir / ("port-" + std::to_string(::getpid()) + "-" + std::to_string(free_port()));
    const auto r = run_command("python3 " + q(ossa::test::source_dir() / "tests" / "support" / "cache_http_server.py") +
                               " " + args + " --port-file " + q(port_file) + " </dev/null >/dev/null 2>&1 & echo $!");
    pid = static_cast<pid_t>(std::stol(r.out));
    for (int i = 0; i < 200 && !fs::exists(port_file); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    if (auto text = ossa::test::read_text(port_file)) port = static_cast<uint16_t>(std::stoi(*text));
  }
  ~PyServer() { stop_pid(pid); }
};

size_t count_lines_with(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// ---------------------------------------------------------------------------------------------
// A second clone cooks nothing

TEST_F(CookCache, FolderSecondCloneCooksNothingAndEditedInputsMiss) {
  const std::string cache = q(dir_ / "cache");
  populate(cache);
  expect_all_hits(cache, dir_ / "outB");

  // The second level of the key: an edited sidecar (read only once the source is known) misses
  // that input alone, and the cook's bytes are those of a local cook of the edited tree.
  auto text = *ossa::test::read_text(dir_ / "clone3" / "pab" / "walk.events.json");
  text.insert(text.find('{') + 1, "\n");
  ossa::test::write_file(dir_ / "clone3" / "pab" / "walk.events.json", text);
  const Cook ref = cook(dir_ / "clone3", dir_ / "ref3", "");
  ASSERT_EQ(ref.run.exit_code, 0);
  const Cook c = cook(dir_ / "clone3", dir_ / "out3", "--cache " + cache + " --cache-mode read");
  ASSERT_EQ(c.run.exit_code, 0) << c.run.err;
  EXPECT_EQ(c.misses(), 1u);
  EXPECT_EQ(c.hits(), inputs_ - 1);
  EXPECT_EQ(c.cache().at("bytes_stored").get<uint64_t>(), 0u);  // read mode stores nothing
  for (const json& r : c.report.at("records"))
    EXPECT_EQ(r.at("cache_hit").get<bool>(), r.at("input").get<std::string>().find("walk.fbx") == std::string::npos);
  EXPECT_TRUE(snapshot(dir_ / "out3") == snapshot(dir_ / "ref3"));
  // The environment sets it for a team; off turns it off.
  const auto env =
      run_command("OSSA_COOK_CACHE=" + cache + " " + (ossa::test::bin_dir() / "ossa-cook").string() + " " +
                  q(dir_ / "clone2") + " -o " + q(dir_ / "outEnv") + " --root " + q(dir_ / "clone2") + " 2>&1");
  EXPECT_EQ(env.exit_code, 0);
  EXPECT_NE(env.out.find(std::to_string(inputs_) + " hits, 0 misses"), std::string::npos) << env.out;
  expect_local_bytes(dir_ / "outEnv");
  const Cook off = cook(dir_ / "clone2", dir_ / "outOff", "--cache " + cache + " --cache-mode off");
  EXPECT_EQ(off.run.exit_code, 0);
  EXPECT_FALSE(off.report.contains("cache"));
}

TEST_F(CookCache, NginxSecondCloneCooksNothing) {
  Nginx nginx(dir_ / "nginx");
  if (!nginx.why_not.empty()) GTEST_SKIP() << nginx.why_not;
  populate(nginx.url());
  EXPECT_TRUE(fs::is_directory(dir_ / "nginx" / "data" / "ac"));
  EXPECT_TRUE(fs::is_directory(dir_ / "nginx" / "data" / "cas"));
  expect_all_hits(nginx.url(), dir_ / "outB");
}

// ---------------------------------------------------------------------------------------------
// Faults

TEST_F(CookCache, DamagedTruncatedForeignAndGarbageEntriesAreMisses) {
  const fs::path cache = dir_ / "cache";
  populate(q(cache));
  std::vector<fs::path> cas, ac;
  for (const auto& e : fs::directory_iterator(cache / "cas")) cas.push_back(e.path());
  for (const auto& e : fs::directory_iterator(cache / "ac")) ac.push_back(e.path());
  std::sort(cas.begin(), cas.end());
  std::sort(ac.begin(), ac.end());
  ASSERT_GE(cas.size(), 4u);
  ASSERT_GE(ac.size(), 3u);
  // One of each: a byte flipped deep inside (still verifies as a FlatBuffer), cut in half, another
  // output under this key, a manifest that is not one and another source's manifest under this key.
  auto flipped = *ossa::test::read_file(cas[0]);
  flipped[flipped.size() * 3 / 4] ^= 0x20;
  ossa::test::write_file(cas[0], flipped);
  auto cut = *ossa::test::read_file(cas[1]);
  cut.resize(cut.size() / 2);
  ossa::test::write_file(cas[1], cut);
  fs::copy_file(cas[3], cas[2], fs::copy_options::overwrite_existing);
  ossa::test::write_file(ac[0], std::string_view("not a manifest"));
  fs::copy_file(ac[2], ac[1], fs::copy_options::overwrite_existing);  // another source's manifest

  const Cook c = survive(q(cache), dir_ / "outB");
  // Three outputs of three inputs damaged, and two manifests (of any inputs).
  EXPECT_LE(c.hits(), inputs_ - 3);
  EXPECT_GE(c.misses(), 3u);
  EXPECT_GE(c.cache().at("inputs_with_trouble").get<size_t>(), 3u);
  EXPECT_EQ(count_lines_with(c.run.err, "cache trouble"), 1u) << c.run.err;
  // Read-write: the misses were cooked and stored again, so the next clone hits everything.
  expect_all_hits(q(cache), dir_ / "outC");
}

TEST_F(CookCache, ServerDownMidBatch) {
  const fs::path cache = dir_ / "cache";
  populate(q(cache));
  // The cache served over HTTP by a server that exits after its 3rd request: the first input hits
  // (manifest, output), the second loses its server half way.
  PyServer server(dir_, "store " + q(cache) + " --die-after 3");
  ASSERT_NE(server.port, 0);
  const Cook c = survive(server.url(), dir_ / "outB", "", 1);
  EXPECT_EQ(c.hits(), 1u);
  EXPECT_EQ(c.misses(), inputs_ - 1);
  EXPECT_TRUE(c.cache().contains("trouble"));
  // Down is said once, and the workers after it do not ask.
  EXPECT_EQ(count_lines_with(c.run.err, "cache trouble"), 1u) << c.run.err;
  EXPECT_EQ(c.cache().at("inputs_with_trouble").get<size_t>(), 1u);
}

TEST_F(CookCache, GarbageBodiesAreMisses) {
  PyServer server(dir_, "junk");
  ASSERT_NE(server.port, 0);
  const Cook c = survive(server.url(), dir_ / "outB");
  EXPECT_EQ(c.hits(), 0u);
  EXPECT_EQ(c.misses(), inputs_);
  EXPECT_NE(c.cache().at("trouble").get<std::string>().find("not a manifest"), std::string::npos);
}

TEST_F(CookCache, SlowServerTimesOutOnce) {
  PyServer server(dir_, "hang");
  ASSERT_NE(server.port, 0);
  const Cook c = survive(server.url(), dir_ / "outB", "--cache-timeout 1", 1);
  EXPECT_EQ(c.hits(), 0u);
  EXPECT_EQ(c.cache().at("inputs_with_trouble").get<size_t>(), 1u);  // down after the first
  EXPECT_NE(c.cache().at("trouble").get<std::string>().find("imeout"), std::string::npos) << c.cache().dump();
}

TEST_F(CookCache, DownServerNeverFailsACook) {
  const uint16_t port = free_port();  // nothing listens there
  const Cook c = survive("http://127.0.0.1:" + std::to_string(port), dir_ / "outB");
  EXPECT_EQ(c.hits(), 0u);
  EXPECT_TRUE(c.cache().contains("trouble"));
}

TEST_F(CookCache, FullCacheFolderCostsStoresNotCooks) {
  const fs::path cache = dir_ / "tiny";
  fs::create_directories(cache);
  if (::mount("tmpfs", cache.c_str(), "tmpfs", 0, "size=64k") != 0)
    GTEST_SKIP() << "cannot mount a 64 KiB tmpfs here to fill (needs CAP_SYS_ADMIN): " << std::strerror(errno);
  const Cook c = survive(q(cache), dir_ / "outB");
  ::umount(cache.c_str());
  EXPECT_NE(c.cache().at("trouble").get<std::string>().find("No space left"), std::string::npos) << c.cache().dump();
}

TEST_F(CookCache, WriteRefusingCacheFolderCostsStoresNotCooks) {
  const fs::path cache = dir_ / "refusing";
  fs::create_directories(cache);
  if (::geteuid() == 0) {
    // root writes through permissions: "ac" and "cas" are files, so no entry can be made.
    ossa::test::write_file(cache / "ac", std::string_view("x"));
    ossa::test::write_file(cache / "cas", std::string_view("x"));
  } else {
    fs::permissions(cache, fs::perms::owner_read | fs::perms::owner_exec);
  }
  const Cook c = survive(q(cache), dir_ / "outB");
  fs::permissions(cache, fs::perms::owner_all);
  EXPECT_EQ(c.hits(), 0u);
  EXPECT_TRUE(c.cache().contains("trouble"));
  EXPECT_EQ(c.cache().at("bytes_stored").get<uint64_t>(), 0u);
}

TEST_F(CookCache, TwoWritersAtOnce) {
  Nginx nginx(dir_ / "nginx");
  std::vector<std::string> caches = {q(dir_ / "cache")};
  if (nginx.why_not.empty()) caches.push_back(nginx.url());
  for (const std::string& cache : caches) {
    SCOPED_TRACE(cache);
    const std::string exe = (ossa::test::bin_dir() / "ossa-cook").string();
    fs::remove_all(dir_ / "w1");
    fs::remove_all(dir_ / "w2");
    const auto both = run_command(exe + " " + q(dir_ / "clone1") + " -o " + q(dir_ / "w1") + " --root " +
                                  q(dir_ / "clone1") + " --cache " + cache + " -q -j2 & " + exe + " " +
                                  q(dir_ / "clone3") + " -o " + q(dir_ / "w2") + " --root " + q(dir_ / "clone3") +
                                  " --cache " + cache + " -q -j2 & wait %1; a=$?; wait %2; b=$?; echo $a $b");
    EXPECT_EQ(both.out, "0 0\n") << both.err;
    expect_local_bytes(dir_ / "w1");
    expect_local_bytes(dir_ / "w2");
    fs::remove_all(dir_ / "outB");
    expect_all_hits(cache, dir_ / "outB");
  }
  if (!nginx.why_not.empty()) GTEST_SKIP() << "the folder passed; over HTTP not run: " << nginx.why_not;
}

}  // namespace
