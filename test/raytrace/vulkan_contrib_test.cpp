// The Vulkan integrator (rcontrib-gpu -backend vulkan) on lavapipe or any Vulkan device:
// analytic answers, and agreement with the Embree backend within the standard errors. Most
// tests bin with reinhart.cal at MF:1 and track one modifier, so one compiled shader serves them
// (compiling takes lavapipe about a minute; it is cached on disk afterwards); a few need their
// own (patterns, mixfunc, Klems bins, the BVH walk).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numeric>
#include <random>
#include <sstream>

#include "raytrace/scenes.h"
#include "test_util.h"

namespace dayflux::test {
namespace fs = std::filesystem;
namespace {

const std::string kBins = " -e MF:1 -f reinhart.cal -b rbin -bn Nrbins ";
// Per-entry z-scores use standard errors from -se's 8 replicas, each estimated with 7 degrees of
// freedom: the difference of two follows Student's t with about 14, whose tails are heavy
// (P(|t| > 4.5) = 5e-4). Beyond 6, P = 3e-5: 0.25 of 7500 entries. Entries fed by one or two
// samples (a sky patch seen through a corner of the window) are worse: when all 8 replicas
// happen to get their sample, the estimated error is far too small, so a few such entries may
// stand out from either backend.
constexpr double kZ = 6;
// lavapipe unless the environment names another device (lavapipe is used only when named).
const std::string kDevice = "DAYFLUX_VULKAN_DEVICE=${DAYFLUX_VULKAN_DEVICE:-llvmpipe} ";

std::vector<double> Floats(const std::string &bytes) {
    std::vector<double> v(bytes.size() / 4);
    for (size_t i = 0; i < v.size(); ++i) {
        float f;
        std::memcpy(&f, bytes.data() + 4 * i, 4);
        v[i] = f;
    }
    return v;
}

// Per-entry agreement of two backends' matrices: z-scores from both standard errors, none
// beyond kZ but a few (see kZ), and totals within 4 combined standard errors.
void ExpectSameMatrix(const std::vector<double> &gpu, const std::vector<double> &se_gpu,
                      const std::vector<double> &cpu, const std::vector<double> &se_cpu,
                      int min_compared) {
    ASSERT_EQ(cpu.size(), gpu.size());
    int beyond = 0, compared = 0;
    double sum_gpu = 0, sum_cpu = 0, var = 0;
    for (size_t i = 0; i < gpu.size(); ++i) {
        sum_gpu += gpu[i], sum_cpu += cpu[i];
        const double s2 = se_gpu[i] * se_gpu[i] + se_cpu[i] * se_cpu[i];
        var += s2;
        if (s2 == 0) {
            EXPECT_EQ(gpu[i], cpu[i]) << "entry " << i;
            continue;
        }
        ++compared;
        if (std::fabs(gpu[i] - cpu[i]) > kZ * std::sqrt(s2)) ++beyond;
    }
    EXPECT_GT(compared, min_compared);
    EXPECT_LE(beyond, 2 + compared / 10000) << "of " << compared;
    EXPECT_NEAR(sum_gpu, sum_cpu, 4 * std::sqrt(var));
}

// Runs command (in dir), which must succeed on the backend it names (no fall back to Embree),
// and gives the numbers of its output (and its stderr in err, if given).
std::vector<double> OutputNumbers(const std::string &command, const fs::path &dir,
                                  std::string *err = nullptr) {
    const CommandResult r = RunCommand(command, dir);
    if (err) *err = r.err;
    EXPECT_EQ(r.status, 0) << command << "\n" << r.err;
    EXPECT_EQ(r.err.find("using Embree"), std::string::npos) << r.err;
    std::vector<double> v;
    std::istringstream in(r.out);
    for (double x; in >> x;) v.push_back(x);
    return v;
}

// One random stream on both engines: gpu and cpu ran with one -seed, other on the CPU with
// another. The engines differ far less than the seeds do (float against double rounding alone),
// and the total passes min_total (there was something to see).
void ExpectOneStream(const std::vector<double> &gpu, const std::vector<double> &cpu,
                     const std::vector<double> &other, size_t size, double min_total) {
    ASSERT_EQ(gpu.size(), size);
    ASSERT_EQ(cpu.size(), size);
    ASSERT_EQ(other.size(), size);
    double backends = 0, seeds = 0, total = 0;
    for (size_t i = 0; i < size; ++i) {
        backends += (gpu[i] - cpu[i]) * (gpu[i] - cpu[i]);
        seeds += (other[i] - cpu[i]) * (other[i] - cpu[i]);
        total += cpu[i];
    }
    EXPECT_GT(total, min_total);
    EXPECT_GT(seeds, 0);
    EXPECT_LT(std::sqrt(backends), 0.2 * std::sqrt(seeds));
}

// Per sensor (record) totals of two backends' matrices of ncols columns: all above .1 and
// within kZ times the square root of the sum of the entries' variances. That bounds the
// total's variance loosely (a sample lands in one bin, so the entries are anticorrelated): a
// coarse check beside ExpectSameMatrix's.
void ExpectSameSensorTotals(const std::vector<double> &gpu, const std::vector<double> &se_gpu,
                            const std::vector<double> &cpu, const std::vector<double> &se_cpu,
                            int sensors, int ncols) {
    ASSERT_EQ(gpu.size(), static_cast<size_t>(sensors) * ncols * 3);
    ASSERT_EQ(cpu.size(), gpu.size());
    for (int r = 0; r < sensors; ++r) {
        double g = 0, c = 0, var = 0;
        for (int k = 0; k < ncols * 3; k += 3) {
            const size_t i = static_cast<size_t>(r) * ncols * 3 + k;
            g += gpu[i], c += cpu[i], var += se_gpu[i] * se_gpu[i] + se_cpu[i] * se_cpu[i];
        }
        EXPECT_GT(c, 0.1);
        EXPECT_NEAR(g, c, kZ * std::sqrt(var)) << "sensor " << r;
    }
}

class VulkanContrib : public ::testing::Test {
  protected:
    void SetUp() override {
        WriteFile(tmp_.path() / "sky.rad",
                  "void glow skyglow 0 0 4 1 1 1 0\nskyglow source sky 0 0 4 0 0 1 180\n");
        if (const std::string why = WhyEmbree("-ab 1 -ad 16"); !why.empty()) GTEST_SKIP() << why;
    }
    // Why a one-ray sky run with extra options goes to Embree instead of the Vulkan backend
    // ("" where Vulkan takes it).
    std::string WhyEmbree(const std::string &options) {
        const CommandResult r =
            RunCommand("echo '0 0 0 0 0 1' | " + kDevice + "rcontrib-gpu -backend vulkan -h -I+ " +
                           options + kBins + "-m skyglow sky.rad",
                       tmp_.path());
        EXPECT_EQ(r.status, 0) << r.err;
        return r.err.find("using Embree") != std::string::npos ? r.err : "";
    }
    // Runs rcontrib-gpu (float output, no header) on a backend; with -se, se gets the errors.
    std::vector<double> Run(const std::string &backend, const std::string &args,
                            const fs::path &dir, std::vector<double> *se = nullptr) {
        const fs::path se_file = tmp_.path() / ("se_" + backend);
        const std::string cmd = kDevice + "rcontrib-gpu -backend " + backend + " -fo+ -h -faf" +
                                (se ? " -se '" + se_file.string() + "'" : std::string()) + " " +
                                args;
        CommandResult r = RunCommand(cmd, dir);
        EXPECT_EQ(r.status, 0) << cmd << "\n" << r.err;
        EXPECT_EQ(r.err.find("using Embree"), std::string::npos) << r.err;
        if (se) *se = Floats(ReadFile(se_file));
        return Floats(r.out);
    }
    // Both backends on args (run in dir), with -se's standard errors.
    struct BothBackends {
        std::vector<double> gpu, se_gpu, cpu, se_cpu;
    };
    BothBackends RunBoth(const std::string &args, const fs::path &dir) {
        BothBackends b;
        b.gpu = Run("vulkan", args, dir, &b.se_gpu);
        b.cpu = Run("embree", args, dir, &b.se_cpu);
        return b;
    }
    // Twenty sensors facing up along the x axis from -1.9 to 1.9, in the file `rays`.
    void WriteSensorLine() {
        std::string rays;
        for (int i = 0; i < 20; ++i) rays += std::to_string(-1.9 + 0.2 * i) + " 0 0 0 0 1\n";
        WriteFile(tmp_.path() / "rays", rays);
    }
    // Both backends on args (run in the test's folder), `entries` entries (their first channel):
    // at most one beyond kZ combined standard errors (plus `slack` of its value, for the GPU's
    // float where values have no noise; with slack 0 such entries are not compared), and the
    // totals within 4 combined standard errors.
    void ExpectSameTotals(const std::string &args, size_t entries, double slack) {
        const auto [gpu, se_gpu, cpu, se_cpu] = RunBoth(args, tmp_.path());
        ASSERT_EQ(gpu.size(), entries * 3) << args;
        ASSERT_EQ(cpu.size(), gpu.size()) << args;
        double sum_gpu = 0, sum_cpu = 0, var = 0;
        int beyond = 0;
        for (size_t i = 0; i < gpu.size(); ++i) {
            sum_gpu += gpu[i], sum_cpu += cpu[i];
            const double s2 = se_gpu[i] * se_gpu[i] + se_cpu[i] * se_cpu[i];
            var += s2;
            if ((s2 > 0 || slack > 0) &&
                std::fabs(gpu[i] - cpu[i]) > kZ * std::sqrt(s2) + slack * std::fabs(cpu[i]))
                ++beyond;
        }
        EXPECT_GT(sum_cpu, 0) << args;
        EXPECT_LE(beyond, 1) << args;
        EXPECT_NEAR(sum_gpu, sum_cpu, 4 * std::sqrt(var) + std::max(slack, 1e-9) * sum_cpu) << args;
    }
    // Both backends on args (run in the test's folder), `entries` entries compared one by one
    // (their first channel) within kZ combined standard errors, each of those at most max_se of
    // the value where max_se > 0 (enough samples to tell). Returns the CPU's total.
    double ExpectSameEntries(const std::string &args, size_t entries, double max_se = 0) {
        const auto [gpu, se_gpu, cpu, se_cpu] = RunBoth(args, tmp_.path());
        EXPECT_EQ(gpu.size(), entries * 3);
        if (cpu.size() != gpu.size() || gpu.size() != entries * 3) return 0;
        double total = 0;
        for (size_t i = 0; i < gpu.size(); i += 3) {
            const double s2 = se_gpu[i] * se_gpu[i] + se_cpu[i] * se_cpu[i];
            if (max_se > 0) {
                EXPECT_LT(std::sqrt(s2), max_se * cpu[i]) << "entry " << i / 3;
            }
            EXPECT_NEAR(gpu[i], cpu[i], kZ * std::sqrt(s2) + 1e-9) << "entry " << i / 3;
            total += cpu[i];
        }
        return total;
    }
    // The tutorial room's 100 sensors through both backends (args: options and scene), a
    // matrix of ncols columns, compared entry by entry.
    void RoomMatrixAsEmbree(const std::string &args, size_t ncols) {
        const fs::path room = DataDir() / "scene" / "models" / "room";
        const std::string all =
            args + " < '" + (DataDir() / "rcontrib" / "points.txt").string() + "'";
        const auto [gpu, se_gpu, cpu, se_cpu] = RunBoth(all, room);
        ASSERT_EQ(gpu.size(), 100u * ncols * 3);
        ExpectSameMatrix(gpu, se_gpu, cpu, se_cpu, 5000);
    }
    // Three suns of radiance 1 (sa, sb and sc, at altitudes whose sines are .8, .8 and .28) seen
    // by an upward sensor, direct only, through both backends with the modifiers and bins of
    // args: each column is its sun's solid angle times `exact` (the sine, or nought), to float
    // rounding.
    void ExpectSunColumns(const std::string &args, const std::vector<double> &exact) {
        WriteFile(tmp_.path() / "suns.rad",
                  "void light sa 0 0 3 1 1 1\nsa source a 0 0 4 0 .6 .8 .533\n"
                  "void light sb 0 0 3 1 1 1\nsb source b 0 0 4 .6 0 .8 .533\n"
                  "void light sc 0 0 3 1 1 1\nsc source c 0 0 4 0 -.96 .28 .533\n");
        WriteFile(tmp_.path() / "ray", "0 0 0 0 0 1\n");
        const std::string all = "-I+ -ab 0 -dj 0 " + args + " suns.rad < ray";
        const std::vector<double> gpu = Run("vulkan", all, tmp_.path()),
                                  cpu = Run("embree", all, tmp_.path());
        ASSERT_EQ(cpu.size(), exact.size() * 3);
        ASSERT_EQ(gpu.size(), cpu.size());
        const double omega = 2 * M_PI * (1 - std::cos(0.533 / 2 * M_PI / 180));
        for (size_t c = 0; c < exact.size(); ++c) {
            EXPECT_NEAR(cpu[3 * c], exact[c] * omega, 1e-6 * omega) << c;
            EXPECT_NEAR(gpu[3 * c], exact[c] * omega, 1e-5 * omega) << c;
        }
    }
    // The underside of a panel seen from below (the test that calls it says more): panel holds
    // its materials, which pass `through` of the sky above and reflect `reflected` of the ground.
    void ExpectPanelUndersideSeen(const std::string &panel, double through, double reflected);
    TempDir tmp_;
};

// The tutorial room's daylight coefficients from both backends: per-entry t-scores from the
// two standard errors stay within what 7500 entries explain, and so does the total.
TEST_F(VulkanContrib, TutorialRoomAgreesWithEmbree) {
    RoomMatrixAsEmbree("-I+ -ab 2 -ad 512 -lw 1e-3" + kBins +
                           "-m skyglow materials.rad room.rad objects/Glazing.rad "
                           "skyDomes/skyglow.rad",
                       146);
}

// One random stream: with the same -seed both backends draw the same numbers for the same
// record, ray and bounce, so the tutorial room's daylight coefficients differ between them only
// where float and double round differently (and the rare path that this turns another way), far
// less than between two seeds on one backend: on lavapipe 1e-7 against 0.7 (relative RMS over
// the entries).
TEST_F(VulkanContrib, OneRandomStreamOnBothBackends) {
    const fs::path room = DataDir() / "scene" / "models" / "room";
    const std::string args = "-I+ -ab 2 -ad 512 -lw 1e-3" + kBins +
                             "-m skyglow materials.rad room.rad objects/Glazing.rad "
                             "skyDomes/skyglow.rad < '" +
                             (DataDir() / "rcontrib" / "points.txt").string() + "'";
    const std::vector<double> gpu = Run("vulkan", "-seed 1 " + args, room),
                              cpu = Run("embree", "-seed 1 " + args, room),
                              other = Run("embree", "-seed 2 " + args, room);
    ASSERT_EQ(gpu.size(), 100u * 146 * 3);
    ASSERT_EQ(cpu.size(), gpu.size());
    ASSERT_EQ(other.size(), gpu.size());
    double backends = 0, seeds = 0, scale = 0;
    for (size_t i = 0; i < gpu.size(); ++i) {
        backends += (gpu[i] - cpu[i]) * (gpu[i] - cpu[i]);
        seeds += (other[i] - cpu[i]) * (other[i] - cpu[i]);
        scale += cpu[i] * cpu[i];
    }
    EXPECT_GT(seeds, 0.01 * scale) << "two seeds should differ";
    EXPECT_LT(std::sqrt(backends), 0.2 * std::sqrt(seeds))
        << "backends " << std::sqrt(backends / scale) << ", seeds " << std::sqrt(seeds / scale);
}

// rtrace_dc-gpu on the GPU: DAYSIM's patch function compiled from calcomp into the shader, its
// -V+ coefficients, with one random stream: the tutorial room's 148 diffuse coefficients as
// Embree's to float rounding (far closer than two seeds). (The sensor cache on a GPU needs a
// second shader, -ab 0, which lavapipe takes a minute to compile: it is left to bench/gpu.sh's
// DSdifC case; the cache's arithmetic is the CPU's on either engine.)
TEST_F(VulkanContrib, RtraceDcAsEmbree) {
    const fs::path room = DataDir() / "daysim" / "room";
    WriteFile(tmp_.path() / "sky148.rad",
              "void glow sky 0 0 4 1000 1000 1000 0\nsky source himmel 0 0 4 0 0 1 360\n");
    const std::string args = "-h -I+ -oc -ab 2 -ad 512 -lw 1e-3 -N 148 -Dd '" +
                             (tmp_.path() / "sky148.rad").string() +
                             "' room_material.rad room_geometry.rad < room.pts";
    const auto run = [&](const std::string &how) {
        return OutputNumbers(kDevice + "rtrace_dc-gpu " + how + " " + args, room);
    };
    const std::vector<double> gpu = run("-backend vulkan -seed 1"),
                              cpu = run("-backend embree -seed 1"),
                              other = run("-backend embree -seed 2");
    ExpectOneStream(gpu, cpu, other, 10u * 148, 1.0);
}

// rtrace-gpu: sensors' irradiance (-I) and view rays' radiance with what they meet (-ovL), the
// same random stream on both backends.
TEST_F(VulkanContrib, RtraceAsEmbree) {
    const fs::path room = DataDir() / "scene" / "models" / "room";
    for (const std::string mode : {"-I -ov", "-ovL"}) {
        SCOPED_TRACE(mode);
        const std::string rays =
            (DataDir() / (mode[1] == 'I' ? "rcontrib/points.txt" : "rtrace/sphere_rays.txt"))
                .string();
        const std::string args = "-h " + mode +
                                 " -ab 2 -ad 256 -lw 1e-3 materials.rad room.rad "
                                 "objects/Glazing.rad skyDomes/skyglow.rad < '" +
                                 rays + "'";
        const auto run = [&](const std::string &how) {
            return OutputNumbers(kDevice + "rtrace-gpu " + how + " " + args, room);
        };
        const std::vector<double> gpu = run("-backend vulkan -seed 1"),
                                  cpu = run("-backend embree -seed 1"),
                                  other = run("-backend embree -seed 2");
        ExpectOneStream(gpu, cpu, other, mode[1] == 'I' ? 100u * 3 : 400u * 4, 1.0);
    }
}

// -target_error: the passes (a pair of replicas traced in slices, kept apart on the device) give
// the same stream on both backends; where float and double round an estimate to either side of
// the target a sensor may take another pass, which ExpectOneStream's margin leaves room for.
TEST_F(VulkanContrib, TargetErrorAsEmbree) {
    const fs::path room = DataDir() / "scene" / "models" / "room";
    const std::string args =
        "-h -I+ -ab 2 -ad 512 -lw 1e-3 -target_error 0.05 -m skyglow "
        "materials.rad room.rad objects/Glazing.rad skyDomes/skyglow.rad";
    const std::string points =
        "head -n 30 '" + (DataDir() / "rcontrib" / "points.txt").string() + "' | ";
    const auto run = [&](const std::string &how) {
        std::string err;
        const std::vector<double> v =
            OutputNumbers(points + kDevice + "rcontrib-gpu " + how + " " + args, room, &err);
        EXPECT_NE(err.find("-target_error 0.05: "), std::string::npos) << err;
        return v;
    };
    const std::vector<double> gpu = run("-backend vulkan -seed 1"),
                              cpu = run("-backend embree -seed 1"),
                              other = run("-backend embree -seed 2");
    ExpectOneStream(gpu, cpu, other, 30u * 3, 0.3);
}

// -target_error with -asub 3 and a sun: the CPU traces each pair's hemisphere whole and adds
// each cell's path to its slice (StepsPerSlice), where the GPU's tasks replay the rows before their
// slice; each slice's sums, and so every pass's estimate and stop, as on the GPU. (A sensor whose
// estimate float and double round to either side of its target may take another pass: at most
// one of the twelve.)
TEST_F(VulkanContrib, TargetErrorSlicesWithSubsamplesAndASunAsEmbree) {
    const fs::path room = DataDir() / "scene" / "models" / "room";
    WriteFile(tmp_.path() / "sun.rad",
              "void light solar 0 0 3 1e5 1e5 1e5\nsolar source sun 0 0 4 .3 -.8 .5 .533\n");
    const auto report = [&](const std::string &backend) {
        const fs::path file = tmp_.path() / (backend + ".txt");
        std::string err;
        OutputNumbers("head -n 12 '" + (DataDir() / "rcontrib" / "points.txt").string() + "' | " +
                          kDevice + "rcontrib-gpu -backend " + backend +
                          " -seed 1 -h -I+ -ab 2 -ad 1024 -asub 3 -lw 1e-4 -target_error 0.05 "
                          "-target_report '" +
                          file.string() +
                          "' -m skyglow -m solar materials.rad room.rad objects/Glazing.rad "
                          "skyDomes/skyglow.rad '" +
                          (tmp_.path() / "sun.rad").string() + "'",
                      room, &err);
        return ReadTargetReport(file);
    };
    const std::vector<TargetReportSensor> gpu = report("vulkan"), cpu = report("embree");
    ASSERT_EQ(gpu.size(), 12u);
    ASSERT_EQ(cpu.size(), 12u);
    int passes_apart = 0;
    for (size_t i = 0; i < cpu.size(); ++i) {
        if (gpu[i].samples != cpu[i].samples) {
            ++passes_apart;
            continue;
        }
        EXPECT_NEAR(gpu[i].error, cpu[i].error, 1e-4 * cpu[i].error) << "sensor " << i;
    }
    EXPECT_LE(passes_apart, 1);
}

// -asub 2: each first-level cell sampled by 2 x 2 rays, one carrying its diffuse paths with 4
// times its coefficient, the same on both backends (a wrong scale would move every entry lit
// after a bounce).
TEST_F(VulkanContrib, SubsampledHemispheresAsEmbree) {
    RoomMatrixAsEmbree("-asub 2 -I+ -ab 2 -ad 512 -lw 1e-3" + kBins +
                           "-m skyglow materials.rad room.rad objects/Glazing.rad "
                           "skyDomes/skyglow.rad",
                       146);
}

// -asub with one random stream: two sensors' daylight coefficients as Embree's, far closer than
// two seeds. The GPU gives each task a slice of a hemisphere's rows; a task starting at a later
// row takes up the steps' keys and the probes (which cells are split) as one task would.
TEST_F(VulkanContrib, SubsampledSlicesAsOneStream) {
    const fs::path room = DataDir() / "scene" / "models" / "room";
    WriteFile(tmp_.path() / "two", "1 1 0.76 0 0 1\n4 2.5 0.76 0 0 1\n");
    const std::string args = "-asub 3 -I+ -ab 1 -ad 1024 -lw 1e-4" + kBins +
                             "-m skyglow materials.rad room.rad objects/Glazing.rad "
                             "skyDomes/skyglow.rad < '" +
                             (tmp_.path() / "two").string() + "'";
    const std::vector<double> gpu = Run("vulkan", "-seed 1 " + args, room),
                              cpu = Run("embree", "-seed 1 " + args, room),
                              other = Run("embree", "-seed 2 " + args, room);
    ExpectOneStream(gpu, cpu, other, 2u * 146 * 3, 0.1);
}

// -asub's probes and receiver samples on the GPU as on the CPU: twenty sensors under a glowing
// strip a third of a cell wide, which many probes miss (the cells they leave whole give other
// numbers than split ones would), and a ceiling above it, whose hemispheres sample the strip
// directly, with one random stream: as Embree's, far closer than two seeds.
TEST_F(VulkanContrib, SubsampledNearTargetsAsOneStream) {
    WriteSensorLine();
    WriteFile(tmp_.path() / "strip.rad",
              "void glow pane 0 0 4 1 1 1 0\n"
              "pane polygon w 0 0 12 -3 -.015 1.2  -3 .015 1.2  3 .015 1.2  3 -.015 1.2\n"
              "void plastic ceiling 0 0 5 .5 .5 .5 0 0\n"
              "ceiling polygon c 0 0 12 -9 -9 2  9 -9 2  9 9 2  -9 9 2\n");
    const std::string args =
        "-asub 3 -I+ -ab 2 -ad 1024 -lw 1e-6" + kBins + "-m pane strip.rad < rays";
    const std::vector<double> gpu = Run("vulkan", "-seed 1 " + args, tmp_.path()),
                              cpu = Run("embree", "-seed 1 " + args, tmp_.path()),
                              other = Run("embree", "-seed 2 " + args, tmp_.path());
    ExpectOneStream(gpu, cpu, other, 20u * 146 * 3, 0.5);
}

// Sun coefficients through the tutorial room's glazing (RADIANCE's octree with 5185 suns,
// direct only, no jitter): no sampling at all, so each sensor's total equals Embree's to float
// rounding. (Per bin, suns lying on a bin's edge may fall either side.)
TEST_F(VulkanContrib, SunsThroughGlassAsEmbree) {
    const fs::path dir = DataDir() / "rcontrib";
    const std::string args =
        "-I+ -ab 0 -dc 1 -dt 0 -dj 0" + kBins + "-m solar cds.oct < points.txt";
    const std::vector<double> gpu = Run("vulkan", args, dir), cpu = Run("embree", args, dir);
    ASSERT_EQ(gpu.size(), 100u * 146 * 3);
    ASSERT_EQ(cpu.size(), gpu.size());
    double all = 0;
    for (size_t r = 0; r < 100; ++r) {
        double g = 0, c = 0;
        for (size_t k = 0; k < 146 * 3; ++k) g += gpu[r * 438 + k], c += cpu[r * 438 + k];
        EXPECT_NEAR(g, c, 1e-5 * c + 1e-9) << "sensor " << r;
        all += c;
    }
    EXPECT_GT(all, 0);
}

// Several tracked modifiers with bin expressions of their own, one shared by two of them (the
// shader has a function per distinct expression and a table of the modifiers' columns, bin
// counts and functions). The shared expression puts a high sun in bin 1 of 2; the second
// modifier's puts its sun, as high, in its only bin.
TEST_F(VulkanContrib, ModifiersWithTheirOwnBinsAsEmbree) {
    ExpectSunColumns(
        "-b 'if(Dz-.7,1,0)' -bn 2 -m sa -b 0 -bn 1 -m sb -b 'if(Dz-.7,1,0)' -bn 2 -m sc",
        {0, .8, .8, .28, 0});
}

// Modifiers given different -p parameters evaluate one bin function, from one -f file, in
// contexts of their own; modifiers given the same ones share a context: each sun lands in the
// bin its parameters pick.
TEST_F(VulkanContrib, ModifiersWithTheirOwnParametersAsEmbree) {
    WriteFile(tmp_.path() / "pick.cal", "above(t) = if(Dz - t, 1, 0);\npick = B * above(T);\n");
    ExpectSunColumns(
        "-f pick.cal -b pick -bn 3 -p T=.7,B=1 -m sa -p T=.2,B=2 -m sb "
        "-p T=.7,B=1 -m sc",
        {0, .8, 0, 0, 0, .8, .28, 0, 0});
}

// Rough specular reflection (sampled, and as a lobe toward the sun), a rough surface below -st
// folded into the diffuse part, and rough specular transmission (sampled, and as a lobe toward
// the sun): sensors facing a rough metal floor, half of it under a frosted pane, and a rough
// plastic wall under a sky and a sun, both backends within their standard errors. Then the
// floors RoughSpecularAsRadiance traces (scenes.h's RoughFloor), from its tilted sensor, and
// the frosted sheets RoughTransmissionAsRadiance traces, from its sensors.
TEST_F(VulkanContrib, RoughSpecularAsEmbree) {
    WriteFile(tmp_.path() / "scene.rad",
              "void metal brushed 0 0 5 .8 .7 .6 .9 .1\n"
              "void plastic satin 0 0 5 .5 .5 .5 .015 .08\n"
              "brushed polygon floor 0 0 12 -5 -5 0  5 -5 0  5 5 0  -5 5 0\n"
              "satin polygon wall 0 0 12 -5 5 0  5 5 0  5 5 4  -5 5 4\n"
              "void trans frost 0 0 7 .8 .8 .8 .03 .12 .6 .7\n"
              "frost polygon pane 0 0 12 -5 -5 .5  .5 -5 .5  .5 5 .5  -5 5 .5\n"
              "void light solar 0 0 3 1e4 1e4 1e4\nsolar source sun 0 0 4 0 -.6 .8 .533\n");
    WriteFile(tmp_.path() / "rays", "0 -1 1 0 .4 -1\n1 0 1 0 .2 -1\n-1 2 1 .1 .3 -1\n");
    // -ss 4 takes several specular samples where a ray's weight is high: the input rays, here
    // sent as they are (-I-) to the floor and wall.
    for (const char *run : {"-I+ -m skyglow", "-I+ -m solar", "-I- -ss 4 -m skyglow"})
        ExpectSameTotals(std::string("-ab 2 -ad 1024 -lw 1e-4 -dj .5") + kBins + run +
                             " scene.rad sky.rad < rays",
                         3 * 146, 0);
    WriteFile(tmp_.path() / "metal.rad", test::RoughFloor(true));
    WriteFile(tmp_.path() / "plastic.rad", test::RoughFloor(false));
    WriteFile(tmp_.path() / "tilted", "0 -1 1 0 0.7 -0.7\n");
    for (const char *floor : {"metal.rad", "plastic.rad"})
        ExpectSameTotals(std::string("-I+ -ab 2 -ad 1024 -lw 1e-5 -dj 0") + kBins +
                             "-m solar -m skyglow " + floor + " < tilted",
                         2 * 146, 0);
    // and the frosted sheets RoughTransmissionAsRadiance traces (scenes.h's FrostedSheet)
    WriteFile(tmp_.path() / "patch.rad", test::SunAndPatch());
    WriteFile(tmp_.path() / "below", "0 0 0 0 0 1\n0 0 0 0 0.64 0.77\n");
    for (char which : {'a', 'b', 'c'}) {
        WriteFile(tmp_.path() / "sheet.rad", test::FrostedSheet(which));
        ExpectSameTotals(std::string("-I+ -ab 2 -ad 1024 -lw 1e-5 -dj 0") + kBins +
                             "-m solar -m skyglow patch.rad sheet.rad < below",
                         2 * 2 * 146, 0);
    }
}

// Records as rcontrib makes them: -c 2 averages two rays, a zero direction counts as a ray that
// contributes nothing, and a partial last record is averaged over its rays.
TEST_F(VulkanContrib, AccumulatedRecordsAsEmbree) {
    WriteFile(tmp_.path() / "rays",
              "0 0 0 0 0 1\n0 0 0 0 0 1\n0 0 1 0 0 1\n0 0 0 0 0 0\n0 0 1 0 0 1\n");
    const std::string args = "-c 2 -I+ -ab 1 -ad 64" + kBins + "-m skyglow sky.rad < rays";
    const std::vector<double> gpu = Run("vulkan", args, tmp_.path());
    ASSERT_EQ(gpu.size(), 3u * 146 * 3);
    const double expected[3] = {M_PI, M_PI / 2, M_PI};
    for (int r = 0; r < 3; ++r) {
        double total = 0;
        for (int k = 0; k < 146 * 3; k += 3) total += gpu[r * 438 + k];
        EXPECT_NEAR(total, expected[r], 1e-5) << "record " << r;
    }
}

// RADIANCE's collision rule at every depth: a sensor facing a large floor sees the sky only
// after one bounce, through hemispheres of 2 x 2 cells at depth 1, where the rule moves light
// between altitudes (without it the GPU's rows differed from Embree's by up to 29 sigma). Per
// altitude row of the Reinhart bins, the backends agree within their standard errors.
TEST_F(VulkanContrib, BouncedSkyPerAltitudeAsEmbree) {
    WriteFile(tmp_.path() / "floor.rad",
              "void plastic grey 0 0 5 .5 .5 .5 0 0\n"
              "grey polygon floor 0 0 12 -1e3 -1e3 0  1e3 -1e3 0  "
              "1e3 1e3 0  -1e3 1e3 0\n");
    const int nrays = 100;
    std::string rays;
    for (int i = 0; i < nrays; ++i) rays += "0 0 1 0 0 -1\n";
    WriteFile(tmp_.path() / "rays", rays);
    // Every ray its own record: the spread of the records gives each row's standard error
    // (-se would trace replicas at -ad / 8, where depth-1 hemispheres have a single cell).
    const std::string args =
        "-I+ -ab 2 -ad 1024 -lw 1e-8" + kBins + "-m skyglow floor.rad sky.rad < rays";
    const std::vector<double> gpu = Run("vulkan", args, tmp_.path());
    const std::vector<double> cpu = Run("embree", args, tmp_.path());
    ASSERT_EQ(gpu.size(), nrays * 146u * 3);
    ASSERT_EQ(cpu.size(), gpu.size());
    static const int per_row[] = {30, 30, 24, 24, 18, 12, 6, 1};
    int first = 1;
    for (int row = 0; row < 8; first += per_row[row], ++row) {
        double mean[2] = {0, 0}, var[2] = {0, 0};
        const std::vector<double> *runs[2] = {&gpu, &cpu};
        for (int b = 0; b < 2; ++b) {
            std::vector<double> x(nrays, 0.0);
            for (int r = 0; r < nrays; ++r)
                for (int k = first; k < first + per_row[row]; ++k)
                    x[r] += (*runs[b])[(r * 146 + k) * 3];
            for (double v : x) mean[b] += v / nrays;
            for (double v : x) var[b] += (v - mean[b]) * (v - mean[b]) / (nrays - 1) / nrays;
        }
        EXPECT_NEAR(mean[0], mean[1], 4.5 * std::sqrt(var[0] + var[1])) << "altitude row " << row;
    }
}

// Deep trees: a box of trans (specular and diffuse transmission, both sides) under a sky at
// -ab 8 without roulette keeps every ray on the GPU's stack (no warning), and with a uniform sky
// the total does not depend on the directions drawn, so it equals Embree's. Two facing mirrors
// with -lr 0 end (the depth guard) instead of looping forever.
TEST_F(VulkanContrib, DeepTreesAndMirrorLoops) {
    WriteFile(tmp_.path() / "box.rad",
              "void trans tr 0 0 7 .6 .6 .6 .05 0 .5 .5\n" + CubeOfPolygons("tr"));
    WriteFile(tmp_.path() / "all.rad",
              "void glow skyglow 0 0 4 1 1 1 0\nskyglow source sky 0 0 4 0 0 1 360\n");
    WriteFile(tmp_.path() / "rays", "0 0 0 0 0 1\n");
    const std::string args = "-I+ -ab 8 -ad 4 -lw 1e-12" + kBins + "-m skyglow box.rad all.rad";
    CommandResult g = RunCommand(
        kDevice + "rcontrib-gpu -backend vulkan -h -faa " + args + " < rays", tmp_.path());
    CommandResult c = RunCommand("rcontrib-gpu -h -faa " + args + " < rays", tmp_.path());
    ASSERT_EQ(g.status, 0) << g.err;
    EXPECT_EQ(g.err, "");
    const auto total = [](const std::string &text) {
        std::istringstream in(text);
        double s = 0, x;
        for (int k = 0; in >> x; ++k)
            if (k % 3 == 0) s += x;
        return s;
    };
    EXPECT_GT(total(c.out), 0.5);
    EXPECT_NEAR(total(g.out), total(c.out), 1e-5 * total(c.out));
    WriteFile(tmp_.path() / "mirrors.rad",
              "void mirror m 0 0 3 1 1 1\n"
              "m polygon a 0 0 12 -1 -1 0  1 -1 0  1 1 0  -1 1 0\n"
              "m polygon b 0 0 12 -1 -1 1  -1 1 1  1 1 1  1 -1 1\n");
    WriteFile(tmp_.path() / "ray", "0 0 .5 0 0 1\n");
    CommandResult loop = RunCommand("timeout 120 sh -c \"" + kDevice +
                                        "rcontrib-gpu -backend vulkan -h -lr 0 -ab 1" + kBins +
                                        "-m skyglow mirrors.rad all.rad < ray\"",
                                    tmp_.path());
    EXPECT_EQ(loop.status, 0) << loop.err;
}

// Accumulators as float pairs (the default), in float (-gpu_accum float) or double, and bins in
// double (-gpu_cal double, on a device opened with shaderFloat64): at -ad 50000 a uniform sky
// still gives pi within 1e-6 every way (each -I task sums a slice of the hemisphere's rows).
TEST_F(VulkanContrib, FloatAndDoubleAccumulators) {
    WriteFile(tmp_.path() / "rays", "0 0 0 0 0 1\n");
    for (const char *variant :
         {"-gpu_accum pair", "-gpu_accum double", "-gpu_accum float", "-gpu_cal double"}) {
        const std::vector<double> v = Run("vulkan",
                                          std::string(variant) + " -I+ -ab 1 -ad 50000 -lw 1e-9" +
                                              kBins + "-m skyglow sky.rad < rays",
                                          tmp_.path());
        double total = 0;
        for (size_t b = 0; b < v.size(); b += 3) total += v[b];
        EXPECT_NEAR(total, M_PI, 1e-6 * M_PI) << variant;
    }
}

// Patterns compiled from calcomp to GLSL: a brightfunc ramp on a floor (with its arguments) and a
// colorfunc sky whose radiance -V counts; both backends within their standard errors.
TEST_F(VulkanContrib, PatternsAsEmbree) {
    WriteFile(tmp_.path() / "ramp.cal",
              "ramp = A1 + A2 * (Px + 2) / 4;\n"
              "skyr = 1 + Dz; skyg = 1; skyb = 2 - Dz * Dz;\n");
    WriteFile(tmp_.path() / "scene.rad",
              "void brightfunc ramp 2 ramp ramp.cal 0 2 .2 .6\n"
              "ramp plastic grey 0 0 5 .7 .6 .5 0 0\n"
              "grey polygon floor 0 0 12 -2 -2 0  2 -2 0  2 2 0  -2 2 0\n"
              "void colorfunc skyfunc 4 skyr skyg skyb ramp.cal 0 0\n"
              "skyfunc glow skyglow 0 0 4 1 1 1 0\n"
              "skyglow source sky 0 0 4 0 0 1 360\n");
    WriteFile(tmp_.path() / "rays", "-1 0 1 .3 0 -1\n1 0 1 -.3 .2 -1\n0 1 .5 0 0 -1\n");
    const std::string args =
        "-V+ -I+ -ab 2 -ad 1024 -lw 1e-4" + kBins + "-m skyglow scene.rad < rays";
    const auto [gpu, se_gpu, cpu, se_cpu] = RunBoth(args, tmp_.path());
    ASSERT_EQ(gpu.size(), 3u * 438);
    ASSERT_EQ(cpu.size(), gpu.size());
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) {  // each sensor's total per colour channel
            double g = 0, e = 0, var = 0;
            for (int b = 0; b < 146; ++b) {
                const size_t i = r * 438 + 3 * b + c;
                g += gpu[i], e += cpu[i];
                var += se_gpu[i] * se_gpu[i] + se_cpu[i] * se_cpu[i];
            }
            EXPECT_GT(e, 0);
            EXPECT_NEAR(g, e, kZ * std::sqrt(var) + 1e-6 * e) << "sensor " << r << " channel " << c;
        }
}

// mixfunc: a panel that is grey plastic where x < 0 and mostly void (20 % grey) elsewhere,
// over sensors under a sky; where y > 0 that mixfunc is itself mixed with frosted trans, and
// the whole with void: mixfuncs of mixfuncs, three deep. Both backends' totals (one bin, so
// that each has its own standard error) within their standard errors, each below 2 %. Then the
// scene MixfuncAsRadiance traces (scenes.h's MixfuncHalvesAndScreen), from sensors above both
// halves of its floor, some under its screen, and its downward one.
TEST_F(VulkanContrib, MixfuncAsEmbree) {
    WriteFile(tmp_.path() / "veil.cal", "side = if(Px, .2, 1);\nband = if(Py, .4, 1);\n");
    WriteFile(tmp_.path() / "veil.rad",
              "void plastic grey 0 0 5 .5 .5 .5 0 0\n"
              "void trans frost 0 0 7 .8 .8 .8 0 0 .6 0\n"
              "void mixfunc half 4 grey void side veil.cal 0 0\n"
              "void mixfunc veil 4 half frost band veil.cal 0 0\n"
              "void mixfunc thin 4 veil void .5 . 0 0\n"
              "thin polygon p 0 0 12 -2 -2 1  2 -2 1  2 2 1  -2 2 1\n");
    WriteSensorLine();
    const double total = ExpectSameEntries(
        "-I+ -ab 2 -ad 1024 -lw 1e-5 -b 0 -bn 1 -m skyglow veil.rad sky.rad < rays", 20, .02);
    EXPECT_GT(total, 20.);  // the sky through the void and frosted parts
    WriteFile(tmp_.path() / "mix.cal", test::kMixCal);
    WriteFile(tmp_.path() / "mix.rad", test::MixfuncHalvesAndScreen());
    std::string above;
    for (int i = 0; i < 10; ++i) above += std::to_string(-1.8 + .4 * i) + " 0 .5 0 0 1\n";
    WriteFile(tmp_.path() / "above", above + "-3 3 1 0 0 -1\n");
    EXPECT_GT(ExpectSameEntries("-I+ -ab 2 -ad 1024 -lw 1e-5 -b 0 -bn 1 -m skyglow mix.rad < above",
                                11, .03),
              10.);
}

// Dielectric: an absorbing block (its extinction weighs the rays it spawns against -lw; rays
// reflect inside it, totally at its sides) and a ball lens above it, which turns the sky
// upside down, between sensors and the sky. Both backends within their standard errors, per
// sky bin and per sensor. Then the slab DielectricAsRadiance traces (scenes.h's DielectricSlab)
// over the same sensors, its sun and sky.
TEST_F(VulkanContrib, DielectricAsEmbree) {
    WriteFile(tmp_.path() / "block.rad",
              "void dielectric water 0 0 5 .5 .6 .7 1.5 0\n" +
                  test::BoxOfPolygons("water", "block", {-1, -1, 1}, {1, 1, 2}) +
                  "void dielectric clear 0 0 5 1 1 1 1.5 0\n"
                  "clear sphere ball 0 0 4 0 0 3.5 1\n");
    WriteSensorLine();
    const std::string args =
        "-I+ -ab 3 -ad 512 -lw 0.02" + kBins + "-m skyglow block.rad sky.rad < rays";
    const auto [gpu, se_gpu, cpu, se_cpu] = RunBoth(args, tmp_.path());
    ASSERT_EQ(gpu.size(), 20u * 146 * 3);
    ExpectSameMatrix(gpu, se_gpu, cpu, se_cpu, 2000);
    ExpectSameSensorTotals(gpu, se_gpu, cpu, se_cpu, 20, 146);
    WriteFile(tmp_.path() / "slab.rad", test::DielectricSlab());
    const auto slab = RunBoth(
        "-I+ -ab 3 -ad 512 -lw 0.02" + kBins + "-m solar -m skyglow slab.rad < rays", tmp_.path());
    ExpectSameMatrix(slab.gpu, slab.se_gpu, slab.cpu, slab.se_cpu, 2000);
    ExpectSameSensorTotals(slab.gpu, slab.se_gpu, slab.cpu, slab.se_cpu, 20, 2 * 146);
}

// Local light sources on the GPU: a square panel, a hexagon (sampled over a turned square) facing
// away, a sphere, a spotlight disc and a tube, split by -ds, over a grey floor (-ab 1); then a
// window of illum (void behind it) in a room under a glow sky (-ab 2); then the room of lamps
// LocalSourcesAsRadiance traces. Both backends within their standard errors, per sensor and
// modifier.
TEST_F(VulkanContrib, LocalSourcesAsEmbree) {
    WriteFile(tmp_.path() / "lamps.rad",
              "void light lamp 0 0 3 10 10 10\n"
              "lamp polygon square 0 0 12 -1 -1 2.5  -1 1 2.5  1 1 2.5  1 -1 2.5\n"
              "void light hexlamp 0 0 3 5 5 5\n"
              "hexlamp polygon hex 0 0 18  3 0 2  2.5 .87 2  1.5 .87 2  1 0 2  1.5 -.87 2  "
              "2.5 -.87 2\n"
              "void light globe 0 0 3 3 3 3\nglobe sphere ball 0 0 4 -3 0 2 .3\n"
              "void spotlight spot 0 0 7 20 20 20 60 0 0 -1\n"
              "spot ring disc 0 0 8 0 .5 2 0 0 -1 0 .4\n"
              "void light tubelamp 0 0 3 4 4 4\n"
              "tubelamp cylinder tube 0 0 7 -2 -3 2.2 2 -3 2.2 .05\n"
              "void plastic grey 0 0 5 .5 .5 .5 0 0\n"
              "grey polygon floor 0 0 12 -6 -6 0 6 -6 0 6 6 0 -6 6 0\n");
    WriteFile(tmp_.path() / "illum.rad", test::IllumWindowRoom());
    std::string lamp_rays, room_rays;
    for (int i = 0; i < 10; ++i) {
        lamp_rays +=
            std::to_string(-2.7 + .6 * i) + " " + std::to_string(.3 * i - 1.3) + " .5 0 0 1\n";
        room_rays +=
            std::to_string(.5 + .4 * i) + " " + std::to_string(.5 + .3 * i) + " .8 0 0 1\n";
    }
    WriteFile(tmp_.path() / "lamp_rays", lamp_rays);
    WriteFile(tmp_.path() / "room_rays", room_rays);
    EXPECT_GT(ExpectSameEntries("-I+ -ab 1 -ad 256 -lw 1e-4 -m lamp -m hexlamp -m globe -m spot "
                                "-m tubelamp lamps.rad < lamp_rays",
                                10 * 5),
              0.1);
    EXPECT_GT(ExpectSameEntries(
                  "-I+ -ab 2 -ad 256 -lw 1e-5 -m winillum -m wall illum.rad < room_rays", 10 * 2),
              0.1);
    // The room LocalSourcesAsRadiance traces (scenes.h's LocalSourcesRoom), from its sensors.
    WriteFile(tmp_.path() / "room.rad", test::LocalSourcesRoom());
    WriteFile(tmp_.path() / "sensors",
              "2.5 2 0.8 0 0 1\n1 1 0.8 0 0 1\n4 3 0.8 0 0 1\n0.5 3.5 1 1 0 0\n");
    EXPECT_GT(ExpectSameEntries(
                  "-I+ -ab 1 -ad 256 -lw 1e-4 -m lamp -m bulb -m disc room.rad < sensors", 4 * 3),
              0.1);
}

// Sources seen in mirrors (RADIANCE's virtual sources, -dr): a sun, a lamp and a spotlight
// between two facing mirror walls and a mirror disc, over a grey floor, so that there are images
// of images, a ring's images and a mirrored spot cone. The disc names a substitute material
// (plastic), which the rays not sent toward its images see, but for ambient rays meeting its
// front: an eleventh sensor faces it, and is run again alone with many samples (the substitute
// instead of the mirror for those rays moves its lamp entry by 20 %). Without jitter or ambient
// rays (-ab 0 -dj 0) both backends trace the same rays, and agree to float rounding; with both,
// within their standard errors. The images matter: -dr 0 loses much of the light.
TEST_F(VulkanContrib, MirrorImagesAsEmbree) {
    WriteFile(tmp_.path() / "mirrors.rad",
              "void light solar 0 0 3 1e4 1e4 1e4\nsolar source sun 0 0 4 -.5 -.4 .8 0.533\n"
              "void light lamp 0 0 3 10 10 10\nlamp sphere bulb 0 0 4 0 -2 2.5 .2\n"
              "void spotlight spot 0 0 7 50 50 50 60 1 0 -.3\n"
              "spot ring spotdisc 0 0 8 -1.5 0 2.5 1 0 -.3 0 .1\n"
              "void mirror silver 0 0 3 .9 .9 .9\n"
              "silver polygon east 0 0 12 2 -3 0  2 -3 3  2 3 3  2 3 0\n"
              "silver polygon west 0 0 12 -2 -3 0  -2 3 0  -2 3 3  -2 -3 3\n"
              "void plastic shelfgrey 0 0 5 .6 .6 .6 0 0\n"
              "void mirror silveralt 1 shelfgrey 0 3 .9 .9 .9\n"
              "silveralt ring disc 0 0 8 0 2.5 1.5 0 -1 0 0 .8\n"
              "void plastic grey 0 0 5 .5 .5 .5 0 0\n"
              "grey polygon floor 0 0 12 -6 -6 0 6 -6 0 6 6 0 -6 6 0\n");
    std::string rays;
    for (int i = 0; i < 10; ++i)
        rays += std::to_string(-1.8 + .4 * i) + " " + std::to_string(.4 * i - 1.5) + " .01 0 0 1\n";
    WriteFile(tmp_.path() / "rays", rays + "0 1.5 1.5 0 1 0\n");
    WriteFile(tmp_.path() / "facing", "0 1.5 1.5 0 1 0\n");
    const std::string scene = " -m solar -m lamp -m spot mirrors.rad < rays";
    // Exact: the same rays on both.
    const std::vector<double> gpu0 = Run("vulkan", "-I+ -ab 0 -dj 0" + scene, tmp_.path());
    const std::vector<double> cpu0 = Run("embree", "-I+ -ab 0 -dj 0" + scene, tmp_.path());
    const std::vector<double> cpu_no_images =
        Run("embree", "-I+ -ab 0 -dj 0 -dr 0" + scene, tmp_.path());
    ASSERT_EQ(gpu0.size(), 11u * 3 * 3);
    ASSERT_EQ(cpu0.size(), gpu0.size());
    ASSERT_EQ(cpu_no_images.size(), gpu0.size());
    double totals[3] = {0, 0, 0}, totals_no_images[3] = {0, 0, 0};
    for (size_t i = 0; i < gpu0.size(); i += 3) {
        EXPECT_NEAR(gpu0[i], cpu0[i], 1e-4 * cpu0[i] + 1e-9) << "entry " << i / 3;
        totals[i / 3 % 3] += cpu0[i];
        totals_no_images[i / 3 % 3] += cpu_no_images[i];
    }
    for (int k = 0; k < 3; ++k) EXPECT_GT(totals[k], 1.2 * totals_no_images[k]) << "source " << k;
    // Jittered sources and ambient rays.
    EXPECT_GT(ExpectSameEntries("-I+ -ab 1 -ad 128 -lw 1e-4 -dj .7" + scene, 11 * 3), 0);
    // The sensor facing the disc: each entry known to 5 %.
    ExpectSameEntries(
        "-I+ -ab 1 -ad 4096 -lw 1e-5 -dj .7 -m solar -m lamp -m spot mirrors.rad < facing", 3, .05);
}

// Materials standing in for others: a mirror naming a substitute (grey plastic) as a side of a
// mixfunc (the other half void), an illum whose alternate is such a mixfunc (of grey and void),
// and an illum whose alternate is a Lambertian Klems BSDF (transmitting .3, reflecting .2).
// Rays meeting the mirror's back see its substitute, and rays meeting an illum's back its
// alternate. A 4 x 4 panel, its front up, one unit above an upward sensor, between a sky and a
// ground of radiance 1 (-ab 2): the sky's column is pi (1 - F + F t) and the ground's pi F r,
// F the panel's view factor, t and r what the panel's underside passes of the sky and reflects
// of the ground (for the mixfuncs .5 and .5 x .5 of grey's .5). Both backends within their
// standard errors.
TEST_F(VulkanContrib, StandInMaterialsAsEmbree) {
    for (const std::string panel : {"void mirror silver 1 grey 0 3 .9 .9 .9\n"
                                    "void mixfunc half 4 silver void .5 . 0 0\n",
                                    "void mixfunc greyish 4 grey void .5 . 0 0\n"
                                    "void illum half 1 greyish 0 3 1 1 1\n"})
        ExpectPanelUndersideSeen(panel, .5, .25);
    WriteFile(tmp_.path() / "lambertian.xml", test::LambertianKlemsXml(.3, .2));
    ExpectPanelUndersideSeen(
        "void BSDF lambertian 6 0 lambertian.xml 0 1 0 . 0 0\n"
        "void illum half 1 lambertian 0 3 1 1 1\n",
        .3, .2);
}

void VulkanContrib::ExpectPanelUndersideSeen(const std::string &panel, double through,
                                             double reflected) {
    WriteFile(tmp_.path() / "panel.rad",
              "void plastic grey 0 0 5 .5 .5 .5 0 0\n" + panel +
                  "half polygon panel 0 0 12 -2 -2 1  2 -2 1  2 2 1  -2 2 1\n"
                  "void glow groundglow 0 0 4 1 1 1 0\n"
                  "groundglow source ground 0 0 4 0 0 -1 180\n");
    WriteFile(tmp_.path() / "up", "0 0 0 0 0 1\n");
    const double f = test::ParallelRectangleViewFactor(2, 2, 1);
    const auto [gpu, se_gpu, cpu, se_cpu] = RunBoth(
        "-I+ -ab 2 -ad 4096 -lw 1e-6 -b 0 -bn 1 -m skyglow -m groundglow panel.rad sky.rad < up",
        tmp_.path());
    ASSERT_EQ(cpu.size(), 2u * 3);
    ASSERT_EQ(gpu.size(), cpu.size());
    const double exact[2] = {M_PI * (1 - f + f * through), M_PI * f * reflected};
    for (int c = 0; c < 2; ++c) {
        EXPECT_NEAR(cpu[3 * c], exact[c], kZ * se_cpu[3 * c]) << panel << c;
        EXPECT_NEAR(gpu[3 * c], exact[c], kZ * se_gpu[3 * c]) << panel << c;
        EXPECT_LT(se_gpu[3 * c], .02 * exact[c]) << panel << c;
    }
}

// antimatter on the GPU: a sphere of it cuts a round hole (radius .5 at height 1) in a grey
// disc roof of radius 100 above sensors at the origin. Sensors see the sky through the hole and
// beyond the roof's edge: pi (1/5 + 1/10001) in all (RADIANCE's view factors of discs), on both
// backends, and the two agree bin by bin.
TEST_F(VulkanContrib, AntimatterAsEmbree) {
    WriteFile(tmp_.path() / "cut.rad",
              "void plastic grey 0 0 5 .5 .5 .5 0 0\nvoid antimatter hole 2 void grey 0 0\n"
              "grey ring roof 0 0 8 0 0 1 0 0 1 0 100\n"
              "hole sphere cutter 0 0 4 0 0 1 .5\n");
    std::string rays;
    for (int i = 0; i < 10; ++i) rays += "0 0 0 0 0 1\n";
    WriteFile(tmp_.path() / "rays", rays);
    const std::string args =
        "-I+ -ab 1 -ad 2048 -lw 1e-5" + kBins + "-m skyglow cut.rad sky.rad < rays";
    const auto [gpu, se_gpu, cpu, se_cpu] = RunBoth(args, tmp_.path());
    ASSERT_EQ(gpu.size(), 10u * 146 * 3);
    ExpectSameMatrix(gpu, se_gpu, cpu, se_cpu, 100);
    const double expected = M_PI * (.2 + 1. / 10001.);
    for (const auto *m : {&gpu, &cpu}) {
        const std::vector<double> &se = m == &gpu ? se_gpu : se_cpu;
        for (int r = 0; r < 10; ++r) {
            double total = 0, var = 0;
            for (int k = 0; k < 146 * 3; k += 3) {
                total += (*m)[r * 146 * 3 + k];
                var += se[r * 146 * 3 + k] * se[r * 146 * 3 + k];
            }
            EXPECT_NEAR(total, expected, kZ * std::sqrt(var)) << (m == &gpu ? "gpu " : "cpu ") << r;
        }
    }
}

// What the GPU's core cannot trace goes to Embree, with one line saying why, and the results
// are Embree's: more specular samples than the ray stack holds (-ss above 16), and mixfuncs
// nested deeper than the shader's stack of their sides. So does a machine whose only device is
// a CPU one, unless it is named.
TEST_F(VulkanContrib, WhatItCannotTraceFallsBackToEmbree) {
    WriteFile(tmp_.path() / "rays", "0 0 0 0 0 1\n");
    // Both backends on args: the Vulkan one says why it cannot, and its output is Embree's.
    const auto expect_fallback = [&](const std::string &args, const std::string &why) {
        const CommandResult gpu = RunCommand(
            kDevice + "rcontrib-gpu -backend vulkan -h -faa -I+ -ab 1 " + args + " < rays",
            tmp_.path());
        const CommandResult cpu =
            RunCommand("rcontrib-gpu -h -faa -I+ -ab 1 " + args + " < rays", tmp_.path());
        ASSERT_EQ(gpu.status, 0) << gpu.err;
        EXPECT_NE(gpu.err.find(why), std::string::npos) << gpu.err;
        EXPECT_EQ(gpu.out, cpu.out);
    };
    expect_fallback("-ad 64 -ss 20" + kBins + "-m skyglow sky.rad",
                    "the Vulkan backend cannot take this run (-ss above 16 (more specular samples "
                    "than the GPU's ray stack holds))");
    std::string nested = "void plastic m0 0 0 5 .5 .5 .5 0 0\n";
    for (int i = 1; i <= 8; ++i)
        nested += "void mixfunc m" + std::to_string(i) + " 4 m" + std::to_string(i - 1) +
                  " void .5 . 0 0\n";
    WriteFile(tmp_.path() / "nested.rad",
              nested + "m8 polygon roof 0 0 12 -2 -2 1  2 -2 1  2 2 1  -2 2 1\n");
    expect_fallback("-ad 64" + kBins + "-m skyglow nested.rad sky.rad",
                    "(a mixfunc nested more than 7 deep (roof) is traced on the CPU only)");
    CommandResult unnamed = RunCommand(
        "DAYFLUX_VULKAN_DEVICE= rcontrib-gpu -backend vulkan -h "
        "-I+ -ab 1 -ad 16" +
            kBins + "-m skyglow sky.rad < rays",
        tmp_.path());
    ASSERT_EQ(unnamed.status, 0) << unnamed.err;
    if (unnamed.err.find("cannot take this run") != std::string::npos) {
        EXPECT_NE(unnamed.err.find("CPU device"), std::string::npos) << unnamed.err;
    }
}

// Our own BVH walk (for devices without ray queries) finds the hits ray queries find: with the
// same random numbers, the tutorial room (triangles) and analytic surfaces (a bubble, sphere,
// disc and tube, which the BVH holds beside the triangles) come out the same entry for entry,
// but for the odd ray grazing an edge, where float tests may differ.
TEST_F(VulkanContrib, BvhTraversalFindsWhatRayQueriesFind) {
    // Devices without ray queries (NVIDIA's H100 and H200) have only our walk to compare.
    if (const std::string why = WhyEmbree("-gpu_traversal rayquery -ab 0"); !why.empty())
        GTEST_SKIP() << why;
    const fs::path room = DataDir() / "scene" / "models" / "room";
    WriteFile(tmp_.path() / "shapes.rad",
              "void plastic grey 0 0 5 .5 .5 .5 0 0\ngrey sphere s 0 0 4 .5 .3 2 .5\n"
              "grey tube t 0 0 7 -1 0 0 -1 0 3 .5\ngrey ring d 0 0 8 1 1 2.5 0 0 -1 0 .5\n"
              "grey bubble b 0 0 4 0 0 0 10\ngrey polygon floor 0 0 12 -3 -3 -.1 3 -3 -.1 3 3 -.1 "
              "-3 3 -.1\n");
    std::string rays;
    for (int i = 0; i < 20; ++i) rays += "0 0 0 0 0 1\n.3 -.2 .5 0 .3 1\n";
    WriteFile(tmp_.path() / "rays", rays);
    const std::string room_args = "-I+ -ab 2 -ad 256 -lw 1e-3" + kBins +
                                  "-m skyglow materials.rad room.rad objects/Glazing.rad "
                                  "skyDomes/skyglow.rad < '" +
                                  (DataDir() / "rcontrib" / "points.txt").string() + "'";
    const std::string shape_args =
        "-I+ -ab 3 -ad 256 -lw 1e-4" + kBins + "-m grey shapes.rad < rays";
    struct Case {
        std::string args;
        fs::path dir;
    } cases[] = {{room_args, room}, {shape_args, tmp_.path()}};
    for (const Case &c : cases) {
        const std::vector<double> rq = Run("vulkan", "-gpu_traversal rayquery " + c.args, c.dir);
        const std::vector<double> bvh = Run("vulkan", "-gpu_traversal bvh " + c.args, c.dir);
        ASSERT_EQ(rq.size(), bvh.size());
        ASSERT_GT(rq.size(), 0u);
        size_t differ = 0;
        double total_rq = 0, total_bvh = 0;
        for (size_t i = 0; i < rq.size(); ++i) {
            total_rq += rq[i], total_bvh += bvh[i];
            if (std::fabs(rq[i] - bvh[i]) > 1e-5 * std::fabs(rq[i]) + 1e-12) ++differ;
        }
        EXPECT_GT(total_rq, 1.);
        EXPECT_LE(differ, rq.size() / 1000) << c.args;
        EXPECT_NEAR(total_bvh, total_rq, 1e-3 * total_rq) << c.args;
    }
}

// The stack and hemisphere rows in scratch buffers (what GPUs use: NVIDIA's driver refuses the
// private arrays) or in private arrays (lavapipe's default): the same arithmetic, so the same
// matrix to the bit, at -ad 65536 too, where the first hemisphere's 256 x 256 cells fill the
// private rows to the last. (Slow on lavapipe: its LLVM compiles the scratch shader for minutes.)
TEST_F(VulkanContrib, ScratchBuffersAsPrivateArrays) {
    const fs::path room = DataDir() / "scene" / "models" / "room";
    std::istringstream points(ReadFile(DataDir() / "rcontrib" / "points.txt"));
    std::string three, line;
    for (int i = 0; i < 3 && std::getline(points, line); ++i) three += line + "\n";
    WriteFile(tmp_.path() / "three.pts", three);
    {
        // NVIDIA's driver refuses the private arrays: then the run must say so, and there is
        // nothing to compare.
        const CommandResult r = RunCommand(
            "head -1 '" + (tmp_.path() / "three.pts").string() + "' | " + kDevice +
                "rcontrib-gpu -backend vulkan -gpu_scratch off -h -I+ -ab 1 -ad 16" + kBins +
                "-m skyglow materials.rad room.rad objects/Glazing.rad skyDomes/skyglow.rad",
            room);
        if (r.status != 0) {
            ASSERT_NE(r.err.find("the driver refused the compute pipeline"), std::string::npos)
                << r.err;
            ASSERT_NE(r.err.find("-gpu_scratch on"), std::string::npos) << r.err;
            GTEST_SKIP() << "this device's driver refuses private arrays: " << r.err;
        }
    }
    for (const char *sampling : {"-ab 2 -ad 256 -lw 1e-3", "-ab 1 -ad 65536 -lw 1e-6"}) {
        const std::string args = std::string("-I+ ") + sampling + kBins +
                                 "-m skyglow materials.rad room.rad objects/Glazing.rad "
                                 "skyDomes/skyglow.rad";
        const std::string input = " < '" + (tmp_.path() / "three.pts").string() + "'";
        const std::vector<double> on = Run("vulkan", "-gpu_scratch on " + args + input, room);
        const std::vector<double> off = Run("vulkan", "-gpu_scratch off " + args + input, room);
        ASSERT_EQ(on.size(), 3u * 146 * 3) << sampling;
        EXPECT_TRUE(on == off) << sampling;
        EXPECT_GT(std::accumulate(on.begin(), on.end(), 0.), 0.) << sampling;
    }
    // Past 256 cells a side the private rows end and RADIANCE's collision rule with them;
    // scratch rows are sized by -ad, so scratch keeps it, as Embree does (one random stream:
    // float rounding apart, the same matrix).
    const std::string args = "-I+ -ab 1 -ad 90000 -lw 1e-6" + kBins +
                             "-m skyglow materials.rad room.rad objects/Glazing.rad "
                             "skyDomes/skyglow.rad < '" +
                             (tmp_.path() / "three.pts").string() + "'";
    const std::vector<double> on = Run("vulkan", "-gpu_scratch on " + args, room);
    const std::vector<double> off = Run("vulkan", "-gpu_scratch off " + args, room);
    const std::vector<double> cpu = Run("embree", args, room);
    ASSERT_EQ(on.size(), cpu.size());
    ASSERT_EQ(off.size(), cpu.size());
    const auto rel_rms = [&](const std::vector<double> &a) {
        double d = 0, n = 0;
        for (size_t i = 0; i < a.size(); ++i)
            d += (a[i] - cpu[i]) * (a[i] - cpu[i]), n += cpu[i] * cpu[i];
        return std::sqrt(d / n);
    };
    EXPECT_LT(rel_rms(on), 5e-5);   // 5e-6 on lavapipe
    EXPECT_GT(rel_rms(off), 5e-4);  // 2.7e-3 on lavapipe
}

// Two devices (here the same one opened twice) split the rays between them; rays keep their
// random numbers, so the output is the one device's, byte for byte.
TEST_F(VulkanContrib, TwoDevicesSplitTheRays) {
    const fs::path room = DataDir() / "scene" / "models" / "room";
    const std::string run = "rcontrib-gpu -backend vulkan -h -faf -I+ -ab 2 -ad 256 -lw 1e-3" +
                            kBins +
                            "-m skyglow materials.rad room.rad objects/Glazing.rad "
                            "skyDomes/skyglow.rad < '" +
                            (DataDir() / "rcontrib" / "points.txt").string() + "'";
    const std::string one = "${DAYFLUX_VULKAN_DEVICE:-llvmpipe}";
    CommandResult a = RunCommand("DAYFLUX_VULKAN_DEVICE=" + one + " " + run, room);
    CommandResult b = RunCommand("DAYFLUX_VULKAN_DEVICE=" + one + "," + one + " " + run, room);
    ASSERT_EQ(a.status, 0) << a.err;
    ASSERT_EQ(b.status, 0) << b.err;
    EXPECT_EQ(b.err.find("using Embree"), std::string::npos) << b.err;
    EXPECT_EQ(a.out.size(), 100u * 146 * 12);
    EXPECT_TRUE(a.out == b.out);
}

// The view matrix V of the three-phase method: the tutorial room's sensors to Klems Full
// patches of the window (a glow sender, rfluxmtx's hemisphere basis), both backends.
TEST_F(VulkanContrib, ViewMatrixAsEmbree) {
    RoomMatrixAsEmbree(
        "-I+ -ab 3 -ad 512 -lw 1e-3 -f klems_full.cal -b 'kbin(0,1,0,0,0,1)' -bn Nkbins "
        "-m Glazing materials.rad room.rad objects/GlazingVmtx.rad",
        145);
}

// The daylight matrix D: rays leaving the window's outside face, cosine-distributed (as
// rfluxmtx sends them), to the Reinhart sky, both backends (one modifier, as the other tests
// track, so that they share one compiled shader).
TEST_F(VulkanContrib, DaylightMatrixAsEmbree) {
    const fs::path room = DataDir() / "scene" / "models" / "room";
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(0, 1);
    std::ostringstream rays;
    for (int i = 0; i < 400; ++i) {  // on the glazing (y = 0, outside is -y), 1 mm out
        const double x = 6.096 * u(rng), z = 0.9144 + (2.4384 - 0.9144) * u(rng);
        const double r = std::sqrt(u(rng)), phi = 2 * M_PI * u(rng);
        const double dx = r * std::cos(phi), dz = r * std::sin(phi), dy = -std::sqrt(1 - r * r);
        rays << x << " -0.001 " << z << " " << dx << " " << dy << " " << dz << "\n";
    }
    WriteFile(tmp_.path() / "window_rays", rays.str());
    const std::string args = "-c 20 -ab 2 -ad 256 -lw 1e-3" + kBins +
                             "-m skyglow materials.rad room.rad objects/Glazing.rad "
                             "skyDomes/skyglow.rad < '" +
                             (tmp_.path() / "window_rays").string() + "'";
    const auto [gpu, se_gpu, cpu, se_cpu] = RunBoth(args, room);
    ASSERT_EQ(gpu.size(), 20u * 146 * 3);
    ExpectSameMatrix(gpu, se_gpu, cpu, se_cpu, 1000);
}

// aBSDF, on the sheets ApertureBsdfAsRadiance traces (scenes.h's ApertureSheet: clear glass
// with a strong peak, and a fabric with some openness: a peak and a surround) under its sun and
// patch, from its sensors (-I+) and view rays (-I-) below: shadow rays passing the peak, view
// rays straight through it and their samples leaving its direction out (-st 0: all sampled),
// and the surround given to sources near it; both backends within their standard errors (and
// 1e-5 of the values that have none).
TEST_F(VulkanContrib, ApertureBsdfAsEmbree) {
    for (const char *xml : {"clear.xml", "frads_klems_aniso_high.xml"})
        fs::copy_file(DataDir() / "bsdf" / xml, tmp_.path() / xml);
    WriteFile(tmp_.path() / "patch.rad", test::SunAndPatch());
    WriteFile(tmp_.path() / "sensors", "0 0 0 0 0 1\n0 0 0 0 0.64 0.77\n");
    WriteFile(tmp_.path() / "views",
              "0 0 0 0 0.6427876 0.7660444\n0 0 0 0 -.5 .866\n0 0 0 0.3 0.2 0.93\n");
    for (const char *xml : {"clear.xml", "frads_klems_aniso_high.xml"}) {
        SCOPED_TRACE(xml);
        WriteFile(tmp_.path() / "sheet.rad", test::ApertureSheet(xml));
        const std::string run = std::string("-dj 0 -ab 2 -ad 1024 -lw 1e-4") + kBins +
                                "-m skyglow -m solar patch.rad sheet.rad ";
        ExpectSameTotals("-I+ " + run + "< sensors", 2 * 292, 1e-5);
        ExpectSameTotals("-I- -st 0 " + run + "< views", 3 * 292, 1e-5);
    }
}

// The BSDF material on the GPU: the tutorial room with venetian blinds (a Klems BSDF) in its
// window, a sky and a sun: specular samples from the matrix, the Lambertian part as ambient, the
// sun through the BSDF. Ten sensors, each traced 8 times: per-modifier totals of both backends
// within 4 standard errors of their difference (from the spread of the replicas). (Compiling
// this shader takes lavapipe minutes; a GPU's driver, seconds.)
TEST_F(VulkanContrib, KlemsBsdfAsEmbree) {
    const fs::path room = DataDir() / "scene" / "models" / "room";
    ASSERT_EQ(
        RunCommand("xz -dc '" + (DataDir() / "rcontrib/bsdf_room/frads_blinds30.xml.xz").string() +
                       "' > frads_blinds30.xml",
                   tmp_.path())
            .status,
        0);
    std::string blinds = ReadFile(DataDir() / "rcontrib/bsdf_room/blinds.rad");
    const size_t at = blinds.find("6 0 frads_blinds30.xml");  // the material's file argument
    ASSERT_NE(at, std::string::npos);
    blinds.replace(at + 4, 18, (tmp_.path() / "frads_blinds30.xml").string());
    WriteFile(tmp_.path() / "blinds.rad", blinds);
    WriteFile(tmp_.path() / "sun.rad",
              "void light solar 0 0 3 1 1 1\nsolar source sun 0 0 4 0.3 -0.6 0.742 0.533\n");
    std::ostringstream rays;
    {
        std::istringstream in(ReadFile(DataDir() / "rcontrib" / "points.txt"));
        std::string line;
        for (int s = 0; s < 10 && std::getline(in, line);)
            if (!line.empty()) {
                for (int k = 0; k < 8; ++k) rays << line << "\n";
                ++s;
            }
    }
    WriteFile(tmp_.path() / "rays", rays.str());
    const std::string args =
        "-I+ -ab 2 -ad 256 -lw 1e-4" + kBins + "-m skyglow -m solar materials.rad room.rad '" +
        (tmp_.path() / "blinds.rad").string() + "' skyDomes/skyglow.rad '" +
        (tmp_.path() / "sun.rad").string() + "' < '" + (tmp_.path() / "rays").string() + "'";
    // Then with -ss 4: several samples of the BSDF's specular part, stratified, per hit where a
    // ray's weight is high, so the sensors' rays go as they are (-I-) toward the window.
    std::string toward_window = rays.str();
    for (size_t at = 0; (at = toward_window.find(" 0 0 1", at)) != std::string::npos;)
        toward_window.replace(at, 6, " 0 -1 .35");
    WriteFile(tmp_.path() / "rays_to_window", toward_window);
    for (const std::string ss : {"", "-I- -ss 4 "}) {
        std::vector<double> total[2], var[2];
        int b = 0;
        for (const char *backend : {"vulkan", "embree"}) {
            std::string a = args;
            if (!ss.empty())
                a.replace(a.find("-I+ "), 4, ss).replace(a.find("rays'"), 4, "rays_to_window");
            const std::vector<double> v = Run(backend, a, room);
            ASSERT_EQ(v.size(), 80u * 292 * 3) << backend << ss;
            total[b].assign(2, 0.), var[b].assign(2, 0.);
            for (int s = 0; s < 10; ++s)
                for (int m = 0; m < 2; ++m) {
                    double sum = 0, sq = 0;
                    for (int k = 0; k < 8; ++k) {
                        double x = 0;
                        for (int bin = 0; bin < 146; ++bin)
                            x += v[((s * 8 + k) * 292 + m * 146 + bin) * 3];
                        sum += x, sq += x * x;
                    }
                    total[b][m] += sum / 8;
                    var[b][m] += (sq - sum * sum / 8) / 7 / 8;
                }
            ++b;
        }
        const char *names[2] = {"sky", "sun"};
        for (int m = 0; m < 2; ++m) {
            EXPECT_GT(total[1][m], 0) << names[m] << ss;
            EXPECT_NEAR(total[0][m], total[1][m], 4 * std::sqrt(var[0][m] + var[1][m]))
                << names[m] << ss;
            EXPECT_LT(std::sqrt(var[0][m] + var[1][m]), 0.03 * total[1][m]) << names[m] << ss;
        }
    }
}

}  // namespace
}  // namespace dayflux::test
