#include "matrix/matrices.h"

#include <strings.h>

#include <algorithm>
#include <cctype>

#include "matrix/bsdf_xml.h"
#include "matrix/header.h"
#include "matrix/writer.h"

namespace dayflux {

namespace {
template <class T>
BasicMatrix<T> ReadRows(MatrixReader &reader) {
    BasicMatrix<T> m;
    m.cols = reader.Cols();
    m.ncomp = reader.Comps();
    m.dtype = reader.Format();
    m.info = reader.Header().info;
    const size_t row_size = static_cast<size_t>(m.cols) * m.ncomp;
    // NROWS is untrusted: room is made ahead for the values the rest of a file can hold, or for
    // at most 16M from a pipe, so a short input claiming many rows fails at its end, not by
    // allocating them first. Beyond that, once rows keep arriving, the room grows by up to 4
    // times toward NROWS and no further (by 2 without it): doubling past NROWS cost rmtxop twice
    // the time and memory on a year of 1425 sensors.
    const size_t claimed = reader.Rows() > 0 ? static_cast<size_t>(reader.Rows()) * row_size : 0;
    const auto left = reader.BytesLeft();
    if (left && reader.MinBytesPerValue() > 0)
        m.data.reserve(std::min<size_t>(claimed, *left / reader.MinBytesPerValue()));
    else
        m.data.reserve(std::min(claimed, size_t{1} << 24));
    std::vector<T> row(row_size);
    while (reader.ReadRow(row.data())) {
        const size_t needed = m.data.size() + row_size;
        if (needed > m.data.capacity()) {
            size_t room = std::max(needed, 2 * m.data.capacity());
            if (claimed >= needed)
                room = std::min(std::max(needed, 4 * m.data.capacity()), claimed);
            m.data.reserve(room);
        }
        m.data.insert(m.data.end(), row.begin(), row.end());
        ++m.rows;
    }
    reader.Finish();
    if (m.rows == 0) {
        FileLoc loc{reader.Name(), 0};
        ErrorExit(&loc, "no data rows in matrix");
    }
    return m;
}
}  // namespace

Matrix ReadAll(MatrixReader &reader, Matrix *) { return ReadRows<double>(reader); }
ColorMatrix ReadAll(MatrixReader &reader, ColorMatrix *) { return ReadRows<float>(reader); }

bool IsXmlSpec(const std::string &spec) {
    if (spec.empty() || spec[0] == '!') return false;
    size_t dot = spec.rfind('.');
    return dot != std::string::npos && strcasecmp(spec.c_str() + dot + 1, "xml") == 0;
}

Matrix LoadMatrix(const std::string &spec, BsdfPart part) {
    if (IsXmlSpec(spec)) {
        ColorMatrix cm = LoadBsdfMatrix(spec, part);
        Matrix m(cm.rows, cm.cols, 3);
        for (size_t i = 0; i < cm.data.size(); ++i) m.data[i] = cm.data[i];
        m.dtype = DataFormat::Ascii;  // as RADIANCE's rmx_load() marks BSDF data
        return m;
    }
    MatrixReader reader(spec);
    return ReadAll<Matrix>(reader);
}

std::string MatrixHeaderText(const Matrix &m, DataFormat format, const std::string &header_start) {
    if (format == DataFormat::Unknown) format = m.dtype;
    std::string text = header_start + m.info;
    if (IsPicture(format)) {
        if (m.ncomp != 3 && m.ncomp != 1)
            ErrorExit("cannot write a " + std::to_string(m.ncomp) +
                      "-component matrix as a picture");
        return text + FormatLine(format) + "\n" + ResolutionLine(m.cols, m.rows);
    }
    return text + HeaderFields(m.rows, m.cols, m.ncomp, format);
}

void WriteMatrix(const Matrix &m, DataFormat format, const std::string &header_start,
                 OutputFile &out) {
    if (format == DataFormat::Unknown) format = m.dtype;
    out.Write(MatrixHeaderText(m, format, header_start));
    const Matrix *src = &m;
    Matrix grey;
    if (IsPicture(format) && m.ncomp == 1) {
        grey = Matrix(m.rows, m.cols, 3);
        for (size_t i = 0; i < m.data.size(); ++i)
            grey.data[3 * i] = grey.data[3 * i + 1] = grey.data[3 * i + 2] = m.data[i];
        src = &grey;
    }
    RowFormatter fmt(format, src->cols, src->ncomp, AsciiStyle::kRmatrix,
                     RmatrixPrecision(m.dtype));
    std::string buf;
    for (int r = 0; r < src->rows; ++r) {
        fmt.Append(src->row(r), &buf);
        if (buf.size() > (1 << 20)) {
            out.Write(buf);
            buf.clear();
        }
    }
    out.Write(buf);
}

}  // namespace dayflux
