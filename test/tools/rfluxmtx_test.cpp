// rfluxmtx-gpu end to end: sender bins that reach exactly their own receiver bins, the sender's
// rays spread by projected solid angle and over its surfaces by area, RADIANCE's own regression
// reference (rfmirror.mtx), pass-through mode as rcontrib, receivers' own outputs, bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "matrix/matrices.h"
#include "test_util.h"

namespace dayflux::test {
namespace {

// A receiver sky of radiance 1 over the upper hemisphere, binned by basis (up +Y).
std::string SkyReceiver(const std::string &basis) {
    return "#@rfluxmtx h=" + basis +
           " u=+Y\nvoid glow skyglow 0 0 4 1 1 1 0\nskyglow source sky 0 0 4 0 0 1 180\n";
}

// The unit square at z = 0 facing down, so that its rays leave upward (out of its back).
std::string SquareSender(const std::string &basis) {
    return "#@rfluxmtx h=" + basis +
           " u=+Y\nvoid polygon window 0 0 12  0 0 0  0 1 0  1 1 0  1 0 0\n";
}

Matrix RunFlux(const TempDir &tmp, const std::string &args) {
    const CommandResult r = RunCommand("rfluxmtx-gpu " + args + " > out.mtx", tmp.path());
    EXPECT_EQ(r.status, 0) << args << "\n" << r.err;
    if (r.status != 0) return Matrix{};
    return LoadMatrix((tmp.path() / "out.mtx").string());
}

class SenderBasis : public testing::TestWithParam<const char *> {};

// With the receiver's frame the sender's (the sky source's normal is the sender's), every ray
// of a sender bin lands in the receiver bin of the same number: the matrix is the identity.
TEST_P(SenderBasis, EachBinReachesItsOwnReceiverBin) {
    TempDir tmp;
    WriteFile(tmp.path() / "sender.rad", SquareSender(GetParam()));
    WriteFile(tmp.path() / "sky.rad", SkyReceiver(GetParam()));
    const Matrix m = RunFlux(tmp, "-c 20 -ab 0 sender.rad sky.rad");
    ASSERT_GT(m.rows, 1);
    ASSERT_EQ(m.rows, m.cols);
    for (int r = 0; r < m.rows; ++r)
        for (int c = 0; c < m.cols; ++c)
            ASSERT_EQ(m.at(r, c, 0), r == c ? 1.0 : 0.0)
                << GetParam() << " row " << r << " col " << c;
}

INSTANTIATE_TEST_SUITE_P(Rfluxmtx, SenderBasis,
                         testing::Values("kf", "kh", "kq", "-kf", "r1", "r2", "-r1", "sc4", "sc5"),
                         [](const testing::TestParamInfo<const char *> &info) {
                             std::string name = info.param;
                             return name[0] == '-' ? "LeftHanded_" + name.substr(1) : name;
                         });

struct XformedSender {
    const char *name;
    const char *xform;  // applied to SquareSender("kf")
    bool faces_the_sky;
};

class SenderThroughXform : public testing::TestWithParam<XformedSender> {};

// "!xform" in a sender file is done in-process (no xform program needed): moved and turned about
// its normal (also within a file that xform reads), the square still sends each bin to its own;
// mirrored across x its front stays its front (xform reverses the vertices); mirrored across z it
// is turned over and sends nothing up.
TEST_P(SenderThroughXform, KeepsItsBinsAndItsFront) {
    const XformedSender &x = GetParam();
    TempDir tmp;
    WriteFile(tmp.path() / "square.rad", SquareSender("kf"));
    WriteFile(tmp.path() / "turned.rad", "!xform -rz 30 square.rad\n");
    WriteFile(tmp.path() / "sender.rad", std::string("!xform ") + x.xform + " square.rad\n");
    WriteFile(tmp.path() / "sky.rad", SkyReceiver("kf"));
    const Matrix m = RunFlux(tmp, "-c 20 -ab 0 sender.rad sky.rad");
    ASSERT_EQ(m.rows, 145);
    ASSERT_EQ(m.cols, 145);
    for (int r = 0; r < m.rows; ++r)
        for (int c = 0; c < m.cols; ++c)
            ASSERT_EQ(m.at(r, c, 0), x.faces_the_sky && r == c ? 1.0 : 0.0)
                << x.xform << " row " << r << " col " << c;
}

INSTANTIATE_TEST_SUITE_P(
    Rfluxmtx, SenderThroughXform,
    testing::Values(XformedSender{"MovedAndTurned", "-rz 90 -t 5 -3 2 -s 2", true},
                    XformedSender{"MirroredAcross", "-mx -t 1 0 0", true},
                    XformedSender{"TurnedOver", "-mz", false},
                    XformedSender{"NestedAndTwoFiles", "-n outer -t 1 1 0 turned.rad", true}),
    [](const testing::TestParamInfo<XformedSender> &info) { return std::string(info.param.name); });

// h=u: the sender's rays are cosine-weighted, so a sky patch between altitudes a0 and a1 with n
// patches in its band gets (sin^2 a1 - sin^2 a0) / n of them; each band likewise in total.
// Tolerances: 4 binomial standard errors (the stratified samples do better).
TEST(Rfluxmtx, UniformSenderSeesTheSkyByProjectedSolidAngle) {
    TempDir tmp;
    WriteFile(tmp.path() / "sender.rad", SquareSender("u"));
    WriteFile(tmp.path() / "sky.rad", SkyReceiver("r1"));
    const int n = 20000;
    const Matrix m = RunFlux(tmp, "-c " + std::to_string(n) + " -ab 0 sender.rad sky.rad");
    ASSERT_EQ(m.rows, 1);
    ASSERT_EQ(m.cols, 145);
    const int per_band[8] = {30, 30, 24, 24, 18, 12, 6, 1};
    const double band_height = M_PI / 2 / 7.5;
    int patch = 0;
    for (int band = 0; band < 8; ++band) {
        const double s0 = std::sin(band * band_height);
        const double s1 = band == 7 ? 1.0 : std::sin((band + 1) * band_height);
        const double band_share = s1 * s1 - s0 * s0;
        double band_total = 0;
        for (int k = 0; k < per_band[band]; ++k, ++patch) {
            const double f = band_share / per_band[band];
            EXPECT_NEAR(m.at(0, patch, 0), f, 4 * std::sqrt(f * (1 - f) / n)) << "patch " << patch;
            band_total += m.at(0, patch, 0);
        }
        EXPECT_NEAR(band_total, band_share, 4 * std::sqrt(band_share * (1 - band_share) / n))
            << "band " << band;
    }
}

struct Shape {
    const char *name;
    const char *sender;  // facing down (normal -Z), its rays going up
    const char *cover;   // a black polygon just above part of it
    double uncovered;    // the share of the sender's area left open
};

class SenderShape : public testing::TestWithParam<Shape> {};

// The sender's rays start all over its surfaces in proportion to their area: a black cover over
// part of it stops that part's share.
TEST_P(SenderShape, RaysLeaveEveryPartByItsArea) {
    const Shape &s = GetParam();
    TempDir tmp;
    WriteFile(tmp.path() / "sender.rad", std::string("#@rfluxmtx h=u u=+Y\n") + s.sender);
    WriteFile(tmp.path() / "sky.rad", SkyReceiver("u"));
    WriteFile(
        tmp.path() / "cover.rad",
        std::string("void plastic black 0 0 5 0 0 0 0 0\nblack polygon cover 0 0 12 ") + s.cover);
    const int n = 4000;
    const Matrix m =
        RunFlux(tmp, "-c " + std::to_string(n) + " -ab 0 sender.rad sky.rad cover.rad");
    ASSERT_EQ(m.rows, 1);
    ASSERT_EQ(m.cols, 1);
    const double p = s.uncovered;
    EXPECT_NEAR(m.at(0, 0, 0), p, 4 * std::sqrt(p * (1 - p) / n)) << s.name;
}

INSTANTIATE_TEST_SUITE_P(
    Rfluxmtx, SenderShape,
    testing::Values(Shape{"Square", "void polygon w 0 0 12  0 0 0  0 1 0  1 1 0  1 0 0",
                          "-1 -1 1e-4  .5 -1 1e-4  .5 2 1e-4  -1 2 1e-4", 0.5},
                    Shape{"ConcaveL",
                          "void polygon w 0 0 18  0 0 0  0 2 0  1 2 0  1 1 0  2 1 0  2 0 0",
                          "-1 1 1e-4  3 1 1e-4  3 3 1e-4  -1 3 1e-4", 2. / 3.},
                    Shape{"RingWithAHole", "void ring w 0 0 8  0 0 0  0 0 -1  .5 1",
                          "-2 -2 1e-4  0 -2 1e-4  0 2 1e-4  -2 2 1e-4", 0.5},
                    Shape{"TwoPolygons",
                          "void polygon a 0 0 12  0 0 0  0 1 0  1 1 0  1 0 0\n"
                          "void polygon b 0 0 12  2 0 0  2 1 0  5 1 0  5 0 0",
                          "1.5 -1 1e-4  6 -1 1e-4  6 2 1e-4  1.5 2 1e-4", 0.25}),
    [](const testing::TestParamInfo<Shape> &info) { return std::string(info.param.name); });

// RADIANCE's regression test of rfluxmtx (test/renders: a Klems sender on a mirror, a ground and
// Tregenza sky receiver, the diorama around them; its reference was traced with -c 10000, ours
// with -c 100). The rcontrib command is RADIANCE's, word for word; the rows (each a sender bin)
// agree: their relative errors average to zero within 4 of their standard errors, and scatter
// as 100 samples a bin should. (At RADIANCE's -c 10000, 7 minutes on 2 cores, ours passes
// RADIANCE's own check, `radcompare -max .4 -rms .05 -rel 1e-4`, checked with its radcompare.)
TEST(Rfluxmtx, MirrorAgreesWithRadiance) {
    TempDir tmp;
    const auto scene = DataDir() / "rfluxmtx" / "mirror";
    const CommandResult r = RunCommand(
        "rfluxmtx-gpu -c 100 -ab 2 -lw 1e-4 mirror.rad dummysky.rad basic.mat diorama_walls.rad "
        "closed_end.rad front_cap.rad glass_pane.rad antimatter_portal.rad > " +
            (tmp.path() / "out.mtx").string(),
        scene);
    ASSERT_EQ(r.status, 0) << r.err;
    const std::string header = ReadFile(tmp.path() / "out.mtx").substr(0, 2000);
    EXPECT_NE(header.find("rcontrib-gpu -fo+ -ab 2 -lw 1e-4 -fda -c 100 -bn 1 -b "
                          "if(-Dx*0-Dy*0-Dz*1,0,-1) -m groundglow -f reinhartb.cal -p "
                          "MF=1,rNx=0,rNy=0,rNz=-1,Ux=0,Uy=1,Uz=0,RHS=+1 -bn Nrbins -b rbin -m "
                          "skyglow -y 145\n"),
              std::string::npos)
        << header;
    const Matrix ours = LoadMatrix((tmp.path() / "out.mtx").string());
    // RADIANCE's test.mtx is rfmirror.mtx transposed (rcollate -t).
    const Matrix ref = LoadMatrix((DataDir() / "radiance_util" / "test.mtx").string());
    ASSERT_EQ(ours.rows, 145);
    ASSERT_EQ(ours.cols, 146);
    ASSERT_EQ(ref.rows, 146);
    ASSERT_EQ(ref.cols, 145);
    std::vector<double> errors;
    for (int row = 0; row < ours.rows; ++row) {
        double a = 0, b = 0;
        for (int col = 0; col < ours.cols; ++col)
            for (int k = 0; k < 3; ++k) a += ref.at(col, row, k), b += ours.at(row, col, k);
        ASSERT_GT(a, 0);
        errors.push_back(b / a - 1);
    }
    double mean = 0, var = 0;
    for (double e : errors) mean += e / errors.size();
    for (double e : errors) var += (e - mean) * (e - mean) / (errors.size() - 1);
    const double sd = std::sqrt(var);
    EXPECT_LT(std::fabs(mean), 4 * sd / std::sqrt(errors.size())) << "mean " << mean;
    EXPECT_LT(sd, 0.06);  // 0.025 is typical at -c 100
}

// Sender "-": the rays come from the input and rfluxmtx only adds the receivers to rcontrib.
TEST(Rfluxmtx, PassThroughIsRcontrib) {
    TempDir tmp;
    WriteFile(tmp.path() / "sky.rad", SkyReceiver("r1"));
    WriteFile(tmp.path() / "room.rad",
              "void plastic grey 0 0 5 .5 .5 .5 0 0\ngrey polygon floor 0 0 12 -5 -5 -1 5 -5 -1 "
              "5 5 -1 -5 5 -1\ngrey polygon wall 0 0 12 2 -5 -1 2 5 -1 2 5 3 2 -5 3\n");
    WriteFile(tmp.path() / "rays", "0 0 0 0 0 1\n0 0 0 1 0 0\n0 0 0 0 1 1\n0 0 0 1 0 .2\n");
    const CommandResult flux = RunCommand(
        "rfluxmtx-gpu -ab 2 -ad 64 -lw 1e-3 -I+ -h - sky.rad room.rad < rays", tmp.path());
    ASSERT_EQ(flux.status, 0) << flux.err;
    const CommandResult rc = RunCommand(
        "rcontrib-gpu -ab 2 -ad 64 -lw 1e-3 -I+ -h -faa -c 1 -f reinhartb.cal -p "
        "MF=1,rNx=0,rNy=0,rNz=-1,Ux=0,Uy=1,Uz=0,RHS=+1 -bn Nrbins -b rbin -m skyglow room.rad "
        "sky.rad < rays",
        tmp.path());
    ASSERT_EQ(rc.status, 0) << rc.err;
    EXPECT_EQ(flux.out, rc.out);
    EXPECT_GT(flux.out.size(), 4 * 145 * 3 * 2u);
}

// The tutorial's view-matrix pictures: vwrays' float rays (here made by hand, 4 x 3 pixels of 2
// rays each) through pass-through mode with -ffc, vwrays -d's -x -y -ld-, and -o: a picture per
// Klems bin with its resolution.
TEST(Rfluxmtx, ViewMatrixPictures) {
    TempDir tmp;
    WriteFile(tmp.path() / "window.rad",
              "void glow Glazing 0 0 4 1 1 1 0\n#@rfluxmtx h=kf u=Z\n"
              "Glazing polygon w 0 0 12  -1 1 0  1 1 0  1 1 2  -1 1 2\n");
    std::string rays;
    for (int y = 0; y < 3; ++y)
        for (int x = 0; x < 4; ++x)
            for (int k = 0; k < 2; ++k) {
                const float ray[6] = {0, 0, 1, (x - 1.5f) / 4, 1, (1 - y) / 4.f};
                rays.append(reinterpret_cast<const char *>(ray), sizeof ray);
            }
    WriteFile(tmp.path() / "rays", rays);
    const CommandResult r = RunCommand(
        "rfluxmtx-gpu -v -ffc -x 4 -y 3 -ld- -o pic%03d.hdr -ab 1 -ad 16 -c 2 - window.rad < rays",
        tmp.path());
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("running: rcontrib-gpu -fo+ -o pic%03d.hdr -ab 1 -ad 16 -x 4 -y 3 -ld- "
                         "-ffc -c 2 -f klems_full.cal -p RHS=+1 -bn Nkbins -b "
                         "'kbin(0,-1,0,0,0,1)' -m Glazing"),
              std::string::npos)
        << r.err;
    for (int bin : {0, 144}) {
        char name[16];
        std::snprintf(name, sizeof name, "pic%03d.hdr", bin);
        const std::string pic = ReadFile(tmp.path() / name);
        EXPECT_NE(pic.find("FORMAT=32-bit_rle_rgbe\n\n-Y 3 +X 4\n"), std::string::npos) << name;
        EXPECT_NE(pic.find("BIN=" + std::to_string(bin) + "\n"), std::string::npos) << name;
    }
    EXPECT_FALSE(std::filesystem::exists(tmp.path() / "pic145.hdr"));
}

// o= sends a receiver's columns to its own file (and nothing to the standard output).
TEST(Rfluxmtx, ReceiversWriteTheirOwnOutputs) {
    TempDir tmp;
    WriteFile(tmp.path() / "sender.rad", SquareSender("kq"));
    WriteFile(tmp.path() / "sky.rad",
              "#@rfluxmtx h=u o=ground.mtx\nvoid glow groundglow 0 0 4 1 1 1 0\n"
              "groundglow source ground 0 0 4 0 0 -1 180\n"
              "#@rfluxmtx h=kq u=+Y o=sky.mtx\nvoid glow skyglow 0 0 4 1 1 1 0\n"
              "skyglow source sky 0 0 4 0 0 1 180\n");
    const CommandResult r = RunCommand("rfluxmtx-gpu -c 10 -ab 0 sender.rad sky.rad", tmp.path());
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.out, "");
    const Matrix ground = LoadMatrix((tmp.path() / "ground.mtx").string());
    const Matrix sky = LoadMatrix((tmp.path() / "sky.mtx").string());
    ASSERT_EQ(ground.rows, 41);
    ASSERT_EQ(ground.cols, 1);
    ASSERT_EQ(sky.rows, 41);
    ASSERT_EQ(sky.cols, 41);
    for (int row = 0; row < 41; ++row) {
        EXPECT_EQ(ground.at(row, 0, 0), 0.0);
        EXPECT_EQ(sky.at(row, row, 0), 1.0);
    }
}

