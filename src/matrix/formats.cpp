#include "matrix/formats.h"

#include <bit>

namespace dayflux {

std::string_view FormatName(DataFormat format) {
    switch (format) {
        case DataFormat::RGBE:
            return "32-bit_rle_rgbe";
        case DataFormat::XYZE:
            return "32-bit_rle_xyze";
        case DataFormat::Float:
            return "float";
        case DataFormat::Ascii:
            return "ascii";
        case DataFormat::Double:
            return "double";
        case DataFormat::Unknown:
            break;
    }
    return "unknown";
}

std::optional<DataFormat> FormatFromLetter(char letter, bool rgbe_allowed) {
    switch (letter) {
        case 'a':
            return DataFormat::Ascii;
        case 'f':
            return DataFormat::Float;
        case 'd':
            return DataFormat::Double;
        case 'c':
            if (rgbe_allowed) return DataFormat::RGBE;
            return std::nullopt;
        default:
            return std::nullopt;
    }
}

std::optional<DataFormat> FormatFromName(std::string_view name) {
    for (DataFormat f : {DataFormat::RGBE, DataFormat::XYZE, DataFormat::Float, DataFormat::Ascii,
                         DataFormat::Double})
        if (name == FormatName(f)) return f;
    return std::nullopt;
}

bool IsPicture(DataFormat format) {
    return format == DataFormat::RGBE || format == DataFormat::XYZE;
}

DataFormat CombinedFormat(DataFormat a, DataFormat b) {
    if ((IsPicture(a) || IsPicture(b)) && a != b) return DataFormat::Unknown;
    return static_cast<int>(a) < static_cast<int>(b) ? a : b;
}

bool NativeBigEndian() { return std::endian::native == std::endian::big; }

}  // namespace dayflux
