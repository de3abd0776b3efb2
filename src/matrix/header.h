// RADIANCE header lines: reading the variables a matrix needs and keeping the rest as info,
// and writing headers the way RADIANCE's programs do.
#pragma once

#include <cstdio>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "matrix/formats.h"
#include "util/files.h"

namespace dayflux {

struct MatrixHeader {
    int nrows = 0, ncols = 0, ncomp = 0;  // 0: not given
    DataFormat format = DataFormat::Unknown;
    std::optional<bool> big_endian;
    // Header lines other than the ones above and the "#?" line, each ending in '\n', in order.
    std::string info;
    // Product of EXPOSURE= and COLORCORR= lines, undone when pictures are read as matrices.
    double exposure[3] = {1, 1, 1};
};

// Reads a header up to and including its blank line. The first line must be a "#?" line.
MatrixHeader ReadHeader(InputSource &in);

// Reads a picture resolution line ("-Y 480 +X 640"). Only the standard orientation is accepted.
void ReadResolution(InputSource &in, int *xres, int *yres);
// True if the next line looks like a resolution line.
bool NextIsResolution(InputSource &in);

// "#?RADIANCE\n" followed by the command line quoted as RADIANCE's printargs() quotes it.
std::string HeaderStart(int argc, char **argv);
// That command line alone, ending in '\n' (RADIANCE's printargs()).
std::string CommandLine(int argc, char **argv);
// A word as RADIANCE's fputword() writes it: in quotes where it holds a blank or a quote.
std::string QuotedWord(std::string_view word);

// RADIANCE's getheader() on a stdio stream, for the small programs that copy its bytes as they
// are (getinfo, rcollate): the header's lines as fgets() reads them (at most 2047 bytes each, a
// longer line in parts), each handed to on_line, up to the empty line (or "\r\n") that ends it,
// which is consumed. False where the stream does not start with a printable character, ends
// before that line, or on_line returns false.
bool ReadHeaderLines(std::FILE *fp, const std::function<bool(const char *)> &on_line);
// The CAPDATE= and GMT= lines RADIANCE's fputnow() writes.
std::string DateLines();
// NROWS/NCOLS/NCOMP, BigEndian (binary only) and FORMAT lines, then the blank line.
std::string HeaderFields(int nrows, int ncols, int ncomp, DataFormat format);
// "FORMAT=...\n" on its own (the caller ends the header with the blank line).
std::string FormatLine(DataFormat format);
std::string ResolutionLine(int xres, int yres);

}  // namespace dayflux
