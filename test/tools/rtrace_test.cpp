// rtrace-gpu against RADIANCE 5.4a's rtrace (test/data/rtrace, made by make_references.sh there)
// on the tutorial room: the daylight-factor recipe with dayflux alone on PATH, against the
// converged answer and within RADIANCE's own noise; honeybee's cached settings, closer to that
// answer than RADIANCE's cache; view rays' values on average; and -o's other values, exactly.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "matrix/rgbe.h"
#include "test_util.h"

namespace dayflux::test {
namespace {
namespace fs = std::filesystem;

// Each line's first number.
std::vector<double> FirstColumn(const std::string &text) {
    std::vector<double> v;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) {
        std::istringstream l(line);
        double x;
        if (l >> x) v.push_back(x);
    }
    return v;
}

struct Errors {
    double mean = NAN, rms = NAN;  // relative to the answer, over the sensors
};
Errors Against(const std::vector<double> &v, const std::vector<double> &answer) {
    Errors e;
    if (v.size() != answer.size() || v.empty()) return e;
    double sum = 0, sum2 = 0;
    for (size_t i = 0; i < v.size(); ++i) {
        const double r = v[i] / answer[i] - 1;
        sum += r, sum2 += r * r;
    }
    e.mean = sum / v.size();
    e.rms = std::sqrt(sum2 / v.size());
    return e;
}

class Rtrace : public testing::Test {
  protected:
    void SetUp() override {
        fs::copy(DataDir() / "scene" / "models" / "room", room_, fs::copy_options::recursive);
        fs::copy_file(DataDir() / "rtrace" / "sky_df.rad", room_ / "sky_df.rad");
        fs::copy_file(DataDir() / "rcontrib" / "points.txt", room_ / "points.txt");
        // The recipe's octree, by our oconv and gensky (its !gensky line).
        const CommandResult r = RunWithDayfluxAlone(
            "oconv materials.rad room.rad objects/Glazing.rad sky_df.rad > df.oct", room_);
        ASSERT_EQ(r.status, 0) << r.err;
    }
    std::vector<double> Sensors(const std::string &options, const std::string &then = "") {
        const CommandResult r =
            RunWithDayfluxAlone("rtrace -h -I " + options + " df.oct < points.txt" + then, room_);
        EXPECT_EQ(r.status, 0) << r.err;
        return FirstColumn(r.out);
    }
    static std::vector<double> Reference(const char *name) {
        return FirstColumn(ReadFile(DataDir() / "rtrace" / name));
    }

