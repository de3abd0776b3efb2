#include "matrix/reader.h"

#include <algorithm>
#include <cstdint>
#include <cstring>

#include "util/strings.h"

namespace dayflux {

MatrixReader::MatrixReader(const std::string &spec, const ReadSpec &rs)
    : in_(InputSource::Open(spec)) {
    Init(rs);
}

MatrixReader::MatrixReader(std::unique_ptr<InputSource> in, const ReadSpec &rs)
    : in_(std::move(in)) {
    Init(rs);
}

void MatrixReader::Init(const ReadSpec &rs) {
    FileLoc loc = in_->LocNoLine();
    if (rs.header) header_ = ReadHeader(*in_);
    format_ = header_.format;
    if (rs.format != DataFormat::Unknown) {
        if (format_ != DataFormat::Unknown && format_ != rs.format)
            ErrorExit(&loc, "unexpected data format '" + std::string(FormatName(format_)) +
                                "' in header (expected " + std::string(FormatName(rs.format)) +
                                ")");
        format_ = rs.format;
    }
    if (format_ == DataFormat::Unknown) {
        if (rs.require_format) ErrorExit(&loc, "missing FORMAT= line in header");
        format_ = DataFormat::Ascii;  // RADIANCE assumes ascii without FORMAT=
    }
    nrows_ = header_.nrows;
    ncols_ = header_.ncols;
    ncomp_ = header_.ncomp;
    if (IsPicture(format_)) {
        if (ncomp_ && ncomp_ != 3) ErrorExit(&loc, "a picture must have NCOMP=3");
        ncomp_ = 3;
    }
    // Pictures carry their size in a resolution line (also after NROWS/NCOLS, as dctimestep -oc
    // writes); other matrices may have one where NROWS/NCOLS are missing. The line wins, as in
    // RADIANCE's rmx_load(): rcontrib's pictures (-x -y -o) say NROWS=x*y and no NCOLS.
    if (NextIsResolution(*in_) && (IsPicture(format_) || nrows_ == 0 || ncols_ == 0)) {
        int x = 0, y = 0;
        ReadResolution(*in_, &x, &y);
        const bool rcontrib_picture =
            static_cast<int64_t>(nrows_) == static_cast<int64_t>(x) * y && ncols_ == 0;
        if (!rcontrib_picture && ((nrows_ && nrows_ != y) || (ncols_ && ncols_ != x)))
            Warning(&loc, "resolution line (" + std::to_string(x) + " x " + std::to_string(y) +
                              ") disagrees with NROWS/NCOLS; taking the resolution line");
        nrows_ = y;
        ncols_ = x;
    }
    auto check = [&](const char *what, int expected, int *actual) {
        if (expected <= 0) return;
        if (*actual > 0 && *actual != expected)
            ErrorExit(&loc, "has " + std::to_string(*actual) + " " + what + ", expected " +
                                std::to_string(expected));
        *actual = expected;
    };
    check("rows", rs.nrows, &nrows_);
    check("columns", rs.ncols, &ncols_);
    check("components", rs.ncomp, &ncomp_);
    if (ncomp_ == 0) ncomp_ = 3;
    if (ncols_ <= 0) ErrorExit(&loc, "unspecified number of columns (no NCOLS= in header)");
    // A row is held whole: one beyond any real matrix (a sensor's 5185 suns, a picture's
    // width) is a damaged header, refused before its buffer is made.
    constexpr int64_t kMaxRowValues = int64_t{1} << 27;
    if (static_cast<int64_t>(ncols_) * ncomp_ > kMaxRowValues)
        ErrorExit(&loc, std::to_string(ncols_) + " columns of " + std::to_string(ncomp_) +
                            " components: rows of more than " + std::to_string(kMaxRowValues) +
                            " values are not supported");
    if (IsPicture(format_) && nrows_ <= 0) ErrorExit(&loc, "picture without a resolution line");
    if (header_.big_endian) swap_ = *header_.big_endian != NativeBigEndian();
    // A file too short for even one row fails before that row's buffer is made.
    if (const int64_t per_value = MinBytesPerValue(); per_value > 0)
        if (const auto left = in_->BytesLeft())
            if (static_cast<int64_t>(ncols_) * ncomp_ * per_value > static_cast<int64_t>(*left))
                ShortInput();
}

int64_t MatrixReader::MinBytesPerValue() const {
    switch (format_) {
        case DataFormat::Float:
            return 4;
        case DataFormat::Double:
            return 8;
        case DataFormat::Ascii:
            return 1;  // a digit (with a separator, two, but for the last)
        default:
            return 0;  // pictures: run-length encoded
    }
}

void MatrixReader::ShortInput() {
    FileLoc loc = in_->Loc();
    if (format_ != DataFormat::Ascii) loc.line = 0;
    std::string expected = nrows_ > 0 ? " of " + std::to_string(nrows_) : "";
    ErrorExit(&loc, "unexpected end of input in row " + std::to_string(rows_read_ + 1) + expected);
}

template <class T>
bool MatrixReader::ReadAsciiRow(T *values) {
    const int n = ncols_ * ncomp_;
    std::string_view word;
    for (int i = 0; i < n; ++i) {
        if (!in_->NextWord(&word)) {
            if (i == 0 && nrows_ <= 0) return false;
            ShortInput();
        }
        if (!ParseNumber(word, &values[i])) {
            FileLoc loc = in_->Loc();
            ErrorExit(&loc, "non-numeric value '" + std::string(word.substr(0, 40)) + "' in row " +
                                std::to_string(rows_read_ + 1));
        }
    }
    return true;
}

template <class T>
bool MatrixReader::ReadBinaryRow(T *values) {
    const size_t n = static_cast<size_t>(ncols_) * ncomp_;
    const size_t size = format_ == DataFormat::Float ? 4 : 8;
    raw_.resize(n * size);
    size_t got = in_->Read(raw_.data(), raw_.size());
    if (got != raw_.size()) {
        if (got == 0 && nrows_ <= 0) return false;
        ShortInput();
    }
    if (swap_) {
        for (size_t i = 0; i < n; ++i)
            std::reverse(raw_.data() + i * size, raw_.data() + (i + 1) * size);
    }
    if (size == 4) {
        for (size_t i = 0; i < n; ++i) {
            float f;
            std::memcpy(&f, raw_.data() + 4 * i, 4);
            values[i] = static_cast<T>(f);
        }
    } else {
        for (size_t i = 0; i < n; ++i) {
            double d;
            std::memcpy(&d, raw_.data() + 8 * i, 8);
            values[i] = static_cast<T>(d);
        }
    }
    return true;
}

template <class T>
bool MatrixReader::ReadPictureRow(T *values) {
    scan_.resize(ncols_);
    if (!DecodeScanline(*in_, scan_.data(), ncols_)) {
        FileLoc loc = in_->LocNoLine();
        ErrorExit(&loc, "bad or short picture data in scanline " + std::to_string(rows_read_ + 1));
    }
    const double *e = header_.exposure;
    const bool scale = e[0] != 1 || e[1] != 1 || e[2] != 1;
    for (int j = 0; j < ncols_; ++j) {
        float rgb[3];
        FromColr(scan_[j], rgb);
        for (int k = 0; k < 3; ++k)
            values[3 * j + k] =
                scale ? static_cast<T>(rgb[k] * (1.0 / e[k])) : static_cast<T>(rgb[k]);
    }
    return true;
}

template <class T>
bool MatrixReader::ReadRowT(T *values) {
    if (nrows_ > 0 && rows_read_ >= nrows_) return false;
    bool ok = false;
    switch (format_) {
        case DataFormat::Ascii:
            ok = ReadAsciiRow(values);
            break;
        case DataFormat::Float:
        case DataFormat::Double:
            ok = ReadBinaryRow(values);
            break;
        case DataFormat::RGBE:
        case DataFormat::XYZE:
            ok = ReadPictureRow(values);
            break;
        case DataFormat::Unknown:
            CHECK(false);
    }
    if (ok) ++rows_read_;
    return ok;
}

bool MatrixReader::ReadRow(float *values) { return ReadRowT(values); }
bool MatrixReader::ReadRow(double *values) { return ReadRowT(values); }

void MatrixReader::Finish(bool trailing_data_is_error) {
    const auto report = [&](const FileLoc &loc, const char *what) {
        if (trailing_data_is_error)
            ErrorExit(&loc, std::string(what) + " (more than the header's size)");
        Warning(&loc, what);
    };
    if (format_ == DataFormat::Ascii) {
        if (!in_->OnlySpaceLeft()) report(in_->Loc(), "unexpected data at end of ascii input");
    } else if (!in_->AtEnd()) {
        report(in_->LocNoLine(), "unexpected data at end of binary input");
    }
    in_->Close();
}

}  // namespace dayflux