struct BadInput {
    const char *name;
    const char *sender, *receiver;  // file contents ("" for none)
    const char *args;               // before sender.rad receiver.rad
    const char *message;            // what the error says
};

class RfluxmtxBadInput : public testing::TestWithParam<BadInput> {};

TEST_P(RfluxmtxBadInput, IsReportedWithItsPlace) {
    const BadInput &b = GetParam();
    TempDir tmp;
    if (*b.sender) WriteFile(tmp.path() / "sender.rad", b.sender);
    if (*b.receiver) WriteFile(tmp.path() / "sky.rad", b.receiver);
    const CommandResult r =
        RunCommand(std::string("rfluxmtx-gpu ") + b.args + " sender.rad sky.rad", tmp.path());
    EXPECT_NE(r.status, 0) << b.name;
    EXPECT_NE(r.err.find(b.message), std::string::npos) << b.name << ": " << r.err;
}

const char *kSender = "#@rfluxmtx h=kf\nvoid polygon w 0 0 12 0 0 0 0 1 0 1 1 0 1 0 0\n";
const char *kReceiver = "#@rfluxmtx h=u\nvoid glow g 0 0 4 1 1 1 0\ng source s 0 0 4 0 0 1 180\n";

INSTANTIATE_TEST_SUITE_P(
    Rfluxmtx, RfluxmtxBadInput,
    testing::Values(
        BadInput{"NoBasis", kSender, "void glow g 0 0 4 1 1 1 0\ng source s 0 0 4 0 0 1 180\n", "",
                 "sky.rad:2: missing hemisphere sampling type (h=) for 'g'"},
        BadInput{"UnknownBasis", kSender,
                 "#@rfluxmtx h=x\nvoid glow g 0 0 4 1 1 1 0\ng source s 0 0 4 0 0 1 180\n", "",
                 "sky.rad:1: unrecognized hemisphere sampling: h=x"},
        // Found by fuzzing (30 minutes): the digits overflowed an int.
        BadInput{"HugeBasis", kSender,
                 "#@rfluxmtx h=r4444444444444\nvoid glow g 0 0 4 1 1 1 0\ng source s 0 0 4 0 0 1 "
                 "180\n",
                 "", "sky.rad:1: h=r4444444444444: a basis size above 1000"},
        BadInput{"BadParameter", kSender,
                 "#@rfluxmtx h=u k=3\nvoid glow g 0 0 4 1 1 1 0\ng source s 0 0 4 0 0 1 180\n", "",
                 "sky.rad:1: bad parameter string: 'k=3'"},
        BadInput{"SourceSender", "#@rfluxmtx h=u\nvoid source s 0 0 4 0 0 1 180\n", kReceiver, "",
                 "sender.rad:2: cannot use source 's' as a sender"},
        BadInput{"BadPolygon", "#@rfluxmtx h=u\nvoid polygon w 0 0 7 0 0 0 1 0 0 0\n", kReceiver,
                 "", "sender.rad:2: bad argument count for surface element 'w'"},
        BadInput{"TruncatedSender", "#@rfluxmtx h=u\nvoid polygon w 0 0 12 0 0 0 1 0 0\n",
                 kReceiver, "", "sender.rad:2: error reading arguments for 'w'"},
        BadInput{"NotANumber", "#@rfluxmtx h=u\nvoid polygon w 0 0 12 0 0 0 1 0 0 nan 1 0 0 1 0\n",
                 kReceiver, "", "sender.rad:2: argument 'nan' of 'w' is not a number"},
        BadInput{"CountOfArguments", "#@rfluxmtx h=u\nvoid polygon w 0 0 1e9 0 0 0 1 0 0 1 1 0\n",
                 kReceiver, "", "sender.rad:2: bad argument count for 'w'"},
        BadInput{"CountBeyondTheFile",
                 "#@rfluxmtx h=u\nvoid polygon w 0 0 2000000000 0 0 0 1 0 0 1 1 0\n", kReceiver, "",
                 "sender.rad:2: error reading arguments for 'w'"},
        BadInput{"UpAlongTheNormal",
                 "#@rfluxmtx h=kf u=-Z\nvoid polygon w 0 0 12 0 0 0 0 1 0 1 1 0 1 0 0\n", kReceiver,
                 "", "sender.rad:2: up vector (u=) coincides with the normal of 'void'"},
        // Issue 41: NaN and inf passed the up vector's check and tripped a CHECK (an abort).
        BadInput{"UpNotANumber",
                 "#@rfluxmtx h=kf u=nan,0,1\nvoid polygon w 0 0 12 0 0 0 0 1 0 1 1 0 1 0 0\n",
                 kReceiver, "", "sender.rad:1: bad parameter string: 'u=nan,0,1' (an up vector"},
        BadInput{"UpInfinite",
                 "#@rfluxmtx h=kf u=0,inf,1\nvoid polygon w 0 0 12 0 0 0 0 1 0 1 1 0 1 0 0\n",
                 kReceiver, "", "sender.rad:1: bad parameter string: 'u=0,inf,1'"},
        BadInput{"UpZero", kSender,
                 "#@rfluxmtx h=u u=0,0,0\nvoid glow g 0 0 4 1 1 1 0\ng source s 0 0 4 0 0 1 180\n",
                 "", "sky.rad:1: bad parameter string: 'u=0,0,0'"},
        BadInput{"NoReceiver", kSender, "void plastic p 0 0 5 1 1 1 0 0\n", "",
                 "sky.rad: missing receiver surface"},
        BadInput{"MissingSender", "", kReceiver, "", "sender.rad"},
        BadInput{"ForcedOutput", kSender, kReceiver, "-fo", "unsupported option '-fo'"},
        BadInput{"IrradianceWhileSampling", kSender, kReceiver, "-I",
                 "-i, -I supported for pass-through only"},
        BadInput{"UnknownToRcontrib", kSender, kReceiver, "-me .1 .1 .1", "unknown option '-me'"}),
    [](const testing::TestParamInfo<BadInput> &info) { return std::string(info.param.name); });

}  // namespace
}  // namespace dayflux::test
