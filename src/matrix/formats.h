// The data formats of RADIANCE matrix files and the rules for choosing between them.
#pragma once

#include <optional>
#include <string_view>

namespace dayflux {

// Ordered as RADIANCE orders them (cmatrix.h): when two operands meet, the result takes the
// "smaller" type, so float < ascii < double, and pictures only combine with their own kind.
enum class DataFormat { Unknown = 0, RGBE, XYZE, Float, Ascii, Double };

// The FORMAT= value written in headers ("ascii", "float", "double", "32-bit_rle_rgbe", ...).
std::string_view FormatName(DataFormat format);
std::optional<DataFormat> FormatFromName(std::string_view name);
// A RADIANCE -f option's letter: a (ascii), f (float), d (double), and c (RGBE) where allowed.
std::optional<DataFormat> FormatFromLetter(char letter, bool rgbe_allowed);
// RADIANCE's rmx_newtype(): the result type of an operation, Unknown on a picture mismatch.
DataFormat CombinedFormat(DataFormat a, DataFormat b);
bool IsPicture(DataFormat format);
bool NativeBigEndian();

}  // namespace dayflux
