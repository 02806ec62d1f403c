// bench_graph.cpp — ossa-bench-graph: how many characters can play the Pab sample graph per frame.
//
//   ossa-bench-graph [--file CHARACTER.ossa --graph NAME] [--frames N] [--repeat N] [--characters N]
//                    [--clone baseline|avx2|avx512]   (bench/machine.h)
//
// Without --file it cooks assets/Pab/pab.graph.json (the sample graph: a walk/jog/run blend space,
// a sprint state, a standing pose, crossed arms layered on the upper body, every transition mode)
// with the real cooker into a temporary directory. Then for 1, 100 and 1000 characters, each with
// its own GraphInstance, pre-rolled to a different time and driven by its own deterministic
// schedule of parameter changes (speed every ~0.5 s, crossed arms every ~2 s, the stop trigger now
// and then, so transitions of every kind keep happening), it times whole 60 Hz frames:
//   - one thread updating every character;
//   - two threads, each updating half the characters, meeting at a barrier every frame (how a game
//     runs its animation jobs).
// Frames are timed back to back, best of --repeat repetitions (default 5: these virtual machines
// share memory bandwidth with neighbours, so single runs of the 1000-character rows vary by 2x;
// the best run is the one least disturbed). The sample's procedural nodes (look-at, foot placement,
// foot locking) are off in those rows: they are the plain locomotion graph. Further rows, at 1000
// characters on two threads, turn them on one by one (uneven ground re-drawn every second per
// character, a look target circling), and play the Fox sample with its tail spring off and on.
// Each row also says the CPU time per character and frame, all threads together (std::clock): on
// a machine whose other jobs take the cores away, wall time says how long the frame took and CPU
// time what the characters cost; 2 x 16,667 / cpu_us is what two threads of their own would fit.
// A row plays the sample's upper-body montage (cross_arms, looping in its loop section) on every
// character next to the same graph without it; `montage_cost_percent_of_frame` is how much of a
// frame the montages take at the count that fits without them (characters without / with - 1).
// The last line reads `characters_per_frame_2_threads: N`, N from 1000 characters on two threads
// of the plain graph: how many characters fit in a 16.7 ms frame.
#include <algorithm>
#include <cmath>
#include <unistd.h>

#include <barrier>
#include <chrono>
#include <ctime>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "cooker/cook.h"
#include <ossa/graph/graph.h>
#include "bench/machine.h"

namespace fs = std::filesystem;
using namespace ossa;

namespace {

constexpr float kDt = 1.0f / 60.0f;
constexpr double kFrameMicros = 1e6 / 60.0;

/// One character: its instance and its own parameter schedule.
struct Character {
  std::unique_ptr<GraphInstance> instance;
  std::mt19937 rng;
  int frame = 0;
};

struct Params {
  int speed = -1, crossed = -1, stop = -1;
  std::vector<std::pair<int, float>> fixed;  // float parameters set once per character (procedural weights)
  int ground_left = -1, ground_right = -1;   // varied per character when >= 0 (uneven ground)
  int look = -1;                             // a look-at target moved every frame when >= 0
  int montage = -1;                          // a montage every character plays (and keeps looping) when >= 0
};

void drive(Character& c, const Params& p, GraphScratch& scratch) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  // Offsets by the character's own draw keep characters out of lockstep.
  if (c.frame % 30 == 0 && p.speed >= 0) c.instance->set_float(p.speed, 6.0f * u(c.rng));
  if (c.frame % 120 == 0 && p.crossed >= 0) c.instance->set_bool(p.crossed, u(c.rng) < 0.5f);
  if (c.frame % 200 == 0 && p.stop >= 0 && u(c.rng) < 0.3f) c.instance->set_trigger(p.stop);
  if (c.frame % 60 == 0 && p.ground_left >= 0) {
    c.instance->set_float(p.ground_left, 16.0f * u(c.rng) - 8.0f);
    c.instance->set_float(p.ground_right, 16.0f * u(c.rng) - 8.0f);
  }
  if (p.look >= 0) {
    const float a = 0.05f * static_cast<float>(c.frame);
    c.instance->set_vector(p.look, glm::vec3(120.0f * std::sin(a), 160.0f, 150.0f + 60.0f * std::cos(a)));
  }
  c.instance->update(kDt, scratch);
  ++c.frame;
}

