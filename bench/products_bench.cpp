// Throughput of dctimestep's product kernel (dense sky and sparse sun operands).
// Run: build/bench/products_bench. Timings belong in docs/benchmarks.md, never in tests.
#include <benchmark/benchmark.h>

#include <random>

#include "matrix/products.h"

namespace dayflux {
namespace {

ColorMatrix Random(int r, int c, unsigned seed) {
    ColorMatrix m(r, c, 3);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0, 1);
    for (float &x : m.data) x = u(rng);
    return m;
}

void DenseSky(benchmark::State &state) {
    const int rows = 256, inner = 146, cols = static_cast<int>(state.range(0));
    ColorMatrix a = Random(rows, inner, 1);
    ColumnOperand sky = ColumnOperand::FromMatrix(Random(inner, cols, 2));
    std::vector<float> out(static_cast<size_t>(rows) * cols * 3);
    for (auto _ : state) {
        MultiplyRows(a.data.data(), rows, inner, sky, 0, cols, out.data());
        benchmark::DoNotOptimize(out.data());
    }
    state.counters["GMAC/s"] = benchmark::Counter(
        3.0 * rows * inner * cols * state.iterations() / 1e9, benchmark::Counter::kIsRate);
}
BENCHMARK(DenseSky)->Arg(8760);

void SparseSun(benchmark::State &state) {
    const int rows = 256, inner = 5186, cols = 8760;
    ColorMatrix a = Random(rows, inner, 3);
    ColorMatrix sun(inner, cols, 3);
    std::mt19937 rng(4);
    for (int j = 0; j < cols; j += 2)
        for (int c = 0; c < 3; ++c) sun.at(static_cast<int>(rng() % inner), j, c) = 1.f;
    ColumnOperand op = ColumnOperand::FromMatrix(sun);
    std::vector<float> out(static_cast<size_t>(rows) * cols * 3);
    for (auto _ : state) {
        MultiplyRows(a.data.data(), rows, inner, op, 0, cols, out.data());
        benchmark::DoNotOptimize(out.data());
    }
}
BENCHMARK(SparseSun);

}  // namespace
}  // namespace dayflux

BENCHMARK_MAIN();
