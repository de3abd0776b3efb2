#include "matrix/products.h"

#include <gtest/gtest.h>

#include <random>

#include "test_util.h"

namespace dayflux {
namespace {

ColorMatrix Random(int r, int c, unsigned seed, double zero_fraction = 0) {
    ColorMatrix m(r, c, 3);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0, 10);
    std::uniform_real_distribution<double> z(0, 1);
    for (int i = 0; i < r; ++i)
        for (int j = 0; j < c; ++j) {
            bool zero = z(rng) < zero_fraction;
            for (int k = 0; k < 3; ++k) m.at(i, j, k) = zero ? 0.f : u(rng);
        }
    return m;
}

// RADIANCE's cm_multiply(): float data, each entry summed in double over k ascending.
float Reference(const ColorMatrix &a, const ColorMatrix &b, int i, int j, int c) {
    double s = 0;
    for (int k = 0; k < a.cols; ++k) s += static_cast<double>(a.at(i, k, c)) * b.at(k, j, c);
    return static_cast<float>(s);
}

TEST(Products, DenseProductIsBitIdenticalToRadianceOrder) {
    // Sizes that leave remainders for the row blocks and the column panels.
    ColorMatrix a = Random(13, 146, 1, 0.1), b = Random(146, 1031, 2, 0.3);
    ColumnOperand op = ColumnOperand::FromMatrix(b);
    ASSERT_FALSE(op.IsSparse());
    EXPECT_EQ(op.ToMatrix().data, b.data);  // (held as the kernel's strips alone)
    size_t nonzero = 0;
    for (int k = 0; k < b.rows; ++k)
        for (int j = 0; j < b.cols; ++j) nonzero += b.at(k, j, 0) != 0;  // (zero in all three)
    EXPECT_EQ(op.NonZeros(), nonzero);
    ColorMatrix p = Multiply(a, op);
    for (int i = 0; i < p.rows; ++i)
        for (int j = 0; j < p.cols; ++j)
            for (int c = 0; c < 3; ++c)
                ASSERT_EQ(p.at(i, j, c), Reference(a, b, i, j, c)) << i << "," << j;
}

TEST(Products, SparseOperandGivesTheSameBits) {
    // A sun matrix: at most one patch per column.
    ColorMatrix a = Random(9, 600, 3);
    ColorMatrix sun(600, 240, 3);
    std::mt19937 rng(4);
    for (int j = 0; j < sun.cols; ++j)
        if (j % 3) {
            int k = static_cast<int>(rng() % 600);
            for (int c = 0; c < 3; ++c) sun.at(k, j, c) = 1000.f + c;
        }
    ColumnOperand op = ColumnOperand::FromMatrix(sun);
    ASSERT_TRUE(op.IsSparse());
    EXPECT_LE(op.NonZeros(), 160u);
    ColorMatrix p = Multiply(a, op);
    for (int i = 0; i < p.rows; ++i)
        for (int j = 0; j < p.cols; ++j)
            for (int c = 0; c < 3; ++c) ASSERT_EQ(p.at(i, j, c), Reference(a, sun, i, j, c));
    EXPECT_EQ(op.ToMatrix().data, sun.data);
}

TEST(Products, ReadingAnOperandKeepsItsStructure) {
    ColorMatrix sparse(50, 20, 3);
    sparse.at(3, 4, 1) = 2.f;
    sparse.at(49, 19, 0) = 5.f;
    std::string text = "#?RADIANCE\nNROWS=50\nNCOLS=20\nNCOMP=3\nFORMAT=ascii\n\n";
    RowFormatter fmt(DataFormat::Ascii, 20, 3);
    for (int r = 0; r < 50; ++r) fmt.Append(sparse.row(r), &text);
    MatrixReader reader(InputSource::FromString(text, "s"));
    ColumnOperand op = ColumnOperand::Read(reader);
    EXPECT_TRUE(op.IsSparse());
    EXPECT_EQ(op.NonZeros(), 2u);
    EXPECT_EQ(op.ToMatrix().data, sparse.data);
}

TEST(Products, StreamedProductEqualsTheWholeProduct) {
    ColorMatrix a = Random(300, 40, 5), b = Random(40, 30, 6);
    ColumnOperand op = ColumnOperand::FromMatrix(b);
    std::string text = "#?RADIANCE\nNROWS=300\nNCOLS=40\nNCOMP=3\nFORMAT=float\n\n";
    RowFormatter bin(DataFormat::Float, 40, 3);
    for (int r = 0; r < a.rows; ++r) bin.Append(a.row(r), &text);
    MatrixReader reader(InputSource::FromString(text, "a"));
    test::TempDir tmp;
    const std::string path = (tmp.path() / "p.fmx").string();
    {
        OutputFile out(path);
        RowFormatter fmt(DataFormat::Float, 30, 3);
        EXPECT_EQ(StreamProduct(reader, op, fmt, out), 300);
        out.Commit();
    }
    ReadSpec rs;
    rs.header = false;
    rs.format = DataFormat::Float;
    rs.ncols = 30;
    MatrixReader back(path, rs);
    ColorMatrix whole = Multiply(a, op);
    std::vector<float> row(30 * 3);
    for (int r = 0; r < 300; ++r) {
        ASSERT_TRUE(back.ReadRow(row.data()));
        for (int j = 0; j < 90; ++j) ASSERT_EQ(row[j], whole.row(r)[j]);
    }
    EXPECT_FALSE(back.ReadRow(row.data()));
}

// A window of columns (per-step outputs compute one), starting and ending inside the 8-column
// strips the dense kernel works in, with rows that leave a partial group of six.
TEST(Products, ColumnWindowsAreBitIdenticalToRadianceOrder) {
    ColorMatrix a = Random(7, 146, 7, 0.1), b = Random(146, 61, 8);
    ColumnOperand op = ColumnOperand::FromMatrix(b);
    ASSERT_FALSE(op.IsSparse());
    for (const auto &[col0, col1] : {std::pair{3, 5}, {5, 22}, {0, 61}, {60, 61}, {16, 24}}) {
        std::vector<float> out(static_cast<size_t>(a.rows) * (col1 - col0) * 3, -1.f);
        MultiplyRows(a.row(0), a.rows, a.cols, op, col0, col1, out.data());
        for (int i = 0; i < a.rows; ++i)
            for (int j = col0; j < col1; ++j)
                for (int c = 0; c < 3; ++c)
                    ASSERT_EQ(out[(static_cast<size_t>(i) * (col1 - col0) + j - col0) * 3 + c],
                              Reference(a, b, i, j, c))
                        << col0 << ".." << col1 << ": " << i << "," << j;
    }
}

// A left matrix held whole (no NROWS in its header), through more blocks than the pipeline holds
// at once, so that blocks' buffers are reused: ascii text, each row as the whole product's.
TEST(Products, StreamedFromMemoryReusesBlocksWithoutMixingThem) {
    ColorMatrix a = Random(1500, 20, 9), b = Random(20, 30, 10);
    ColumnOperand op = ColumnOperand::FromMatrix(b);
    test::TempDir tmp;
    const std::string path = (tmp.path() / "p.txt").string();
    RowFormatter fmt(DataFormat::Ascii, 30, 3, AsciiStyle::kCmatrix);
    {
        OutputFile out(path);
        EXPECT_EQ(StreamProduct(a, op, fmt, out), 1500);
        out.Commit();
    }
    ColorMatrix whole = Multiply(a, op);
    std::string expect;
    for (int r = 0; r < whole.rows; ++r) fmt.Append(whole.row(r), &expect);
    EXPECT_EQ(test::ReadFile(path), expect);
}

}  // namespace
}  // namespace dayflux