std::vector<Character> make_characters(const GraphDefinition& def, const Params& p, size_t count) {
  std::vector<Character> out(count);
  GraphScratch scratch = GraphScratch::create(def);
  for (size_t i = 0; i < count; ++i) {
    auto inst = GraphInstance::create(def, 64, /*own_scratch=*/false);
    if (!inst) {
      std::fprintf(stderr, "ossa-bench-graph: %s\n", inst.error().message.c_str());
      std::exit(1);
    }
    out[i].instance = std::make_unique<GraphInstance>(std::move(*inst));
    for (const auto& [param, value] : p.fixed) out[i].instance->set_float(param, value);
    if (p.montage >= 0) out[i].instance->play_montage(p.montage);
    out[i].rng.seed(static_cast<uint32_t>(1000 + i));
    out[i].frame = static_cast<int>(i * 7 % 240);
    for (int pre = 0; pre < static_cast<int>(i % 90); ++pre) drive(out[i], p, scratch);  // pre-roll
  }
  return out;
}

/// Microseconds of process CPU time (every thread's) since `start`, a std::clock() reading.
double cpu_micros_since(std::clock_t start) { return 1e6 * static_cast<double>(std::clock() - start) / CLOCKS_PER_SEC; }

/// One scratch per thread: what a game's job system would keep per worker. Returns wall-clock
/// microseconds; *cpu gets the CPU microseconds all threads spent meanwhile (barrier waits too).
double time_frames(const GraphDefinition& def, std::vector<Character>& chars, const Params& p, int frames,
                   unsigned threads, double* cpu) {
  using clock = std::chrono::steady_clock;
  const std::clock_t cpu_start = std::clock();
  if (threads <= 1 || chars.size() < 2) {
    GraphScratch scratch = GraphScratch::create(def);
    const auto start = clock::now();
    for (int f = 0; f < frames; ++f)
      for (Character& c : chars) drive(c, p, scratch);
    const double wall = std::chrono::duration<double, std::micro>(clock::now() - start).count();
    *cpu = cpu_micros_since(cpu_start);
    return wall;
  }
  std::barrier sync(static_cast<std::ptrdiff_t>(threads));
  const size_t per = (chars.size() + threads - 1) / threads;
  clock::time_point start;
  const auto work = [&](unsigned t) {
    const size_t first = t * per, last = std::min(chars.size(), first + per);
    GraphScratch scratch = GraphScratch::create(def);
    sync.arrive_and_wait();
    for (int f = 0; f < frames; ++f) {
      for (size_t i = first; i < last; ++i) drive(chars[i], p, scratch);
      sync.arrive_and_wait();
    }
  };
  std::vector<std::thread> pool;
  start = clock::now();
  for (unsigned t = 1; t < threads; ++t) pool.emplace_back(work, t);
  work(0);
  const auto end = clock::now();
  for (std::thread& t : pool) t.join();
  *cpu = cpu_micros_since(cpu_start);
  return std::chrono::duration<double, std::micro>(end - start).count();
}

}  // namespace

