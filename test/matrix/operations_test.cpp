#include "matrix/operations.h"

#include <gtest/gtest.h>

#include <random>

namespace dayflux {
namespace {

Matrix Random(int r, int c, int n, unsigned seed) {
    Matrix m(r, c, n);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    for (double &x : m.data) x = u(rng);
    return m;
}

TEST(Operations, LargeProductsAgreeWithTheExactPath) {
    // 40 x 300 x 2000 x 3 multiply-adds: over the exact-path limit, so Eigen computes it.
    Matrix a = Random(40, 300, 3, 1), b = Random(300, 1500, 3, 2);
    Matrix p = Multiply(a, b);
    for (int i = 0; i < a.rows; i += 7)
        for (int j = 0; j < b.cols; j += 101)
            for (int k = 0; k < 3; ++k) {
                long double d = 0;
                for (int h = a.cols; h--;) d += a.at(i, h, k) * b.at(h, j, k);
                EXPECT_NEAR(p.at(i, j, k), static_cast<double>(d), 1e-13);
            }
}

TEST(Operations, InfoLinesFollowRadiance) {
    Matrix m = Random(3, 4, 3, 3);
    m.info = "made by a test\n";
    Scale(&m, {1, 2, 3});
    Matrix t = Transpose(m);
    EXPECT_EQ(t.info, "made by a test\nApplied scalar\nTransposed rows and columns\n");
    Matrix v = Random(1, 4, 3, 4);
    v.info = "vector\n";
    EXPECT_EQ(Transpose(v).info, "vector\n");  // vectors are relabelled silently
    Matrix c = TransformComponents(m, {0.2, 0.7, 0.1});
    EXPECT_EQ(c.ncomp, 1);
    EXPECT_EQ(c.info, m.info + "Applied 1x3 component transform\n");
    Matrix plain = Random(2, 2, 3, 5);
    Scale(&plain, {2, 2, 2});
    EXPECT_EQ(plain.info, "");
}

TEST(Operations, ElementDivisionByZeroGivesZeroAndAWarningLine) {
    Matrix a = Random(2, 2, 3, 6), b = Random(2, 2, 3, 7);
    b.at(1, 1, 2) = 0;
    int zeros = 0;
    Matrix q = a;
    ASSERT_TRUE(ElementMultiply(&q, b, true, &zeros));
    EXPECT_EQ(zeros, 1);
    EXPECT_EQ(q.at(1, 1, 2), 0);
    EXPECT_DOUBLE_EQ(q.at(0, 0, 0), a.at(0, 0, 0) / b.at(0, 0, 0));
    EXPECT_EQ(q.info, "WARNING: zero divide(s) corrupted results\n");
    Matrix wrong = Random(3, 2, 3, 8);
    EXPECT_FALSE(ElementMultiply(&q, wrong, false, &zeros));
    EXPECT_FALSE(AddInto(&q, wrong));
}

TEST(Operations, ResultTypeIsTheSmallerOperandType) {
    Matrix a = Random(2, 2, 3, 9), b = Random(2, 2, 3, 10);
    a.dtype = DataFormat::Double;
    b.dtype = DataFormat::Float;
    ASSERT_TRUE(AddInto(&a, b));
    EXPECT_EQ(a.dtype, DataFormat::Float);
    Matrix pic = Random(2, 2, 3, 11);
    pic.dtype = DataFormat::RGBE;
    Matrix p = Multiply(a, pic);
    EXPECT_EQ(p.dtype, DataFormat::Double);
    EXPECT_EQ(p.info, "WARNING: data type mismatch\n");
}

}  // namespace
}  // namespace dayflux