    TempDir tmp_;
    fs::path room_ = tmp_.path() / "room";
};

// The daylight-factor recipe (gensky, oconv, rtrace -I, rcalc to daylight factors in %) with
// -aa 0: its error against the converged answer is RADIANCE's own at the same -ad (rms 4.4 %
// over the 100 sensors), within 1.3 times, and unbiased (the mean of 100 sensors' errors: within
// 1.5 %, three standard errors).
TEST_F(Rtrace, DaylightFactorsAsRadianceWithDayfluxAlone) {
    std::vector<double> answer = Reference("df_converged.txt");
    ASSERT_EQ(answer.size(), 100u);
    const Errors radiance = Against(Reference("df_2048.txt"), answer);
    for (double &e : answer) e *= 0.179;  // a grey sky: 100 x 179 lm/W / 100,000 lux
    const Errors ours =
        Against(Sensors("-ab 2 -aa 0 -ad 2048 -lw 2e-5",
                        " | rcalc -e '$1=(0.265*$1+0.67*$2+0.065*$3)*17900/100000'"),
                answer);
    EXPECT_LE(ours.rms, 1.3 * radiance.rms) << radiance.rms;
    EXPECT_LE(std::fabs(ours.mean), 0.015);
}

// honeybee's settings (-aa 0.1 -ar 64): RADIANCE's ambient cache is biased (its sensors 9 % high
// on average, 16 % rms); our sensor cache comes closer to the converged answer.
TEST_F(Rtrace, HoneybeeSettingsCloserToTheAnswerThanRadiancesCache) {
    const std::vector<double> answer = Reference("df_converged.txt");
    const Errors radiance = Against(Reference("df_honeybee.txt"), answer);
    const Errors ours = Against(Sensors("-ab 2 -aa 0.1 -ad 2048 -ar 64 -lw 2e-5"), answer);
    EXPECT_LT(ours.rms, radiance.rms);
    EXPECT_LT(std::fabs(ours.mean), std::fabs(radiance.mean));
    EXPECT_LE(std::fabs(ours.mean), 0.04);
}

// View rays in every direction from the room's middle (-ov -ab 2 -ad 256): each is noisy, but
// the mean of 400 agrees with RADIANCE's within three standard errors of their difference.
TEST_F(Rtrace, ViewRaysAsRadianceOnAverage) {
    fs::copy_file(DataDir() / "rtrace" / "sphere_rays.txt", room_ / "sphere_rays.txt");
    const CommandResult r =
        RunWithDayfluxAlone("rtrace -h -ab 2 -aa 0 -ad 256 -ov df.oct < sphere_rays.txt", room_);
    ASSERT_EQ(r.status, 0) << r.err;
    const std::vector<double> ours = FirstColumn(r.out), theirs = Reference("view_values.txt");
    ASSERT_EQ(ours.size(), 400u);
    ASSERT_EQ(theirs.size(), 400u);
    double mean = 0, var = 0, ref = 0;
    for (size_t i = 0; i < ours.size(); ++i) mean += ours[i] - theirs[i], ref += theirs[i];
    mean /= ours.size();
    for (size_t i = 0; i < ours.size(); ++i) var += std::pow(ours[i] - theirs[i] - mean, 2);
    const double standard_error = std::sqrt(var / (ours.size() - 1) / ours.size());
    EXPECT_LE(std::fabs(mean), 3 * standard_error) << "mean " << ref / ours.size();
    EXPECT_GT(ref / ours.size(), 1.0);  // the room is lit
}

// -o's values other than the light (origin, direction, weights, lengths, point, normals,
// surface, modifier and material) are RADIANCE's, text for text: for view rays, a flush (a
// zero direction) among them, and sensors (-I).
TEST_F(Rtrace, OutputsOtherThanLightAreRadiances) {
    for (const char *name : {"view", "sensor"}) {
        SCOPED_TRACE(name);
        const std::string rays = std::string(name) + "_rays.txt";
        fs::copy_file(DataDir() / "rtrace" / rays, room_ / rays);
        const CommandResult r =
            RunWithDayfluxAlone(std::string("rtrace -h ") + (name[0] == 's' ? "-I " : "") +
                                    "-ab 1 -aa 0 -ad 16 -odwWlLpNnsmM df.oct < " + rays,
                                room_);
        ASSERT_EQ(r.status, 0) << r.err;
        EXPECT_EQ(r.out, ReadFile(DataDir() / "rtrace" / (std::string(name) + "_outputs.txt")));
    }
}

// The header (the octree's, the command, the format and component count) and the binary
// formats: -ff as many floats as -fa writes numbers, -fc a picture with its resolution.
TEST_F(Rtrace, HeaderAndFormats) {
    CommandResult r =
        RunWithDayfluxAlone("head -n 4 points.txt | rtrace -I -ab 0 -ovL -faf df.oct", room_);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("#?RADIANCE\noconv materials.rad room.rad objects/Glazing.rad "
                         "sky_df.rad\nrtrace -I -ab 0 -ovL -faf\nSOFTWARE= dayflux rtrace-gpu"),
              std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find("NCOMP=4\n"), std::string::npos);
    EXPECT_NE(r.out.find("FORMAT=float\n\n"), std::string::npos);
    EXPECT_EQ(r.out.size() - r.out.find("\n\n") - 2, 4u * 4 * sizeof(float));
    // -fc: the values of -fa (the same rays and seed) as RGBE pixels after the resolution.
    const std::string six = "head -n 6 points.txt | rtrace -h -I -ab 1 -ad 64 -x 3 -y 2 ";
    r = RunWithDayfluxAlone(six + "-fac df.oct", room_);
    ASSERT_EQ(r.status, 0) << r.err;
    const std::string resolution = "-Y 2 +X 3\n";
    ASSERT_EQ(r.out.size(), resolution.size() + 6 * 4);
    EXPECT_EQ(r.out.rfind(resolution, 0), 0u);
    const CommandResult text = RunWithDayfluxAlone(six + "-faa df.oct", room_);
    ASSERT_EQ(text.status, 0) << text.err;
    std::istringstream values(text.out.substr(text.out.find('\n') + 1));  // after -Y 2 +X 3
    for (int i = 0; i < 6; ++i) {
        Colr c;
        std::memcpy(c.data(), r.out.data() + resolution.size() + 4 * i, 4);
        float rgb[3];
        FromColr(c, rgb);
        for (float decoded : rgb) {
            double v;
            ASSERT_TRUE(values >> v);
            EXPECT_GT(v, 0.1);
            EXPECT_NEAR(decoded, v, v / 128) << "pixel " << i;  // an 8-bit mantissa
        }
    }
}

