// Google Benchmark of tessera::voronoi on generated uniform points.
//
// One benchmark per (dim, n, threads, build_mesh). The points are generated once
// per (dim, n) with a fixed seed, outside the timed region; the timed region is
// one call of tessera::voronoi, including the returned Cells' destruction.
// items/s is cells per second of wall time (UseRealTime: the work runs on TBB
// worker threads, so the calling thread's CPU time would be meaningless).
//
//   build/bench/bench_cells                                   # everything
//   build/bench/bench_cells --benchmark_filter='dim:3/n:100000/'
//   build/bench/bench_cells --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cstddef>
#include <cstdint>
#include <map>
#include <random>
#include <span>
#include <utility>
#include <vector>

#include "tessera/cells.hpp"

namespace {

// Uniform points in the unit cube / square, n*dim doubles, row-major; cached per (dim, n).
const std::vector<double>& uniform_points(int dim, std::size_t n) {
  static std::map<std::pair<int, std::size_t>, std::vector<double>> cache;
  auto [it, fresh] = cache.try_emplace({dim, n});
  if (fresh) {
    std::mt19937_64 rng(12345 + 1000 * std::uint64_t(dim) + n);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    it->second.resize(n * std::size_t(dim));
    for (double& x : it->second) x = u(rng);
  }
  return it->second;
}

void BM_voronoi(benchmark::State& state) {
  const int dim = int(state.range(0));
  const auto n = std::size_t(state.range(1));
  tessera::VoronoiOptions opt;
  opt.dim = dim;
  opt.threads = int(state.range(2));
  opt.build_mesh = state.range(3) != 0;
  const std::vector<double>& pts = uniform_points(dim, n);

  std::size_t cells = 0;
  int threads_used = 0;
  for (auto _ : state) {
    tessera::Cells c = tessera::voronoi(std::span<const double>(pts), dim, {}, opt);
    cells = c.n_cells();
    threads_used = c.threads_used;
    benchmark::DoNotOptimize(c.volume.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(cells));
  state.counters["cells"] = double(cells);
  state.counters["threads_used"] = double(threads_used);
  // Cells per second per thread actually used (wall time): the scaling figure.
  state.counters["cells/s/thread"] = benchmark::Counter(
      double(cells) / double(threads_used > 0 ? threads_used : 1),
      benchmark::Counter::kIsIterationInvariantRate);
}

// Listed dim, then n, then threads, then mesh (ArgsProduct would vary dim fastest).
void configurations(benchmark::internal::Benchmark* b) {
  for (int dim : {3, 2})
    for (int n : {10'000, 100'000})
      for (int threads : {1, 2})
        for (int mesh : {0, 1}) b->Args({dim, n, threads, mesh});
}

}  // namespace

BENCHMARK(BM_voronoi)
    ->ArgNames({"dim", "n", "threads", "mesh"})
    ->Apply(configurations)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
