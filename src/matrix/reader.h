// Streaming reader for RADIANCE matrices: the header first, then one row at a time in any of
// the four data formats, byte-swapped as the header's BigEndian= says.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "matrix/header.h"
#include "matrix/rgbe.h"

namespace dayflux {

// What the caller knows or expects about an input.
struct ReadSpec {
    bool header = true;                       // false: no header at all (dctimestep -n, -if)
    DataFormat format = DataFormat::Unknown;  // required when there is no header
    int nrows = 0, ncols = 0, ncomp = 0;      // expected sizes; 0 = take them from the header
    bool require_format = false;              // a header without FORMAT= is an error (dctimestep)
};

class MatrixReader {
  public:
    // spec: a file, "-" (stdin) or "!command".
    explicit MatrixReader(const std::string &spec, const ReadSpec &rs = {});
    MatrixReader(std::unique_ptr<InputSource> in, const ReadSpec &rs = {});

    const MatrixHeader &Header() const { return header_; }
    const std::string &Name() const { return in_->Name(); }
    // 0 when the row count is not known until the input ends.
    int Rows() const { return nrows_; }
    // The least a value takes in this input's format (0 where it varies: pictures).
    int64_t MinBytesPerValue() const;
    std::optional<uint64_t> BytesLeft() const { return in_->BytesLeft(); }
    int Cols() const { return ncols_; }
    int Comps() const { return ncomp_; }
    DataFormat Format() const { return format_; }

    // Reads the next row (Cols() x Comps() values, components interleaved). Returns false at
    // the end of input only where the row count is unknown; a short row is an error.
    bool ReadRow(float *values);
    bool ReadRow(double *values);
    // After the last row: warns about trailing data (or, where a consumer needs the exact size,
    // fails) and closes the input.
    void Finish(bool trailing_data_is_error = false);

  private:
    void Init(const ReadSpec &rs);
    template <class T>
    bool ReadRowT(T *values);
    template <class T>
    bool ReadAsciiRow(T *values);
    template <class T>
    bool ReadBinaryRow(T *values);
    template <class T>
    bool ReadPictureRow(T *values);
    [[noreturn]] void ShortInput();

    std::unique_ptr<InputSource> in_;
    MatrixHeader header_;
    DataFormat format_ = DataFormat::Unknown;
    int nrows_ = 0, ncols_ = 0, ncomp_ = 0;
    bool swap_ = false;
    int rows_read_ = 0;
    std::vector<unsigned char> raw_;
    std::vector<Colr> scan_;
};

}  // namespace dayflux
