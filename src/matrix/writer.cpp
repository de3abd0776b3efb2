#include "matrix/writer.h"

#include <cstring>

#include "util/errors.h"
#include "util/strings.h"

namespace dayflux {

int RmatrixPrecision(DataFormat type) {
    if (type == DataFormat::Float) return 7;
    if (IsPicture(type)) return 3;
    return 15;
}

RowFormatter::RowFormatter(DataFormat format, int ncols, int ncomp, AsciiStyle style, int precision)
    : format_(format), ncols_(ncols), ncomp_(ncomp), style_(style), precision_(precision) {
    CHECK(format != DataFormat::Unknown);
    CHECK(!IsPicture(format) || ncomp == 3);
}

template <class T>
void RowFormatter::AppendT(const T *v, std::string *out) const {
    const size_t n = static_cast<size_t>(ncols_) * ncomp_;
    switch (format_) {
        case DataFormat::Ascii:
            if (style_ == AsciiStyle::kRmatrix) {
                for (int j = 0; j < ncols_; ++j) {
                    for (int k = 0; k < ncomp_; ++k) {
                        out->push_back(' ');
                        AppendScientific(out, static_cast<double>(v[j * ncomp_ + k]), precision_);
                    }
                    out->push_back('\t');
                }
                out->push_back('\n');
            } else {
                for (int j = 0; j < ncols_; ++j) {
                    for (int k = 0; k < ncomp_; ++k) {
                        if (k) out->push_back(' ');
                        AppendScientific(out, static_cast<double>(v[j * ncomp_ + k]), 6);
                    }
                    out->push_back(j + 1 < ncols_ ? '\t' : '\n');
                }
            }
            break;
        case DataFormat::Float: {
            size_t at = out->size();
            out->resize(at + 4 * n);
            for (size_t i = 0; i < n; ++i) {
                float f = static_cast<float>(v[i]);
                std::memcpy(out->data() + at + 4 * i, &f, 4);
            }
            break;
        }
        case DataFormat::Double: {
            size_t at = out->size();
            out->resize(at + 8 * n);
            for (size_t i = 0; i < n; ++i) {
                double d = static_cast<double>(v[i]);
                std::memcpy(out->data() + at + 8 * i, &d, 8);
            }
            break;
        }
        case DataFormat::RGBE:
        case DataFormat::XYZE: {
            std::vector<Colr> scan(ncols_);
            for (int j = 0; j < ncols_; ++j) scan[j] = ToColr(v[3 * j], v[3 * j + 1], v[3 * j + 2]);
            EncodeScanline(scan.data(), ncols_, out);
            break;
        }
        case DataFormat::Unknown:
            CHECK(false);
    }
}

void RowFormatter::Append(const double *values, std::string *out) const { AppendT(values, out); }
void RowFormatter::Append(const float *values, std::string *out) const { AppendT(values, out); }

}  // namespace dayflux
