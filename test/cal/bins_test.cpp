// Our lib/ bin functions against the patch geometry of src/sky and the Klems bases.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "cal/calcomp.h"
#include "matrix/bsdf_xml.h"
#include "sky/patches.h"

namespace dayflux::cal {
namespace {

std::string Lib(const char *f) { return std::string(DAYFLUX_LIB_DIR) + "/" + f; }

std::vector<std::array<double, 3>> RandomDirections(int n, unsigned seed) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> g;
    std::vector<std::array<double, 3>> d(n);
    for (auto &v : d) {
        double x = g(rng), y = g(rng), z = g(rng), r = std::sqrt(x * x + y * y + z * z);
        v = {x / r, y / r, z / r};
    }
    return d;
}

TEST(BinFunctions, TregenzaMatchesPatchGeometry) {
    Context cx;
    cx.LoadRayInit();
    cx.LoadFile(Lib("tregenza.cal"));
    EXPECT_EQ(cx.Value("Ntbins"), 146);
    Expression bin = cx.Compile("tbin", FileLoc{"-b", 0});
    SkyPatchBasis sky(1);
    ChannelArray ray(std::vector<double>(27, 0.0));
    for (const auto &d : RandomDirections(20000, 1)) {
        std::copy(d.begin(), d.end(), ray.values().begin());
        ASSERT_EQ(bin.Evaluate(cx, &ray), sky.Bin(d[0], d[1], d[2]))
            << d[0] << " " << d[1] << " " << d[2];
    }
}

TEST(BinFunctions, ReinhartMatchesPatchGeometryForMF1To6) {
    for (int mf = 1; mf <= 6; ++mf) {
        Context cx;
        cx.LoadRayInit();
        cx.Set("MF", mf, true);
        cx.LoadFile(Lib("reinhart.cal"));
        SkyPatchBasis sky(mf);
        EXPECT_EQ(cx.Value("Nrbins"), sky.Size()) << "MF " << mf;
        Expression bin = cx.Compile("rbin", FileLoc{"-b", 0});
        ChannelArray ray(std::vector<double>(27, 0.0));
        for (const auto &d : RandomDirections(5000, mf)) {
            std::copy(d.begin(), d.end(), ray.values().begin());
            ASSERT_EQ(bin.Evaluate(cx, &ray), sky.Bin(d[0], d[1], d[2])) << "MF " << mf;
        }
        // Every patch centre lands in its own bin.
        for (int p = 1; p < sky.Size(); ++p) {
            double v[3];
            sky.Direction(p, v);
            std::copy(v, v + 3, ray.values().begin());
            ASSERT_EQ(bin.Evaluate(cx, &ray), p) << "MF " << mf;
        }
    }
}

// reinhartb.cal with its defaults (rN = -Z, U = +Y) is reinhart.cal counted from 0, ground -1.
TEST(BinFunctions, ReinhartbDefaultsAgreeWithReinhart) {
    Context cx;
    cx.LoadRayInit();
    cx.LoadFile(Lib("reinhartb.cal"));
    cx.Set("MF", 2);
    SkyPatchBasis sky(2);
    EXPECT_EQ(cx.Value("Nrbins"), sky.Size() - 1);
    Expression bin = cx.Compile("rbin", FileLoc{"-b", 0});
    ChannelArray ray(std::vector<double>(27, 0.0));
    for (const auto &d : RandomDirections(5000, 9)) {
        std::copy(d.begin(), d.end(), ray.values().begin());
        ASSERT_EQ(bin.Evaluate(cx, &ray), sky.Bin(d[0], d[1], d[2]) - 1);
    }
}

// kbin(N, U) bins the incoming direction -D; with N = +Z, U = +Y and RHS = 1 the frame is the
// basis's own: polar angle from N, azimuth from +X (= U x N) toward +Y.
TEST(BinFunctions, KlemsMatchTheAngleBases) {
    const char *files[] = {"klems_full.cal", "klems_half.cal", "klems_quarter.cal"};
    const char *fn[] = {"kbin", "khbin", "kqbin"};
    const char *count[] = {"Nkbins", "Nkhbins", "Nkqbins"};
    for (int b = 0; b < 3; ++b) {
        Context cx;
        cx.LoadRayInit();
        cx.LoadFile(Lib(files[b]));
        const AngleBasis &basis = KlemsBases()[b];
        EXPECT_EQ(cx.Value(count[b]), basis.Size());
        Expression bin = cx.Compile(std::string(fn[b]) + "(0,0,1, 0,1,0)", FileLoc{"-b", 0});
        ChannelArray ray(std::vector<double>(27, 0.0));
        for (const auto &d : RandomDirections(20000, 20 + b)) {
            std::copy(d.begin(), d.end(), ray.values().begin());
            ASSERT_EQ(bin.Evaluate(cx, &ray), basis.IndexOf(-d[0], -d[1], -d[2])) << files[b];
        }
    }
}

}  // namespace
}  // namespace dayflux::cal