int main(int argc, char** argv) {
  std::string file, graph_name;
  int frames = 300, repeat = 5;
  std::vector<size_t> counts = {1, 100, 1000};
  std::string clone_error;
  if (!ossa::bench::apply_clone(argc, argv, &clone_error)) {
    std::fprintf(stderr, "ossa-bench-graph: %s\n", clone_error.c_str());
    return 2;
  }
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--file" && i + 1 < argc) file = argv[++i];
    else if (a == "--graph" && i + 1 < argc) graph_name = argv[++i];
    else if (a == "--frames" && i + 1 < argc) frames = std::max(10, std::atoi(argv[++i]));
    else if (a == "--repeat" && i + 1 < argc) repeat = std::max(1, std::atoi(argv[++i]));
    else if (a == "--characters" && i + 1 < argc) counts = {static_cast<size_t>(std::max(1, std::atoi(argv[++i])))};
    else {
      std::fprintf(stderr,
                   "usage: ossa-bench-graph [--file CHARACTER.ossa --graph NAME] [--frames N] [--repeat N] "
                   "[--characters N] [--clone baseline|avx2|avx512]\n");
      return 2;
    }
  }
  fs::path cooked_dir;
  std::string fox_file;
  if (file.empty()) {
    const fs::path source = fs::path(OSSA_BENCH_SOURCE_DIR) / "assets" / "Pab" / "pab.graph.json";
    const fs::path dir = fs::temp_directory_path() / ("ossa-bench-graph-" + std::to_string(::getpid()));
    const cook::CookRecord r = cook::cook_file(source, dir / "pab.ossa", cook::CookOptions{});
    if (!r.ok) {
      fs::remove_all(dir);
      std::fprintf(stderr, "ossa-bench-graph: %s\n", r.error.c_str());
      return 1;
    }
    file = (dir / "pab.ossa").string();
    cooked_dir = dir;
    const fs::path fox_source = fs::path(OSSA_BENCH_SOURCE_DIR) / "assets" / "Fox" / "fox_tail.graph.json";
    const cook::CookRecord fr = cook::cook_file(fox_source, dir / "fox_tail.ossa", cook::CookOptions{});
    if (fr.ok) fox_file = (dir / "fox_tail.ossa").string();
    else std::fprintf(stderr, "ossa-bench-graph: %s (the spring rows are left out)\n", fr.error.c_str());
  }
  auto asset = Asset::open(file);
  if (!asset) {
    if (!cooked_dir.empty()) fs::remove_all(cooked_dir);
    std::fprintf(stderr, "ossa-bench-graph: %s\n", asset.error().message.c_str());
    return 1;
  }
  if (graph_name.empty()) {
    if (graph_count(*asset) == 0) {
      std::fprintf(stderr, "ossa-bench-graph: %s: the file has no graph\n", file.c_str());
      return 1;
    }
    graph_name = asset->file().graphs()->Get(0)->name()->str();
  }
  auto def = GraphDefinition::create(*asset, graph_name);
  if (!def) {
    std::fprintf(stderr, "ossa-bench-graph: %s\n", def.error().message.c_str());
    return 1;
  }
  Params plain;
  plain.speed = def->find_parameter("speed");
  plain.crossed = def->find_parameter("crossed_arms");
  plain.stop = def->find_parameter("strike_pose");
  // The plain locomotion graph: the sample's procedural nodes (look-at, feet on the ground, foot
  // locking) at weight 0, where they cost a parameter read each.
  for (const char* off : {"look_weight", "feet_on_ground", "foot_lock"})
    if (const int q = def->find_parameter(off); q >= 0) plain.fixed.emplace_back(q, 0.0f);
  std::printf("# %s\n", ossa::bench::machine_line().c_str());
  std::printf("graph '%s' of %s: %u joints, %zu nodes, %zu state machines, %zu clips; %d frames of %.1f ms\n",
              graph_name.c_str(), file.c_str(), def->joint_count(), def->node_count(), def->machine_count(),
              def->clip_count(), frames, 1000.0 * kDt);
  std::printf("%-40s %-11s %-8s %14s %22s %14s\n", "graph", "characters", "threads", "us/char/frame",
              "characters/16.7ms", "cpu_us/char");
  const auto row = [&](const GraphDefinition& d, const Params& p, const char* label, size_t count, unsigned threads) {
    // More frames for fewer characters, so every row times a similar amount of work.
    const int n = count == 1 ? frames * 50 : count == 100 ? frames * 2 : frames / 5;
    double best = 1e300, best_cpu = 1e300, cpu = 0.0;
    for (int rep = 0; rep < repeat; ++rep) {
      std::vector<Character> chars = make_characters(d, p, count);
      time_frames(d, chars, p, std::max(3, n / 10), threads, &cpu);  // warm: caches decoded, pages touched
      best = std::min(best, time_frames(d, chars, p, n, threads, &cpu));
      best_cpu = std::min(best_cpu, cpu);
    }
    const double per_char = best / (static_cast<double>(n) * static_cast<double>(count));
    const double fit = kFrameMicros / per_char;
    std::printf("%-40s %-11zu %-8u %14.3f %22.0f %14.3f\n", label, count, threads, per_char, fit,
                best_cpu / (static_cast<double>(n) * static_cast<double>(count)));
    return fit;
  };
  double last_rate = 0.0;
  for (size_t count : counts) {
    for (unsigned threads : {1u, 2u}) {
      if (count == 1 && threads == 2) continue;  // one character is one job
      const double fit = row(*def, plain, "locomotion", count, threads);
      if (threads == 2 || count == 1) last_rate = fit;  // the largest count on two threads
    }
  }
  // The procedural nodes on, at the largest count on two threads.
  const size_t many = counts.back();
  const int feet = def->find_parameter("feet_on_ground"), lock = def->find_parameter("foot_lock"),
            look_weight = def->find_parameter("look_weight");
  if (feet >= 0 && lock >= 0) {
    Params p = plain;
    p.fixed = {{feet, 1.0f}, {lock, 0.0f}};
    if (look_weight >= 0) p.fixed.emplace_back(look_weight, 0.0f);
    p.ground_left = def->find_parameter("ground_left");
    p.ground_right = def->find_parameter("ground_right");
    if (p.ground_left >= 0 && p.ground_right >= 0) {
      row(*def, p, "+ foot placement (uneven ground)", many, 2);
      p.fixed[1].second = 1.0f;
      row(*def, p, "+ foot placement + foot locking", many, 2);
      if (look_weight >= 0 && (p.look = def->find_parameter("look_target")) >= 0) {
        p.fixed.back().second = 1.0f;
        row(*def, p, "+ look-at (3-joint aim chain)", many, 2);
      }
    }
  }
  // The sample's upper-body montage (cross_arms: its loop section repeats until told) on every
  // character, next to the same graph without it, both at the largest count on two threads. The
  // two are timed in turn, repetition by repetition (best of each), so a neighbour's load falls on
  // both alike.
  if (const int montage = def->find_montage("cross_arms"); montage >= 0) {
    Params with = plain;
    with.montage = montage;
    const int n = frames / 5;
    double best[2] = {1e300, 1e300};
    for (int rep = 0; rep < repeat; ++rep) {
      for (int k = 0; k < 2; ++k) {
        const Params& p = k == 0 ? plain : with;
        std::vector<Character> chars = make_characters(*def, p, many);
        double cpu = 0.0;  // this comparison reads wall time only
        time_frames(*def, chars, p, std::max(3, n / 10), 2, &cpu);
        best[k] = std::min(best[k], time_frames(*def, chars, p, n, 2, &cpu));
      }
    }
    double fit[2];
    for (int k = 0; k < 2; ++k) {
      const double per_char = best[k] / (static_cast<double>(n) * static_cast<double>(many));
      fit[k] = kFrameMicros / per_char;
      std::printf("%-40s %-11zu %-8u %14.3f %22.0f\n",
                  k == 0 ? "locomotion, no montage (interleaved)" : "+ upper-body montage on every character", many, 2u,
                  per_char, fit[k]);
    }
    // What the montages take of a frame filled with characters that play none: with / without - 1.
    std::printf("montage_cost_percent_of_frame: %.1f\n", 100.0 * (fit[0] / fit[1] - 1.0));
  }
  // A spring chain: the Fox sample's tail (3 joints, 3 colliders) at weight 0 and 1. At weight 0 the
  // chain still simulates (its state stays continuous), so the two rows cost the same.
  if (!fox_file.empty()) {
    auto fox = Asset::open(fox_file);
    auto fox_def = fox ? GraphDefinition::create(*fox, "fox") : Result<GraphDefinition>(fox.error());
    if (!fox_def) {
      std::fprintf(stderr, "ossa-bench-graph: %s\n", fox_def.error().message.c_str());
      return 1;
    }
    Params p;
    p.speed = -1;
    const int tail = fox_def->find_parameter("tail_spring");
    if (tail >= 0) {
      p.fixed = {{tail, 0.0f}};
      row(*fox_def, p, "fox, tail spring weight 0 (simulating)", many, 2);
      p.fixed = {{tail, 1.0f}};
      row(*fox_def, p, "fox, tail spring weight 1", many, 2);
    }
  }
  if (!cooked_dir.empty()) fs::remove_all(cooked_dir);
  std::printf("characters_per_frame_2_threads: %.0f\n", last_rate);
  return 0;
}
