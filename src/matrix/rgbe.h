// RADIANCE's 4-byte RGBE pixels and the run-length encoding of picture scanlines.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "util/files.h"

namespace dayflux {

using Colr = std::array<uint8_t, 4>;  // red, green, blue mantissas and a shared exponent

// RADIANCE's setcolr(): the largest component gets a mantissa in [128, 256).
Colr ToColr(double r, double g, double b);
// RADIANCE's colr_color(): the centre of each mantissa interval.
void FromColr(const Colr &c, float rgb[3]);

// Appends one scanline with RADIANCE's run-length encoding (flat for very short or long lines).
void EncodeScanline(const Colr *scan, int len, std::string *out);
// Reads one scanline in any of RADIANCE's encodings; false on a short or corrupt line.
bool DecodeScanline(InputSource &in, Colr *scan, int len);

}  // namespace dayflux
