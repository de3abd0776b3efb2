// Whole matrices in memory, for the operands that must be held (rmtxop, skies, BSDFs).
// Large left-hand operands are streamed by row instead (products.h).
#pragma once

#include <string>
#include <vector>

#include "matrix/formats.h"
#include "matrix/reader.h"
#include "util/files.h"

namespace dayflux {

template <class T>
struct BasicMatrix {
    int rows = 0, cols = 0, ncomp = 0;
    DataFormat dtype = DataFormat::Double;  // the type the data came in, for output defaults
    std::string info;                       // header lines passed on, each ending in '\n'
    std::vector<T> data;                    // row-major, components interleaved

    BasicMatrix() = default;
    BasicMatrix(int r, int c, int n)
        : rows(r), cols(c), ncomp(n), data(static_cast<size_t>(r) * c * n) {}

    T &at(int r, int c, int k) { return data[(static_cast<size_t>(r) * cols + c) * ncomp + k]; }
    const T &at(int r, int c, int k) const {
        return data[(static_cast<size_t>(r) * cols + c) * ncomp + k];
    }
    T *row(int r) { return data.data() + static_cast<size_t>(r) * cols * ncomp; }
    const T *row(int r) const { return data.data() + static_cast<size_t>(r) * cols * ncomp; }
};

using Matrix = BasicMatrix<double>;      // rmtxop works in double, as RADIANCE's rmatrix
using ColorMatrix = BasicMatrix<float>;  // dctimestep works in float, as RADIANCE's cmatrix

// Reads every remaining row of reader (to the end of input when the row count is unknown).
Matrix ReadAll(MatrixReader &reader, Matrix *);
ColorMatrix ReadAll(MatrixReader &reader, ColorMatrix *);
template <class M>
M ReadAll(MatrixReader &reader) {
    return ReadAll(reader, static_cast<M *>(nullptr));
}

// Which part of a BSDF XML file an operand means (rmtxop -rf / -rb).
enum class BsdfPart { kTransmission, kReflectionFront, kReflectionBack };

// True if spec names a BSDF XML file (by its suffix, as RADIANCE decides), not a command.
bool IsXmlSpec(const std::string &spec);

// rmtxop's loader: a matrix file, "-", "!command" or a Klems XML file.
Matrix LoadMatrix(const std::string &spec, BsdfPart part = BsdfPart::kTransmission);

// Writes m as RADIANCE's rmx_write() does after the header start: info lines, sizes, format
// and data. format Unknown means the matrix's own type. A 1-component matrix written as a
// picture becomes grey.
void WriteMatrix(const Matrix &m, DataFormat format, const std::string &header_start,
                 OutputFile &out);
// What WriteMatrix writes before the data (m.rows as the header's row count), for a writer
// that streams the rows itself.
std::string MatrixHeaderText(const Matrix &m, DataFormat format, const std::string &header_start);

}  // namespace dayflux
