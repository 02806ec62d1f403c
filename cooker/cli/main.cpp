// main.cpp — the ossa-cook command line: parse options, plan, cook in parallel, report.
// Inputs are sources (FBX, glTF, ...) and animation graph files (`*.graph.json`, docs/GRAPH.md).
//
//   ossa-cook INPUT... -o OUTDIR [--root DIR] [--jobs N] [--max-memory SIZE] [--timeout SECONDS]
//             [--report FILE.json] [--skeleton REF.ossa] [--retarget-to TARGET.ossa [--map MAP.json]]
//             [--float-vertices] [--clip-tolerance MM]
//             [--no-clip-compression] [--root-motion] [--up-axis x|y|z] [--metres-per-unit M] [--force] [--depfile
//             FILE]
//             [--list-inputs] [--cache DIR|URL [--cache-mode read|readwrite|off] [--cache-timeout S]]
//             [-q | -v] [--version] [--help]
//
// As a build step (docs/SCALE.md): an output whose cook key matches its inputs as they are now is
// up to date and left alone (--force cooks anyway); --depfile writes a Make-syntax file naming
// every file each output's cook read; --list-inputs prints those files without writing anything.
// --cache (or OSSA_COOK_CACHE) shares outputs through a folder or an HTTP cache: the batch looks
// each input up before starting its worker, and a worker stores what it cooked
// (cooker/cache/cook_cache.h).
//
// Each input is cooked in a worker process of its own, up to --jobs at once (cooker/cli/worker.h):
// an input that crashes or aborts the importer, runs past --timeout (default 600 s) or past
// --max-memory (default 0.8 x memory / workers, at least 1 GiB) fails alone, named with the cause.
// This process must stay single-threaded: it forks the workers.
//
// Exit status (tools/cli/cli.h): 0 when every input cooked; 1 when any failed (the rest
// are still cooked) or the report or the depfile could not be written; 2 for a usage error or a plan that cannot
// be carried out (nothing is written then).
//
// Output: failures always (stderr). Without -q, a progress line per input and the number of
// warnings (stderr) and a table of what was cooked (stdout). -v adds the options in effect, every
// input's warnings, time and sizes, one line per clip (frames, error, ratio) and the total time.
// Warnings are not printed one by one by default: importing the samples alone gives dozens of
// lines (dropped cameras, matched joint names) that would bury the failures. The --report document is
// docs/schemas/ossa-cook-report.schema.json (docs/JSON.md).
#include <signal.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "cooker/cache/cook_cache.h"
#include "cooker/cli/batch.h"
#include "cooker/cli/worker.h"
#include "cooker/cook.h"
#include "cooker/texture/texture_cook.h"
#include "common/message.h"
#include "tools/cli/cli.h"

namespace fs = std::filesystem;
using namespace ossa::cook;

