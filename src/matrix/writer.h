// Writing matrix rows in the four formats, with the ascii layouts of RADIANCE's two matrix
// libraries: rmatrix (rmtxop: " %.Ne" per value, a tab after each element) and cmatrix
// (dctimestep: "%.6e %.6e %.6e", tab between elements, newline after the last).
#pragma once

#include <string>
#include <vector>

#include "matrix/formats.h"
#include "matrix/rgbe.h"
#include "util/files.h"

namespace dayflux {

enum class AsciiStyle { kRmatrix, kCmatrix };

class RowFormatter {
  public:
    // precision: digits after the point for kRmatrix ascii (RADIANCE: 7 float, 3 picture,
    // 15 otherwise); kCmatrix always uses 6.
    RowFormatter(DataFormat format, int ncols, int ncomp, AsciiStyle style = AsciiStyle::kRmatrix,
                 int precision = 15);

    // Appends one row of ncols x ncomp interleaved values.
    void Append(const double *values, std::string *out) const;
    void Append(const float *values, std::string *out) const;
    // Whether a row of floats is written as its own bytes (float output, this machine's order).
    bool WritesFloatsAsTheyAre() const { return format_ == DataFormat::Float; }

  private:
    template <class T>
    void AppendT(const T *values, std::string *out) const;

    DataFormat format_;
    int ncols_, ncomp_;
    AsciiStyle style_;
    int precision_;
};

// RADIANCE's ascii precision for a matrix of the given type (rmx_write_ascii).
int RmatrixPrecision(DataFormat type);

}  // namespace dayflux
