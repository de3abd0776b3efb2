// The hardware's limit for dctimestep's dense product (issue 43): OpenBLAS sgemm on the
// reference office's sizes (1425 sensors x 146 patches times 146 x 8760 hours, each of three
// components) and writing its 150 MB of floats, against which dctimestep's own time is judged
// (bench/example_products_bench.sh). sgemm is the bound, not a kernel we could use: its sums are
// blocked and in float, so its bytes are not RADIANCE's; dgemm is the bound for sums in double.
// Run: build/bench/product_limit_bench. Timings belong in docs/benchmarks.md.
#include <benchmark/benchmark.h>
#include <cblas.h>

#include <algorithm>
#include <cstdio>
#include <random>
#include <vector>

namespace {

constexpr int kSensors = 1425, kPatches = 146, kHours = 8760;

std::vector<float> Random(size_t n, unsigned seed) {
    std::vector<float> v(n);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0, 1);
    for (float &x : v) x = u(rng);
    return v;
}

// The three components' products in Real, one gemm each (row-major, all threads OpenBLAS has).
template <class Real, class Gemm>
void GemmOfTheYear(benchmark::State &state, Gemm gemm) {
    const std::vector<float> af = Random(size_t{kSensors} * kPatches, 1),
                             bf = Random(size_t{kPatches} * kHours, 2);
    const std::vector<Real> a(af.begin(), af.end()), b(bf.begin(), bf.end());
    std::vector<Real> c(size_t{kSensors} * kHours);
    for (auto _ : state)
        for (int comp = 0; comp < 3; ++comp) {
            gemm(CblasRowMajor, CblasNoTrans, CblasNoTrans, kSensors, kHours, kPatches, Real(1),
                 a.data(), kPatches, b.data(), kHours, Real(0), c.data(), kHours);
            benchmark::DoNotOptimize(c.data());
        }
    state.counters["GFLOP/s"] = benchmark::Counter(
        3.0 * 2 * kSensors * kPatches * double(kHours) * state.iterations() / 1e9,
        benchmark::Counter::kIsRate);
}
// sgemm: the bound; dgemm: the bound for sums in double, as RADIANCE's (and dctimestep's) are.
void SgemmOfTheYear(benchmark::State &state) { GemmOfTheYear<float>(state, cblas_sgemm); }
void DgemmOfTheYear(benchmark::State &state) { GemmOfTheYear<double>(state, cblas_dgemm); }
BENCHMARK(SgemmOfTheYear)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(DgemmOfTheYear)->Unit(benchmark::kMillisecond)->UseRealTime();

// Writing the year's products (kSensors x kHours x 3 floats) in 8 MiB blocks to a temporary
// file (in /tmp: memory on most machines, as a pipe's reader would take them).
void WriteOfTheYear(benchmark::State &state) {
    const std::vector<float> block(size_t{8} << 18, 1.f);  // 8 MiB
    const size_t total = size_t{kSensors} * kHours * 3 * sizeof(float);
    std::FILE *out = std::tmpfile();
    for (auto _ : state) {
        std::rewind(out);
        for (size_t done = 0; done < total; done += block.size() * sizeof(float))
            std::fwrite(block.data(), 1, std::min(total - done, block.size() * sizeof(float)), out);
        std::fflush(out);
    }
    std::fclose(out);
}
BENCHMARK(WriteOfTheYear)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
