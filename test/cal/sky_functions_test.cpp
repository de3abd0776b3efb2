// lib/skybright.cal, perezlum.cal and disk2square.cal: analytic checks.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "cal/calcomp.h"

namespace dayflux::cal {
namespace {

std::string Lib(const char *f) { return std::string(DAYFLUX_LIB_DIR) + "/" + f; }

double At(const Context &cx, const std::string &f, double dx, double dy, double dz,
          std::vector<double> args) {
    ChannelArray ray(std::vector<double>(27, 0.0));
    ray.values()[0] = dx, ray.values()[1] = dy, ray.values()[2] = dz;
    ray.SetObjectArguments(std::move(args));
    return cx.Value(f, &ray);
}

TEST(SkyFunctions, GenskySkies) {
    Context cx;
    cx.LoadRayInit();
    cx.LoadFile(Lib("skybright.cal"));
    const double w = std::pow(2.01, 10), g = std::pow(2.01, -10);
    // Uniform sky: the zenith brightness, blended a little with the ground at the zenith.
    EXPECT_NEAR(At(cx, "skybr", 0, 0, 1, {3, 5, 1, 1, 0, 0, 1}), (w * 5 + g * 1) / (w + g), 1e-12);
    // CIE overcast: the zenith is three times as bright as the horizon.
    const double zenith = At(cx, "skybr", 0, 0, 1, {2, 3, 0, 1, 0, 0, 1});
    const double w0 = std::pow(1.01, 10);
    const double horizon = At(cx, "skybr", 1, 0, 0, {2, 3, 0, 1, 0, 0, 1}) * (w0 + 1 / w0) / w0;
    EXPECT_NEAR(zenith * (w + g) / w, 3, 1e-12);
    EXPECT_NEAR(horizon, 1, 1e-12);
    // Below the horizon the ground brightness takes over.
    EXPECT_NEAR(At(cx, "skybr", 0, 0, -1, {2, 3, 0.4, 1, 0, 0, 1}), 0.4, 1e-3);
}

TEST(SkyFunctions, PerezSkyAtTheZenith) {
    Context cx;
    cx.LoadRayInit();
    cx.LoadFile(Lib("perezlum.cal"));
    // Sun at the zenith: gamma = 0 there, so L = A1 (1 + a e^b)(1 + c + e).
    const std::vector<double> a = {2, 0.1, -1, -0.3, 3, -2, 0.5, 0, 0, 1};
    const double w = std::pow(2.01, 10), g = std::pow(2.01, -10);
    const double l = 2 * (1 + -1 * std::exp(-0.3)) * (1 + 3 + 0.5);
    EXPECT_NEAR(At(cx, "skybright", 0, 0, 1, a), (w * l + g * 0.1) / (w + g), 1e-12);
}

TEST(SkyFunctions, ShirleyChiuMapRoundTripsAndBins) {
    Context cx;
    cx.LoadRayInit();
    cx.LoadFile(Lib("disk2square.cal"));
    std::mt19937 rng(2);
    std::uniform_real_distribution<double> u(0.001, 0.999);
    for (int i = 0; i < 2000; ++i) {
        const double sx = u(rng), sy = u(rng);
        cx.Set("in_square_x", sx);
        cx.Set("in_square_y", sy);
        const double dx = cx.Value("out_disk_x"), dy = cx.Value("out_disk_y");
        ASSERT_LE(dx * dx + dy * dy, 1 + 1e-12);
        cx.Set("in_disk_x", dx);
        cx.Set("in_disk_y", dy);
        EXPECT_NEAR(cx.Value("out_square_x"), sx, 1e-9);
        EXPECT_NEAR(cx.Value("out_square_y"), sy, 1e-9);
    }
}

TEST(SkyFunctions, ScbinCoversTheHemisphere) {
    Context cx;
    cx.LoadRayInit();
    cx.LoadFile(Lib("disk2square.cal"));
    cx.Load("SCdim = 4; rNx = 0; rNy = 0; rNz = -1; Ux = 0; Uy = 1; Uz = 0;", FileLoc{"-p", 0});
    Expression bin = cx.Compile("scbin", FileLoc{"-b", 0});
    // A sky receiver (normal rN = -Z, away from the sky dome's inside): cosine-weighted rays going
    // up reach it. The map preserves area, so the 16 bins fill evenly.
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<int> count(16, 0);
    ChannelArray ray(std::vector<double>(27, 0.0));
    const int n = 16000;
    for (int i = 0; i < n; ++i) {
        const double r = std::sqrt(u(rng)), phi = 2 * M_PI * u(rng);
        ray.values()[0] = -r * std::cos(phi), ray.values()[1] = -r * std::sin(phi);
        ray.values()[2] = std::sqrt(1 - r * r);
        const int b = static_cast<int>(bin.Evaluate(cx, &ray));
        ASSERT_GE(b, 0);
        ASSERT_LT(b, 16);
        ++count[b];
    }
    // Binomial standard deviation of each count: sqrt(n p (1-p)) with p = 1/16; allow 5 sigma.
    const double mean = n / 16.0, sd = std::sqrt(n * (1 / 16.0) * (15 / 16.0));
    for (int c : count) EXPECT_NEAR(c, mean, 5 * sd);
    ray.values()[2] = -0.5;  // going down: from behind
    EXPECT_EQ(bin.Evaluate(cx, &ray), -1);
}

}  // namespace
}  // namespace dayflux::cal
