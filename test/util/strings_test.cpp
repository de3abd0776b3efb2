#include "util/strings.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

namespace dayflux {
namespace {

std::string Printf(double v, int p) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*g", p, v);
    return buf;
}

std::string Ours(double v, int p) {
    std::string s;
    AppendGeneral(&s, v, p);
    return s;
}

// Every float a sky matrix can hold, printed as printf prints it: random floats over many decades,
// all floats in a few of them, and values at and around the rounding ties.
TEST(Strings, GeneralFormatIsPrintfs) {
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> mant(1, 10);
    std::uniform_int_distribution<int> expo(-40, 40);
    for (int i = 0; i < 2000000; ++i) {
        const float f =
            static_cast<float>(mant(rng) * std::pow(10.0, expo(rng)) * (i % 7 ? 1 : -1));
        for (int p : {3, 6}) ASSERT_EQ(Ours(f, p), Printf(f, p)) << f;
    }
    for (float f = 0.001f; f < 2000.f; f = std::nextafter(f, 1e9f) + f * 1e-5f)
        ASSERT_EQ(Ours(f, 3), Printf(f, 3)) << f;
    for (double v : std::initializer_list<double>{
             0.0,          -0.0,     1.0,        0.125, 1.125,    2.5,   999.5,
             9995.0,       0.0001,   0.00001234, 1e-5,  123456.0, 1e300, 1e-310,
             std::nan(""), INFINITY, -INFINITY,  13.8,  1920.0,   0.1,   100.0})
        for (int p : {1, 3, 6, 15}) EXPECT_EQ(Ours(v, p), Printf(v, p)) << v << " %." << p << "g";
}

}  // namespace
}  // namespace dayflux
