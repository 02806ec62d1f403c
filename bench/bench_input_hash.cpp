// bench_input_hash.cpp — ossa-bench-input-hash (Google Benchmark): the cook key's input hash,
// XXH3-64 (cooker/model/input_log.h), against the FNV-1a 64 it replaced, on buffers the size of a
// sidecar, a texture and a large source. Why it matters: an all-up-to-date run re-hashes every
// input of the tree, so the hash must run at memory speed to keep that run a few percent of a
// full cook (docs/SCALE.md).
#include <benchmark/benchmark.h>

#include <cstdint>
#include <vector>

#include "cooker/model/input_log.h"
#include <ossa/format/hash.h>

namespace {

std::vector<uint8_t> bytes_of(size_t n) {
  std::vector<uint8_t> v(n);
  uint32_t x = 2463534242u;
  for (uint8_t& b : v) {
    x ^= x << 13;
    x ^= x >> 17;
    x ^= x << 5;
    b = static_cast<uint8_t>(x);
  }
  return v;
}

void BM_InputHashXxh3(benchmark::State& state) {
  const std::vector<uint8_t> data = bytes_of(static_cast<size_t>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(ossa::cook::input_hash(data));
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) * state.range(0));
}

void BM_InputHashFnv1a(benchmark::State& state) {
  const std::vector<uint8_t> data = bytes_of(static_cast<size_t>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(ossa::hash_bytes(data.data(), data.size()));
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) * state.range(0));
}

BENCHMARK(BM_InputHashXxh3)->Arg(150)->Arg(64 << 10)->Arg(2 << 20);
BENCHMARK(BM_InputHashFnv1a)->Arg(150)->Arg(64 << 10)->Arg(2 << 20);

}  // namespace
