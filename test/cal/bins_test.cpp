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

// kbin, khbin and kqbin are computed directly (direct_bins.h) with the .cal files' arithmetic:
// the same bins as the interpreter in every frame and handedness, on random directions and on
// those along the rings' edges (and just off them: the ring is found by cosines away from an
// edge, by acos near it) and the patches' edges, where a different order of operations would
// round across a boundary.
TEST(BinFunctions, KlemsComputedDirectlyAsTheCalFiles) {
    const char *files[] = {"klems_full.cal", "klems_half.cal", "klems_quarter.cal"};
    const char *fn[] = {"kbin", "khbin", "kqbin"};
    const char *frames[] = {"(0,0,1, 0,1,0)", "(0,-1,0, 0,0,1)", "(0.6,0,-0.8, 0,1,0)",
                            "(-0.267261,0.534522,0.801784, 0,0.83205,-0.5547)"};
    for (int b = 0; b < 3; ++b) {
        for (const char *rhs : {"1", "-1"}) {
            Context cx;
            cx.LoadRayInit();
            cx.LoadFile(Lib(files[b]));
            cx.Load(std::string("RHS = ") + rhs + ";", FileLoc{"-p", 0});
            // directions on the edges of the basis's own frame (N = +Z, U = +Y): rings at
            // polar angles kpola(r), patches' edges at multiples of 360 / knaz(r) plus half a patch
            std::vector<std::array<double, 3>> dirs = RandomDirections(20000, 40 + b);
            const int rings = static_cast<int>(cx.Value("kpola(0)"));
            for (int r = 1; r <= rings; ++r) {
                const double pol = cx.Value("kpola(" + std::to_string(r) + ")") * M_PI / 180;
                const double n = cx.Value("knaz(" + std::to_string(r) + ")");
                for (int k = 0; k < n; ++k) {  // patches centred on multiples of 360 / n
                    const double azi = (k + .5) * 2 * M_PI / n;
                    // on the edge and about it: where the ring is decided by cosines (clear of
                    // the edge by 1e-9) and by acos (within it), both sides of that limit
                    for (double off : {0., 1e-12, -1e-12, 3e-9, -3e-9, 1e-7, -1e-7}) {
                        const double p = pol + off;
                        dirs.push_back({-std::sin(p) * std::cos(azi), -std::sin(p) * std::sin(azi),
                                        -std::cos(p)});
                    }
                }
            }
            for (const char *frame : frames) {
                const std::string text = std::string(fn[b]) + frame;
                const Expression direct = cx.Compile(text, FileLoc{"-b", 0});
                const Expression interpreted = cx.CompileInterpreted(text, FileLoc{"-b", 0});
                ASSERT_TRUE(direct.Direct()) << text;
                ChannelArray ray(std::vector<double>(27, 0.0));
                for (const auto &d : dirs) {
                    std::copy(d.begin(), d.end(), ray.values().begin());
                    ASSERT_EQ(direct.Evaluate(cx, &ray), interpreted.Evaluate(cx, &ray))
                        << files[b] << " RHS=" << rhs << " " << frame << " at " << d[0] << " "
                        << d[1] << " " << d[2];
                }
            }
        }
    }
}

// reinhart.cal's rbin is computed directly too (direct_bins.h), at every MF (3: division by MF
// is multiplication by a reciprocal that is not exact): the interpreter's bins on random
// directions and on every row's and patch's edge; reinhartb.cal's rbin (rfluxmtx's, in a frame
// of its own) keeps the calcomp program.
TEST(BinFunctions, ReinhartComputedDirectlyAsTheCalFile) {
    for (int mf : {1, 2, 3, 4}) {
        Context cx;
        cx.LoadRayInit();
        cx.Load("MF : " + std::to_string(mf) + ";", FileLoc{"-e", 0});
        cx.LoadFile(Lib("reinhart.cal"));
        const Expression direct = cx.Compile("rbin", FileLoc{"-b", 0});
        const Expression interpreted = cx.CompileInterpreted("rbin", FileLoc{"-b", 0});
        ASSERT_TRUE(direct.Direct()) << "MF " << mf;
        std::vector<std::array<double, 3>> dirs = RandomDirections(20000, 60 + mf);
        const double alpha = cx.Value("ralpha");
        for (int r = 0; r <= 7 * mf; ++r) {
            const double n = cx.Value("rnaz(" + std::to_string(r) + ")");
            for (double alt : {r * alpha, (r + .5) * alpha}) {
                const double a = std::min(alt, 90.) * M_PI / 180;
                for (int j = 0; j < n; ++j) {  // patches centred on multiples of 360 / n
                    const double azi = (j + .5) * 2 * M_PI / n;
                    dirs.push_back(
                        {std::cos(a) * std::sin(azi), std::cos(a) * std::cos(azi), std::sin(a)});
                }
            }
        }
        ChannelArray ray(std::vector<double>(27, 0.0));
        for (const auto &d : dirs) {
            std::copy(d.begin(), d.end(), ray.values().begin());
            ASSERT_EQ(direct.Evaluate(cx, &ray), interpreted.Evaluate(cx, &ray))
                << "MF " << mf << " at " << d[0] << " " << d[1] << " " << d[2];
        }
    }
    Context framed;
    framed.LoadRayInit();
    framed.Load("MF : 1;", FileLoc{"-e", 0});
    framed.LoadFile(Lib("reinhartb.cal"));
    EXPECT_FALSE(framed.Compile("rbin", FileLoc{"-b", 0}).Direct());
}

// Where the call is not the files' own, the calcomp program stays: an argument that is not a
// number, a redefined ring table (kring still holds the old edges, so the bins would differ),
// or another function of the same name.
TEST(BinFunctions, KlemsDirectOnlyForTheFilesOwnFunction) {
    Context cx;
    cx.LoadRayInit();
    cx.LoadFile(Lib("klems_full.cal"));
    EXPECT_TRUE(cx.Compile("kbin(0,0,1,0,1,0)", FileLoc{"-b", 0}).Direct());
    EXPECT_FALSE(cx.Compile("kbin(0,0,1,0,1,Dx)", FileLoc{"-b", 0}).Direct());
    EXPECT_FALSE(cx.Compile("kbin(0,0,1,0,1,0) + 0", FileLoc{"-b", 0}).Direct());
    Context redefined;
    redefined.LoadRayInit();
    redefined.LoadFile(Lib("klems_full.cal"));
    redefined.Load("kpola(r) : select(r, 10, 20, 30, 40, 50, 60, 70, 80, 90);", FileLoc{"-e", 0});
    EXPECT_FALSE(redefined.Compile("kbin(0,0,1,0,1,0)", FileLoc{"-b", 0}).Direct());
    Context other;
    other.LoadRayInit();
    other.Load("kbin(a,b,c,d,e,f) = Dx + 1;", FileLoc{"-e", 0});
    EXPECT_FALSE(other.Compile("kbin(0,0,1,0,1,0)", FileLoc{"-b", 0}).Direct());
}

}  // namespace
}  // namespace dayflux::cal
