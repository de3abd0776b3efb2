#include "sky/perez_kernel.h"

#include <immintrin.h>

#include <cmath>

extern "C" {
// glibc's libmvec: AVX2 variants of exp and acos. Declared with the target of their callers:
// passing __m256d in a register is AVX's ABI, which clang refuses to assume otherwise.
__attribute__((target("avx2,fma"))) __m256d _ZGVdN4v_exp(__m256d);
__attribute__((target("avx2,fma"))) __m256d _ZGVdN4v_acos(__m256d);
}

namespace dayflux {

namespace {

void Scalar(size_t n, const double *x, const double *rf, const double *c, const double *d,
            const double *e, float *out) {
    for (size_t i = 0; i < n; ++i) {
        const float l = static_cast<float>(
            rf[i] * (1.0 + c[i] * std::exp(d[i] * std::acos(x[i])) + e[i] * x[i] * x[i]));
        out[i] = l < 0 ? 0.f : l;
    }
}

__attribute__((target("avx2,fma"))) void Avx2(size_t n, const double *x, const double *rf,
                                              const double *c, const double *d, const double *e,
                                              float *out) {
    const __m256d one = _mm256_set1_pd(1.0);
    size_t i = 0;
    for (; i + 4 <= n; i += 4) {
        const __m256d xv = _mm256_loadu_pd(x + i);
        const __m256d g = _ZGVdN4v_acos(xv);
        const __m256d ex = _ZGVdN4v_exp(_mm256_mul_pd(_mm256_loadu_pd(d + i), g));
        // rf (1 + c ex + e x x), in the order the scalar code rounds it
        __m256d t = _mm256_add_pd(one, _mm256_mul_pd(_mm256_loadu_pd(c + i), ex));
        t = _mm256_add_pd(t, _mm256_mul_pd(_mm256_mul_pd(_mm256_loadu_pd(e + i), xv), xv));
        const __m256d l = _mm256_mul_pd(_mm256_loadu_pd(rf + i), t);
        __m128 lf = _mm256_cvtpd_ps(l);
        lf = _mm_max_ps(lf, _mm_setzero_ps());
        _mm_storeu_ps(out + i, lf);
    }
    Scalar(n - i, x + i, rf + i, c + i, d + i, e + i, out + i);
}

bool HaveAvx2() {
    static const bool have = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
    return have;
}

}  // namespace

void PerezRelativeLuminance(size_t n, const double *x, const double *rf, const double *c,
                            const double *d, const double *e, float *out) {
    if (HaveAvx2())
        Avx2(n, x, rf, c, d, e, out);
    else
        Scalar(n, x, rf, c, d, e, out);
}

}  // namespace dayflux