namespace {

std::string human_bytes(uint64_t n) {
  char buf[32];
  if (n >= 1u << 20) std::snprintf(buf, sizeof buf, "%.2f MiB", static_cast<double>(n) / (1 << 20));
  else if (n >= 1u << 10) std::snprintf(buf, sizeof buf, "%.1f KiB", static_cast<double>(n) / (1 << 10));
  else std::snprintf(buf, sizeof buf, "%llu B", static_cast<unsigned long long>(n));
  return buf;
}

/// The end-of-batch table: the output column is as wide as the longest output path, so the
/// number columns stay aligned whatever the tree's depth.
/// Text from a record as it may reach a terminal: each line's control bytes (an escape sequence in
/// a file name) and invalid UTF-8 shown as \xNN, and each line cut at 2000 characters (a source
/// can make names megabytes long). Line breaks stay: a graph's errors are one per line.
std::string shown(const std::string& text) {
  std::string out;
  size_t start = 0;
  while (true) {
    const size_t end = text.find('\n', start);
    out += ossa::detail::printable(std::string_view(text).substr(start, end - start), 2000);
    if (end == std::string::npos) break;
    out += '\n';
    start = end + 1;
  }
  return out;
}

/// "[12/40, 1 failed, ETA 0:08]": done of total, failures so far, and the time left at the mean
/// pace so far (inputs finish out of order with --jobs, so the mean is the honest estimate).
std::string progress_head(size_t done, size_t total, size_t failed, double elapsed) {
  std::string s = "[" + std::to_string(done) + "/" + std::to_string(total);
  if (failed > 0) s += ", " + std::to_string(failed) + " failed";
  if (done > 0 && done < total) {
    const auto left =
        static_cast<long long>(elapsed / static_cast<double>(done) * static_cast<double>(total - done) + 0.5);
    char eta[32];
    std::snprintf(eta, sizeof eta, ", ETA %lld:%02lld", left / 60, left % 60);
    s += eta;
  }
  return s + "]";
}

size_t terminal_columns() {
  winsize w{};
  if (::ioctl(STDERR_FILENO, TIOCGWINSZ, &w) == 0 && w.ws_col >= 20) return w.ws_col;
  return 80;
}

/// `text` cut to `width` characters by dropping its start ("...tail"): the file name stays.
std::string fit(const std::string& text, size_t width) {
  width = std::max<size_t>(width, 8);
  if (text.size() <= width) return text;
  return "..." + text.substr(text.size() - (width - 3));
}

void print_summary(const std::vector<CookRecord>& records) {
  int width = 6;
  for (const CookRecord& r : records)
    if (r.ok) width = std::max(width, static_cast<int>(shown(r.output).size()));
  std::printf("%-*s %7s %7s %9s %6s %12s %12s  %s\n", width, "output", "joints", "meshes", "vertices", "clips",
              "source", "cooked", "status");
  for (const CookRecord& r : records) {
    if (!r.ok) continue;
    std::printf("%-*s %7u %7u %9u %6u %12s %12s  %s\n", width, shown(r.output).c_str(), r.joints.value_or(0),
                r.meshes.value_or(0), r.vertices.value_or(0), r.clips.value_or(0), human_bytes(r.source_bytes).c_str(),
                human_bytes(r.cooked_bytes).c_str(),
                r.up_to_date  ? "up to date"
                : r.cache_hit ? "cache_hit"
                              : "cooked");
  }
}

/// -v: what one input took and what compression achieved on each of its clips.
void print_details(const CookRecord& r) {
  std::fprintf(stderr, "  %s: %.1f ms, source %s", shown(r.input).c_str(), r.seconds * 1e3,
               human_bytes(r.source_bytes).c_str());
  if (r.ok) std::fprintf(stderr, ", cooked %s", human_bytes(r.cooked_bytes).c_str());
  std::fprintf(stderr, "\n");
  for (const MorphRecord& m : r.morph_records)
    std::fprintf(stderr,
                 "    morph target '%s' of mesh '%s': %u vertices, error %.4f mm (bound %.4f) / %.3f deg, "
                 "%u -> %u bytes (%.1f:1)\n",
                 shown(m.name).c_str(), shown(m.mesh).c_str(), m.vertices, static_cast<double>(m.position_error_mm),
                 static_cast<double>(m.position_bound_mm), static_cast<double>(m.normal_error_deg), m.raw_bytes,
                 m.stored_bytes, m.stored_bytes > 0 ? static_cast<double>(m.raw_bytes) / m.stored_bytes : 0.0);
  for (const TextureRecord& t : r.texture_records) {
    std::fprintf(stderr,
                 "    texture '%s' (%s): %u x %u, %s%s, %u mips, %s -> %s (decoded RGBA8 + mips: %s), PSNR %.1f dB",
                 shown(t.name).c_str(), t.role.c_str(), t.width, t.height, t.encoding.c_str(), t.srgb ? " sRGB" : "",
                 t.mips, human_bytes(t.source_bytes).c_str(), human_bytes(t.cooked_bytes).c_str(),
                 human_bytes(t.gpu_rgba8_bytes).c_str(), static_cast<double>(t.psnr_db));
    if (t.role == "normal")
      std::fprintf(stderr, ", normals off by %.2f deg mean, %.2f max", static_cast<double>(t.normal_mean_deg),
                   static_cast<double>(t.normal_max_deg));
    std::fprintf(stderr, "\n");
  }
  for (const RetargetRecord& t : r.retarget_records) {
    std::fprintf(stderr,
                 "    retarget '%s': %u frames, hips ratio %.3f, limbs within %.2f deg, hands %.2f, feet %.2f, "
                 "%u frames crossing, %u guarded (limbs %.2f deg), %zu contacts",
                 shown(t.clip).c_str(), t.frames, static_cast<double>(t.hips_ratio),
                 static_cast<double>(t.limb_max_deg), static_cast<double>(t.hand_max_deg),
                 static_cast<double>(t.foot_max_deg), t.crossing_frames, t.guarded_frames,
                 static_cast<double>(t.guard_max_deg), t.contacts.size());
    float held = 0.0f, slide = 0.0f, source = 0.0f;
    for (const RetargetContactRecord& c : t.contacts)
      held = std::max(held, c.held_mm), slide = std::max(slide, c.slide_mm),
      source = std::max(source, c.source_slide_mm);
    if (!t.contacts.empty())
      std::fprintf(stderr, " (held within %.2f mm; feet slide up to %.2f mm, the source's %.2f mm)",
                   static_cast<double>(held), static_cast<double>(slide), static_cast<double>(source));
    std::fprintf(stderr, "\n");
  }
  for (const ClipRecord& c : r.clip_records)
    std::fprintf(
        stderr,
        "    clip '%s': %u frames, %u joints, max error %.4f mm (mean %.4f mm, at '%s'), %u -> %u bytes (%.1f:1)\n",
        shown(c.name).c_str(), c.frames, c.joints, static_cast<double>(c.max_error_mm),
        static_cast<double>(c.mean_error_mm), shown(c.worst_joint).c_str(), c.raw_bytes, c.cooked_bytes,
        c.cooked_bytes > 0 ? static_cast<double>(c.raw_bytes) / c.cooked_bytes : 0.0);
}

}  // namespace

