// RADIANCE matrices and pictures in memory, read as the programs read them: whole, in double
// (rmtxop's LoadMatrix), in float with FORMAT= required (dctimestep's operands), and as
// dctimestep's right-hand operand (sparse or dense columns). Inputs that start with "#?" are
// whole files; any other input is headerless data, its first two bytes choosing what the caller
// says about it (dctimestep -n / -if): format, components, columns and rows. Whole inputs also go
// through ReadHeaderLines (RADIANCE's getheader(), getinfo's and rcollate's reader): its lines are
// within the input and end the header or come before its end.
#include <array>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "fuzz_util.h"
#include "matrix/header.h"
#include "matrix/matrices.h"
#include "matrix/products.h"

namespace {

using dayflux::DataFormat;
using dayflux::InputSource;
using dayflux::MatrixReader;
using dayflux::ReadSpec;

constexpr std::array<DataFormat, 4> kFormats = {DataFormat::Ascii, DataFormat::Float,
                                                DataFormat::Double, DataFormat::RGBE};

// The spec of a headerless input from its first two bytes; the data follow them.
ReadSpec HeaderlessSpec(uint8_t mode, uint8_t cols) {
    ReadSpec spec;
    spec.header = false;
    spec.format = kFormats[mode % kFormats.size()];
    spec.ncomp = (mode & 4) ? 1 : 3;
    spec.nrows = (mode >> 3) % 4;  // 0: to the end of the data
    spec.ncols = 1 + cols % 64;
    return spec;
}

[[noreturn]] void Finding(const std::string &what) {
    std::fprintf(stderr, "matrix_fuzzer: %s\n", what.c_str());
    std::abort();
}

std::unique_ptr<InputSource> Source(std::string_view text) {
    return InputSource::FromString(std::string(text), "fuzz.mtx");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    std::string_view text = dayflux::fuzz::AsText(data, size);
    ReadSpec spec;
    if (size >= 2 && !text.starts_with("#?")) {
        spec = HeaderlessSpec(data[0], data[1]);
        text.remove_prefix(2);
    }
    dayflux::fuzz::ExpectUserErrors([&] {
        MatrixReader reader(Source(text), spec);
        dayflux::ReadAll<dayflux::Matrix>(reader);
    });
    dayflux::fuzz::ExpectUserErrors([&] {
        ReadSpec strict = spec;
        strict.require_format = spec.header;
        MatrixReader reader(Source(text), strict);
        dayflux::ReadAll<dayflux::ColorMatrix>(reader);
    });
    dayflux::fuzz::ExpectUserErrors([&] {
        MatrixReader reader(Source(text), spec);
        dayflux::ColumnOperand::Read(reader);
    });
    if (spec.header && size > 0) {
        std::FILE *fp = fmemopen(const_cast<uint8_t *>(data), size, "rb");
        size_t seen = 0;
        const bool ended = dayflux::ReadHeaderLines(fp, [&](const char *line) {
            const size_t n = std::strlen(line);
            if (n > 2046)  // (0 where the line holds a NUL first: C strings, as RADIANCE reads it)
                Finding("a header line of " + std::to_string(n) + " bytes");
            seen += n;
            return true;
        });
        if (seen > size) Finding("header lines longer than the input");
        if (ended && seen >= size) Finding("a header ended past the input's end");
        std::fclose(fp);
    }
    return 0;
}