// rtrace's booleans as RADIANCE reads them: -I, -I+, -IT and -Iy set, -I0 and -In clear, and a
// bare -I toggles.
TEST_F(Rtrace, BooleansAsRtraceReadsThem) {
    const auto run = [&](const std::string &flags) {
        const CommandResult r = RunWithDayfluxAlone(
            "head -n 1 points.txt | rtrace -h -ab 1 -ad 64 " + flags + " df.oct", room_);
        EXPECT_EQ(r.status, 0) << r.err;
        return r.out;
    };
    const std::string irradiance = run("-I"), radiance = run("");
    EXPECT_NE(irradiance, radiance);
    for (const char *on : {"-I+", "-IT", "-Iy", "-I0 -I", "-I -I -I"})
        EXPECT_EQ(run(on), irradiance) << on;
    for (const char *off : {"-I-", "-In", "-I -I", "-IT -I0"}) EXPECT_EQ(run(off), radiance) << off;
}

// gendaylit's skies, in colour (-C, our perezlum_c.cal) and not (perezlum.cal), seen along 50
// rays: RADIANCE's radiance to float rounding.
TEST_F(Rtrace, GendaylitSkiesAsRadiance) {
    fs::copy_file(DataDir() / "rtrace" / "sky_rays.txt", room_ / "sky_rays.txt");
    std::vector<double> ours;
    for (const char *colour : {"-C", ""}) {
        const CommandResult r = RunWithDayfluxAlone(
            std::string("gendaylit 6 21 12 -a 40 -o 80 -m 75 -W 800 80 ") + colour +
                " > sky.rad && printf 'skyfunc glow sky_glow 0 0 4 1 1 1 0\\nsky_glow source "
                "sky 0 0 4 0 0 1 180\\n' >> sky.rad && oconv sky.rad > sky.oct && "
                "rtrace -h -ab 0 -ov sky.oct < sky_rays.txt",
            room_);
        ASSERT_EQ(r.status, 0) << r.err;
        std::istringstream in(r.out);
        for (double x; in >> x;) ours.push_back(x);
    }
    std::istringstream in(ReadFile(DataDir() / "rtrace" / "sky_values.txt"));
    std::vector<double> theirs;
    for (double x; in >> x;) theirs.push_back(x);
    ASSERT_EQ(theirs.size(), 2u * 50 * 3);
    ASSERT_EQ(ours.size(), theirs.size());
    bool coloured = false;
    for (size_t i = 0; i < ours.size(); ++i) {
        EXPECT_NEAR(ours[i], theirs[i], 1e-5 * theirs[i]) << i;
        if (i < 150 && i % 3 == 2) coloured |= theirs[i] > 1.5 * theirs[i - 2];  // bluer
    }
    EXPECT_TRUE(coloured);
}

// Bad options get a message and no output: outputs rtrace-gpu does not write, a picture of more
// than -ov, an ambient value, no octree.
TEST_F(Rtrace, BadOptionsAreRefused) {
    const struct {
        const char *args, *message;
    } cases[] = {
        {"-or df.oct", "-o: output 'r' is not supported by rtrace-gpu"},
        {"-oq df.oct", "-o: output 'q' is not one of rtrace's"},
        {"-ffc -ovp df.oct", "color format only with -ov"},
        {"-av 1 1 1 df.oct", "-av: an ambient value is not supported"},
        {"-ab 1", "usage: rtrace"},
    };
    for (const auto &c : cases) {
        SCOPED_TRACE(c.args);
        const CommandResult r =
            RunWithDayfluxAlone(std::string("rtrace ") + c.args + " < points.txt", room_);
        EXPECT_EQ(r.status, 1);
        EXPECT_EQ(r.out, "");
        EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
    }
}

}  // namespace
}  // namespace dayflux::test
