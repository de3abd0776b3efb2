#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "matrix/header.h"
#include "matrix/reader.h"
#include "matrix/writer.h"

namespace dayflux {
namespace {

std::vector<double> RandomValues(int n, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0, 1000);
    std::vector<double> v(n);
    for (double &x : v) x = std::ldexp(std::floor(u(rng) * 4096), -12);  // exact in every format
    return v;
}

std::string Encode(const std::vector<double> &v, int rows, int cols, int ncomp, DataFormat f,
                   bool nrows = true, AsciiStyle style = AsciiStyle::kRmatrix) {
    std::string s = "#?RADIANCE\ntest\n";
    s += nrows ? HeaderFields(rows, cols, ncomp, f)
               : "NCOLS=" + std::to_string(cols) + "\nNCOMP=" + std::to_string(ncomp) + "\n" +
                     FormatLine(f) + "\n";
    if (IsPicture(f)) s = "#?RADIANCE\n" + FormatLine(f) + "\n" + ResolutionLine(cols, rows);
    RowFormatter fmt(f, cols, ncomp, style);
    for (int r = 0; r < rows; ++r) fmt.Append(v.data() + static_cast<size_t>(r) * cols * ncomp, &s);
    return s;
}

std::vector<double> Decode(const std::string &s, int *rows = nullptr) {
    MatrixReader reader(InputSource::FromString(s, "mem"));
    std::vector<double> all, row(static_cast<size_t>(reader.Cols()) * reader.Comps());
    int n = 0;
    while (reader.ReadRow(row.data())) all.insert(all.end(), row.begin(), row.end()), ++n;
    reader.Finish();
    if (rows) *rows = n;
    return all;
}

class RoundTrip : public testing::TestWithParam<DataFormat> {};

TEST_P(RoundTrip, EveryFormatReadsBackWhatWasWritten) {
    const int rows = 7, cols = 9, ncomp = 3;
    std::vector<double> v = RandomValues(rows * cols * ncomp, 7);
    std::vector<double> back = Decode(Encode(v, rows, cols, ncomp, GetParam()));
    ASSERT_EQ(back.size(), v.size());
    for (size_t i = 0; i < v.size(); ++i) {
        if (IsPicture(GetParam())) {
            // RGBE keeps 8 bits of mantissa relative to the largest component of each pixel.
            const size_t p = i / 3 * 3;
            const double big = std::max({v[p], v[p + 1], v[p + 2]});
            EXPECT_NEAR(back[i], v[i], big / 256 + 1e-12) << i;
        } else {
            EXPECT_EQ(back[i], v[i]) << i;
        }
    }
}

INSTANTIATE_TEST_SUITE_P(Formats, RoundTrip,
                         testing::Values(DataFormat::Ascii, DataFormat::Float, DataFormat::Double,
                                         DataFormat::RGBE));

TEST(RoundTrip, CmatrixAsciiStyleAndOneComponent) {
    std::vector<double> v = RandomValues(4 * 5, 3);
    EXPECT_EQ(Decode(Encode(v, 4, 5, 1, DataFormat::Ascii)), v);
    std::vector<double> w = RandomValues(2 * 3 * 3, 4);
    std::string s = Encode(w, 2, 3, 3, DataFormat::Ascii, true, AsciiStyle::kCmatrix);
    EXPECT_NE(s.find("e+02\t"), std::string::npos);
    std::vector<double> back = Decode(s);
    for (size_t i = 0; i < w.size(); ++i) EXPECT_NEAR(back[i], w[i], 1e-6 * w[i]);
}

TEST(Reader, RowCountFromEndOfInputWhenNoNrows) {
    std::vector<double> v = RandomValues(5 * 4 * 3, 9);
    for (DataFormat f : {DataFormat::Ascii, DataFormat::Float, DataFormat::Double}) {
        int rows = 0;
        EXPECT_EQ(Decode(Encode(v, 5, 4, 3, f, false), &rows), v);
        EXPECT_EQ(rows, 5);
    }
}

// Ascii data starting with a minus sign is data, not a picture's resolution line ("-Y 3 +X 4").
TEST(Reader, NegativeFirstValueIsNotAResolutionLine) {
    std::vector<double> v = RandomValues(3 * 2 * 3, 5);
    for (double &x : v) x = -x;
    int rows = 0;
    EXPECT_EQ(Decode(Encode(v, 3, 2, 3, DataFormat::Ascii, false), &rows), v);
    EXPECT_EQ(rows, 3);
}

// rcontrib's pictures (-x 4 -y 2 -o) say NROWS=8 before their resolution line: the line gives the
// size, as RADIANCE's rmtxop takes it; a size that disagrees otherwise is taken from the line too.
TEST(Reader, PictureSizeFromItsResolutionLine) {
    const std::vector<double> v = RandomValues(2 * 4 * 3, 13);
    const std::string picture = Encode(v, 2, 4, 3, DataFormat::RGBE);
    for (const char *line : {"NROWS=8\n", "NROWS=3\nNCOLS=3\n"}) {
        std::string s = picture;
        s.insert(s.find("FORMAT="), line);
        MatrixReader reader(InputSource::FromString(s, "mem"));
        EXPECT_EQ(reader.Rows(), 2) << line;
        EXPECT_EQ(reader.Cols(), 4) << line;
        std::vector<double> row(4 * 3);
        int n = 0;
        while (reader.ReadRow(row.data())) ++n;
        EXPECT_EQ(n, 2) << line;
    }
}

TEST(Reader, SwapsBytesForTheOtherByteOrder) {
    std::vector<double> v = RandomValues(3 * 2 * 3, 11);
    for (DataFormat f : {DataFormat::Float, DataFormat::Double}) {
        std::string s = Encode(v, 3, 2, 3, f);
        const size_t size = f == DataFormat::Float ? 4 : 8;
        size_t at = s.find("BigEndian=") + 10;
        s[at] = s[at] == '0' ? '1' : '0';
        size_t body = s.find("\n\n") + 2;
        for (size_t i = body; i + size <= s.size(); i += size)
            std::reverse(s.begin() + i, s.begin() + i + size);
        EXPECT_EQ(Decode(s), v);
    }
}

std::string ReadError(const std::string &s, ReadSpec rs = {}) {
    try {
        MatrixReader reader(InputSource::FromString(s, "m.mtx"), rs);
        std::vector<double> row(static_cast<size_t>(reader.Cols()) * reader.Comps());
        while (reader.ReadRow(row.data())) {
        }
    } catch (const UserError &e) {
        return e.what();
    }
    return "";
}

TEST(Reader, ShortAndMalformedDataAreErrors) {
    std::vector<double> v = RandomValues(5 * 4 * 3, 9);
    std::string full = Encode(v, 5, 4, 3, DataFormat::Float);
    EXPECT_EQ(ReadError(full.substr(0, full.size() - 10)),
              "m.mtx: unexpected end of input in row 5 of 5");
    std::string noend = Encode(v, 5, 4, 3, DataFormat::Float, false);
    EXPECT_EQ(ReadError(noend.substr(0, noend.size() - 4)),
              "m.mtx: unexpected end of input in row 5");
    EXPECT_EQ(ReadError("#?RADIANCE\nNROWS=2\nNCOLS=2\nNCOMP=1\n\n1 2\n3 x4\n"),
              "m.mtx:7: non-numeric value 'x4' in row 2");
    EXPECT_EQ(ReadError("#?RADIANCE\nNROWS=2\nNCOMP=1\n\n1 2\n"),
              "m.mtx: unspecified number of columns (no NCOLS= in header)");
    ReadSpec rs;
    rs.ncols = 3;
    EXPECT_EQ(ReadError("#?RADIANCE\nNROWS=1\nNCOLS=2\nNCOMP=1\n\n1 2\n", rs),
              "m.mtx: has 2 columns, expected 3");
}

TEST(Reader, HeaderlessInputWithGivenFormat) {
    ReadSpec rs;
    rs.header = false;
    rs.format = DataFormat::Ascii;
    rs.ncols = 2;
    MatrixReader reader(InputSource::FromString("1 2 3 4 5 6\n7 8 9 10 11 12\n", "sky"), rs);
    double row[6];
    ASSERT_TRUE(reader.ReadRow(row));
    EXPECT_EQ(row[5], 6);
    ASSERT_TRUE(reader.ReadRow(row));
    EXPECT_EQ(row[0], 7);
    EXPECT_FALSE(reader.ReadRow(row));
}

}  // namespace
}  // namespace dayflux
