#include "matrix/rgbe.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace dayflux {
namespace {

TEST(Rgbe, ColourConversionKeepsEightBits) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(0, 1);
    for (int i = 0; i < 10000; ++i) {
        double scale = std::pow(10.0, u(rng) * 20 - 10);
        double c[3] = {u(rng) * scale, u(rng) * scale, u(rng) * scale};
        float back[3];
        FromColr(ToColr(c[0], c[1], c[2]), back);
        double big = std::max({c[0], c[1], c[2]});
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(back[k], c[k], big / 256) << c[k];
    }
    EXPECT_EQ(ToColr(0, 0, 0), (Colr{0, 0, 0, 0}));
    EXPECT_EQ(ToColr(-1, 0, 0), (Colr{0, 0, 0, 0}));
    EXPECT_EQ(ToColr(1, 0.5, 0)[3], 129);  // 1 = 0.5 * 2^1: mantissa 128, exponent 128 + 1
}

TEST(Rgbe, RunLengthEncodingRoundTrips) {
    std::mt19937 rng(17);
    for (int len : {1, 7, 8, 9, 127, 128, 129, 300, 1000}) {
        std::vector<Colr> scan(len);
        for (int i = 0; i < len; ++i) {
            // Runs of varying length mixed with literal stretches.
            if (i > 0 && rng() % 3) {
                scan[i] = scan[i - 1];
            } else {
                for (auto &b : scan[i]) {
                    b = static_cast<uint8_t>(rng() % 4 ? rng() : 7);
                }
            }
        }
        std::string bytes;
        EncodeScanline(scan.data(), len, &bytes);
        if (len < 8) {
            EXPECT_EQ(bytes.size(), 4u * len);  // short lines are flat
        }
        auto in = InputSource::FromString(bytes, "scan");
        std::vector<Colr> back(len);
        ASSERT_TRUE(DecodeScanline(*in, back.data(), len)) << len;
        EXPECT_EQ(back, scan) << len;
        EXPECT_TRUE(in->AtEnd());
    }
}

TEST(Rgbe, ConstantScanlineCompresses) {
    std::vector<Colr> scan(1000, Colr{10, 20, 30, 130});
    std::string bytes;
    EncodeScanline(scan.data(), 1000, &bytes);
    EXPECT_LT(bytes.size(), 80u);
}

TEST(Rgbe, CorruptScanlineIsRejected) {
    std::vector<Colr> scan(16, Colr{1, 2, 3, 4});
    std::string bytes;
    EncodeScanline(scan.data(), 16, &bytes);
    bytes[3] = 17;  // announced length differs
    auto in = InputSource::FromString(bytes, "scan");
    std::vector<Colr> back(16);
    EXPECT_FALSE(DecodeScanline(*in, back.data(), 16));
}

}  // namespace
}  // namespace dayflux
