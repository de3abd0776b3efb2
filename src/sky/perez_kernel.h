// The Perez relative luminance for many sky points at once:
//   L = rf (1 + c exp(d acos(x)) + e x^2), rounded to float and clamped at 0,
// with x the cosine of the angle to the sun. On AVX2 machines glibc's vector exp and acos
// (libmvec, a few units in the last place of a double) do four points at a time; elsewhere libm.
#pragma once

#include <cstddef>

namespace dayflux {

void PerezRelativeLuminance(size_t n, const double *x, const double *rf, const double *c,
                            const double *d, const double *e, float *out);

}  // namespace dayflux