int main(int argc, char** argv) {
  const auto start = std::chrono::steady_clock::now();
  // A file-size limit (ulimit -f) reached while writing is a write error to report with the input
  // it concerns, like a full disk, not a signal that ends the process (workers inherit this).
  ::signal(SIGXFSZ, SIG_IGN);
  ossa::cli::Command command("ossa-cook",
                             "ossa-cook: cook FBX / glTF / GLB / Collada / BVH sources and animation graph files "
                             "(*.graph.json) into .ossa files",
                             "when any input failed to cook (the others are still cooked)");
  CLI::App& app = command.app();
  std::vector<std::string> inputs;
  std::string out_dir, root, report_path, skeleton_path;
  unsigned jobs = std::max(1u, std::thread::hardware_concurrency());
  std::string max_memory_text;
  unsigned timeout_seconds = 600;
  bool float_vertices = false, lossless_clips = false, root_motion = false, force = false, list_inputs = false;
  std::string depfile_path;
  double clip_tolerance_mm = 0.1;
  double metres_per_unit = 0.0;
  std::string up_axis;
  app.add_option("inputs", inputs,
                 "source files (X.fbx -> X.ossa; sources of one folder that share a stem keep their extension: "
                 "X.fbx -> X.fbx.ossa beside X.dae -> X.dae.ossa), graph files (X.graph.json -> X.ossa) or "
                 "directories (searched recursively)")
      ->required();
  app.add_option("-o,--output", out_dir, "output directory")->required();
  app.add_option("--root", root,
                 "mirror inputs' paths relative to this directory under the output directory; cooks may read only "
                 "files inside it (without --root: inside the directory argument, or a file input's own folder)");
  std::vector<std::string> allow_dirs;
  app.add_option("--allow-dir", allow_dirs,
                 "also let cooks read files inside this directory (repeatable), e.g. a shared texture library")
      ->allow_extra_args(false);  // one directory per --allow-dir: the inputs that follow stay inputs
  bool allow_hard_links = false;
  app.add_flag("--allow-hard-links", allow_hard_links,
               "read files that have more than one hard link (refused by default: another name for the same "
               "bytes may lie outside the folders a cook may read)");
  app.add_option("-j,--jobs", jobs, "cook this many files in parallel, each in a worker process of its own")
      ->check(CLI::Range(1u, 256u));
  CLI::Option* max_memory_option =
      app.add_option("--max-memory", max_memory_text,
                     "address space one input may use, e.g. 512M, 4G, 1.5GiB or bytes (K/M/G/T are powers of 1024; "
                     "0: no limit); past it the input fails alone (default: 0.8 x physical memory, or the cgroup's "
                     "limit if lower, / the number of workers (--jobs, or the inputs if fewer), at least 1 GiB)");
  app.add_option("--timeout", timeout_seconds,
                 "seconds one input may take; past it its worker is killed and the input fails alone "
                 "(default 600; 0: no limit)");
  app.add_option("--report", report_path, "write a JSON record per input to this file (docs/JSON.md)");
  app.add_option("--skeleton", skeleton_path, "cook clip-only files against this cooked skeleton (.ossa)");
  std::string retarget_path, map_path;
  app.add_option("--retarget-to", retarget_path,
                 "retarget the inputs' clips onto this cooked humanoid rig (.ossa) and cook them as its clips; the "
                 "clips play on their own rig, or on --skeleton's for clip-only files (docs/RETARGET.md)");
  app.add_option("--map", map_path,
                 "a humanoid map file naming which joints play which humanoid bones, for rigs whose names do not say "
                 "(with --retarget-to; docs/RETARGET.md)");
  app.add_flag("--float-vertices", float_vertices, "store vertices as float32 instead of quantized");
  std::string texture_format = "bc";
  app.add_option("--texture-format", texture_format,
                 "textures as GPU-ready mip chains, block-compressed by role (bc: BC1/BC3 colour in sRGB, BC5 "
                 "normal maps, BC4 grey maps; the default), uncompressed mip chains (rgba8), or the source's "
                 "PNG/JPEG bytes as read (source)")
      ->check(CLI::IsMember({"bc", "rgba8", "source"}));
  app.add_option("--clip-tolerance", clip_tolerance_mm,
                 "largest model-space error of any joint, in millimetres at 10 cm from it (default 0.1)")
      ->check(CLI::Range(1e-6, 1e4));
  app.add_flag("--no-clip-compression", lossless_clips, "keep every clip key exact (raw floats at every frame)");
  app.add_flag("--root-motion", root_motion, "extract root translation and yaw from clips into a root-motion track");
  app.add_option("--up-axis", up_axis,
                 "the sources' up axis, over what each file states (FBX UpAxis, Collada <up_axis>) or its format's "
                 "convention (SMD: z); every output is Y-up")
      ->check(CLI::IsMember({"x", "y", "z"}));
  app.add_option("--metres-per-unit", metres_per_unit,
                 "length of one source unit in metres, for sources that state none (BVH: 1 assumed) or state it "
                 "wrongly; clips cooked with --skeleton are converted into the rig's unit")
      ->check(CLI::Range(1e-6, 1e6));
  app.add_flag("--force", force, "cook every input, even those whose output is up to date");
  app.add_option("--depfile", depfile_path,
                 "write a Make-syntax depfile: each output and every file its cook read (for Ninja / CMake DEPFILE)");
  app.add_flag("--list-inputs", list_inputs,
               "print every file the cooks read (one per line, sorted) and write no output; up-to-date outputs "
               "answer from their provenance");
  std::string cache_location, cache_mode_text;
  unsigned cache_timeout = 10;
  app.add_option("--cache", cache_location,
                 "a shared cook cache: a folder, or the URL of an HTTP cache speaking Bazel's remote-cache protocol "
                 "(nginx with WebDAV, bazel-remote); outputs found there are not cooked, outputs cooked are stored "
                 "(default: $OSSA_COOK_CACHE; docs/SCALE.md)");
  app.add_option("--cache-mode", cache_mode_text,
                 "read: look up only (developers' machines); readwrite: also store (CI); off (default: "
                 "$OSSA_COOK_CACHE_MODE, else readwrite)")
      ->check(CLI::IsMember({"read", "readwrite", "off"}));
  app.add_option("--cache-timeout", cache_timeout,
                 "seconds one request to an HTTP cache may take before it counts as a miss (default 10)")
      ->check(CLI::Range(1u, 3600u));
  if (const auto exit_now = command.parse(argc, argv)) return *exit_now;
  const bool quiet = command.quiet(), verbose = command.verbose();
  std::optional<uint64_t> max_memory;
  if (max_memory_option->count() > 0) {
    max_memory = parse_size(max_memory_text);
    if (!max_memory)
      return command.usage_error("--max-memory: '" + max_memory_text +
                                 "' is not a size (bytes, or a number followed by K, M, G or T)");
  }

  CookOptions options;
  options.float_vertices = float_vertices;
  options.textures = *parse_texture_output(texture_format);
  options.clips.enabled = !lossless_clips;
  options.clips.tolerance_metres = static_cast<float>(clip_tolerance_mm / 1000.0);
  options.root_motion = root_motion;
  options.up_axis = up_axis.empty() ? -1 : up_axis == "x" ? 0 : up_axis == "z" ? 2 : 1;
  options.metres_per_unit = static_cast<float>(metres_per_unit);
  options.force = force;
  options.root = root;
  for (const std::string& d : allow_dirs) {
    std::error_code ec;
    if (!fs::is_directory(d, ec)) {
      std::fprintf(stderr, "ossa-cook: --allow-dir %s: not a directory\n", d.c_str());
      return ossa::cli::kExitUsage;
    }
    options.allow_dirs.emplace_back(d);
  }
  options.write = !list_inputs;
  // The cache: set once for a team through the environment, or per run on the command line.
  if (cache_location.empty())
    if (const char* env = std::getenv("OSSA_COOK_CACHE"); env != nullptr) cache_location = env;
  if (cache_mode_text.empty())
    if (const char* env = std::getenv("OSSA_COOK_CACHE_MODE"); env != nullptr && *env != '\0') cache_mode_text = env;
  CookCache cache;
  if (!cache_mode_text.empty()) {
    const std::optional<CacheMode> mode = parse_cache_mode(cache_mode_text);
    if (!mode)
      return command.usage_error("OSSA_COOK_CACHE_MODE: '" + cache_mode_text + "' is not read, readwrite or off");
    cache.mode = *mode;
  }
  if (!cache_location.empty() && cache.mode != CacheMode::Off && !list_inputs) {
    auto store = open_cache_store(cache_location, cache_timeout);
    if (!store) {
      std::fprintf(stderr, "ossa-cook: %s\n", store.error().message.c_str());
      return ossa::cli::kExitUsage;
    }
    cache.store = std::move(*store);
    options.cache = &cache;
  }
  options.allow_hard_links = allow_hard_links;
  SourceSkeleton reference;
  if (!skeleton_path.empty()) {
    auto loaded = load_reference_skeleton(skeleton_path, &options.reference_input);
    if (!loaded) {
      std::fprintf(stderr, "ossa-cook: --skeleton %s\n", loaded.error().message.c_str());
      return ossa::cli::kExitUsage;
    }
    reference = std::move(*loaded);
    options.reference = &reference;
    options.reference_name = fs::path(skeleton_path).filename().string();
  }

  SourceSkeleton retarget_target;
  ossa::tools::HumanoidMapFile map_file;
  if (!map_path.empty() && retarget_path.empty())
    return command.usage_error(
        "--map is read with --retarget-to (ossa-inspect --humanoid --map shows a rig's mapping)");
  if (!retarget_path.empty()) {
    auto loaded = load_reference_skeleton(retarget_path, &options.retarget_input);
    if (!loaded) {
      std::fprintf(stderr, "ossa-cook: --retarget-to %s\n", loaded.error().message.c_str());
      return ossa::cli::kExitUsage;
    }
    retarget_target = std::move(*loaded);
    options.retarget_target = &retarget_target;
    options.retarget_name = fs::path(retarget_path).filename().string();
  }
  if (!map_path.empty()) {
    auto parsed = load_humanoid_map_file(map_path, &options.retarget_map_input);
    if (!parsed) {
      std::fprintf(stderr, "ossa-cook: --map %s\n", parsed.error().message.c_str());
      return ossa::cli::kExitUsage;
    }
    map_file = std::move(*parsed);
    options.retarget_map = &map_file;
    options.retarget_map_name = fs::path(map_path).filename().string();
  }

  std::vector<fs::path> input_paths(inputs.begin(), inputs.end());
  auto plan = plan_batch(input_paths, out_dir, root);
  if (!plan) {
    std::fprintf(stderr, "ossa-cook: %s\n", plan.error().message.c_str());
    return ossa::cli::kExitUsage;
  }
  if (plan->empty()) {
    std::fprintf(stderr, "ossa-cook: no source files found in the inputs given\n");
    return ossa::cli::kExitUsage;
  }
  // Without a rig for the whole batch, clip-only sources bind to their folder's rig (batch.h).
  if (options.reference == nullptr && options.retarget_target == nullptr) assign_folder_rigs(*plan);
  BatchLimits limits;
  limits.timeout_seconds = timeout_seconds;
  // The default share is of the workers that will run: no more than there are inputs.
  limits.max_memory_bytes =
      max_memory ? *max_memory : default_max_memory(static_cast<unsigned>(std::min<size_t>(jobs, plan->size())));
  if (verbose)
    std::fprintf(stderr, "ossa-cook: %zu inputs, %u jobs, options %s, limits per input: memory %s%s, time %s\n",
                 plan->size(), jobs, options.canonical().c_str(),
                 limits.max_memory_bytes > 0 ? format_size(limits.max_memory_bytes).c_str() : "unlimited",
                 limits.max_memory_bytes > 0 && !memory_limit_enforced() ? " (not enforced in a sanitizer build)" : "",
                 limits.timeout_seconds > 0 ? (std::to_string(limits.timeout_seconds) + " s").c_str() : "unlimited");

  // -v writes a block per input, which a progress line rewritten in place would tear.
  const bool tty = ::isatty(STDERR_FILENO) != 0 && !verbose;
  size_t warnings = 0;  // progress calls are serialized by the batch
  size_t failed_so_far = 0;
  const auto batch_start = std::chrono::steady_clock::now();
  auto progress = [&](size_t done, size_t total, const CookRecord& r) {
    warnings += r.warnings.size();
    failed_so_far += r.ok ? 0 : 1;
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - batch_start).count();
    const std::string head = progress_head(done, total, failed_so_far, elapsed);
    if (!r.ok) {
      std::fprintf(stderr, "%s%s FAILED %s\n", tty ? "\r\033[K" : "", head.c_str(), shown(r.error).c_str());
    } else if (!quiet && !list_inputs) {
      const char* what = r.up_to_date ? " (up to date)" : r.cache_hit ? " (cache hit)" : "";
      if (tty)  // one line rewritten in place: it must not wrap, so a long path keeps its tail
        std::fprintf(stderr, "\r\033[K%s %s%s", head.c_str(),
                     fit(shown(r.input), terminal_columns() - head.size() - std::strlen(what) - 2).c_str(), what);
      else std::fprintf(stderr, "%s %s -> %s%s\n", head.c_str(), shown(r.input).c_str(), shown(r.output).c_str(), what);
    }
    if (verbose) {
      for (const std::string& w : r.warnings)
        std::fprintf(stderr, "warning: %s: %s\n", shown(r.input).c_str(), shown(w).c_str());
      print_details(r);
    }
    if (tty && done == total && !quiet) std::fprintf(stderr, "\n");
    std::fflush(stderr);
  };
  // Folder rigs others bind to cook first, the rest after them; records keep the plan's order.
  std::vector<BatchItem> first, then;
  std::vector<size_t> first_at, then_at;
  {
    std::set<fs::path> rigs;
    for (const BatchItem& item : *plan)
      if (!item.rig.empty()) rigs.insert(item.rig);
    for (size_t i = 0; i < plan->size(); ++i) {
      const bool is_rig = rigs.count((*plan)[i].output) > 0;
      (is_rig ? first : then).push_back((*plan)[i]);
      (is_rig ? first_at : then_at).push_back(i);
    }
  }
  std::vector<CookRecord> records(plan->size());
  size_t done_before = 0;
  for (const auto& [part, at] : {std::pair{&first, &first_at}, std::pair{&then, &then_at}}) {
    if (part->empty()) continue;
    const auto part_progress = [&](size_t done, size_t, const CookRecord& r) {
      progress(done_before + done, plan->size(), r);
    };
    std::vector<CookRecord> got = run_batch(*part, options, limits, jobs, part_progress);
    for (size_t k = 0; k < got.size(); ++k) records[(*at)[k]] = std::move(got[k]);
    done_before += part->size();
  }
  {
    std::vector<fs::path> own;
    for (const std::string& p : {report_path, depfile_path})
      if (!p.empty()) own.emplace_back(p);
    remove_stale_temporaries(own);
  }

  size_t failed = 0;
  for (const CookRecord& r : records) failed += r.ok ? 0 : 1;
  // The report and the depfile are written whatever happens to the other: a build tool relies on
  // the depfile even when the report's folder is read-only, and each failure is said.
  bool written = true;
  if (!report_path.empty()) {
    const std::string text = report_json(records, options, limits).dump(2) + "\n";
    if (ossa::Status st = write_file_atomic(report_path, std::vector<uint8_t>(text.begin(), text.end())); !st) {
      std::fprintf(stderr, "ossa-cook: report: %s\n", shown(st.message()).c_str());
      written = false;
    }
  }
  if (list_inputs) {
    // One sorted, de-duplicated list: what a build system declares as the step's inputs.
    std::set<std::string> files;
    for (const CookRecord& r : records)
      for (const InputFile& f : r.inputs_read)
        if (f.present) files.insert(f.path);
    for (const std::string& f : files) std::printf("%s\n", f.c_str());
  }
  if (!depfile_path.empty()) {
    if (ossa::Status st = write_depfile(depfile_path, records); !st) {
      std::fprintf(stderr, "ossa-cook: depfile %s\n", shown(st.message()).c_str());
      written = false;
    }
  }
  if (!quiet && !list_inputs) print_summary(records);
  if (options.cache != nullptr) {
    // Said once: the totals, and the cache's first trouble (each such input cooked as a miss).
    const CacheTotals t = cache_totals(records);
    if (!quiet)
      std::fprintf(stderr, "ossa-cook: cache %s (%s): %zu hits, %zu misses, %s fetched, %s stored\n",
                   shown(cache.store->name()).c_str(), cache_mode_name(cache.mode), t.hits, t.misses,
                   human_bytes(t.bytes_fetched).c_str(), human_bytes(t.bytes_stored).c_str());
    if (t.troubled > 0)
      std::fprintf(stderr, "ossa-cook: cache trouble (%zu input%s cooked without it): %s\n", t.troubled,
                   t.troubled == 1 ? "" : "s", shown(t.first_trouble).c_str());
  }
  if (!quiet && !verbose && warnings > 0)
    std::fprintf(stderr, "ossa-cook: %zu warning%s (-v prints them; --report records them)\n", warnings,
                 warnings == 1 ? "" : "s");
  if (verbose)
    std::fprintf(stderr, "ossa-cook: %zu inputs in %.0f ms\n", records.size(),
                 std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  if (failed > 0) {
    std::fprintf(stderr, "ossa-cook: %zu of %zu inputs failed:\n", failed, records.size());
    for (const CookRecord& r : records) {
      if (r.ok) continue;
      std::string indented = shown(r.error);  // graph files report one problem per line
      for (size_t at = indented.find('\n'); at != std::string::npos; at = indented.find('\n', at + 3))
        indented.replace(at, 1, "\n  ");
      std::fprintf(stderr, "  %s\n", indented.c_str());
    }
    return ossa::cli::kExitFailed;
  }
  return written ? ossa::cli::kExitOk : ossa::cli::kExitFailed;
}
