// Generated GLSL against the interpreter, run on a Vulkan device (lavapipe in CI).
#include "cal/glsl.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>

#include "raytrace/vulkan/raytracing.h"

namespace dayflux::cal {
namespace {

std::string Lib(const char *f) { return std::string(DAYFLUX_LIB_DIR) + "/" + f; }

struct Case {
    std::string name;
    std::function<void(Context &)> load;
    std::vector<std::string> exprs;
};

// What a comparison allows: each value within tolerance of the interpreter's, relative to the
// larger of it and `floor`, but for at most `allowed` values.
struct Allowance {
    double tolerance = 0, floor = 0;
    int allowed = 0;
};

class GlslAgainstInterpreter : public testing::Test {
  protected:
    static void SetUpTestSuite() {
        // Any device with ray queries will do, lavapipe included; the scene is empty. The
        // double code runs where shaderFloat64 is enabled, the float code on a device opened
        // without it (as the engine opens one by default).
        device_ = vk::GpuDevice::Open(&skip_reason_, true, vk::Traversal::kRayQuery, 0, "", true)
                      .release();
        if (device_) device_->BuildScene({}, {});
        single_device_ =
            vk::GpuDevice::Open(&single_skip_reason_, true, vk::Traversal::kRayQuery).release();
        if (single_device_) single_device_->BuildScene({}, {});
    }
    static void TearDownTestSuite() {
        delete device_;
        delete single_device_;
        device_ = single_device_ = nullptr;
    }

    // Evaluates exprs on the device for n random directions, in the generated code's precision
    // (in float, the directions rounded to float first, for both), and compares every value with
    // the interpreter's.
    // Gives the device's values, n x exprs.size().
    std::vector<double> Compare(Context &cx, const std::vector<std::string> &exprs, int n,
                                unsigned seed, Allowance allow = {},
                                const std::vector<double> &object_args = {},
                                GlslPrecision precision = GlslPrecision::kDouble) {
        const bool single = precision == GlslPrecision::kFloat;
        vk::GpuDevice *device = single ? single_device_ : device_;
        if (!device) {
            [&] {
                GTEST_SKIP() << "no Vulkan device" << (single ? "" : " with shaderFloat64") << ": "
                             << (single ? single_skip_reason_ : skip_reason_);
            }();
            return {};
        }
        const std::string t = single ? "float" : "double", suffix = single ? "" : "LF";
        std::vector<Expression> compiled;
        for (const auto &e : exprs) compiled.push_back(cx.Compile(e, FileLoc{"-b", 0}));
        std::vector<GlslEntry> entries;
        for (size_t k = 0; k < exprs.size(); ++k)
            entries.push_back({"entry" + std::to_string(k), &compiled[k]});
        const int k = static_cast<int>(exprs.size());
        GlslOptions options;
        options.precision = precision;
        std::string src =
            "#version 450\nlayout(local_size_x = 64) in;\n"
            "layout(std430, binding = 1) readonly buffer In { " +
            t + " dirs[]; };\nlayout(std430, binding = 2) writeonly buffer Out { " + t +
            " vals[]; };\n" + GenerateGlsl(cx, entries, options) +
            "void main() {\n  uint i = gl_GlobalInvocationID.x;\n  if (i >= " + std::to_string(n) +
            "u) return;\n  for (int c = 0; c < 3; ++c) cal_chan[c + 1] = "
            "dirs[3 * i + c];\n";
        src += "  cal_arg[0] = " + std::to_string(object_args.size()) + ".0" + suffix + ";\n";
        for (size_t a = 0; a < object_args.size(); ++a) {
            char lit[64];
            std::snprintf(lit, sizeof lit, "%.17e", object_args[a]);
            src += "  cal_arg[" + std::to_string(a + 1) + "] = " + lit + suffix + ";\n";
        }
        for (int e = 0; e < k; ++e)
            src += "  vals[" + std::to_string(k) + " * i + " + std::to_string(e) + "] = entry" +
                   std::to_string(e) + "();\n";
        src += "}\n";
        const auto spirv = vk::GpuDevice::CompileGlsl(src, "glsl_test");
        EXPECT_EQ(vk::GpuDevice::UsesFloat64(spirv), !single);
        std::vector<double> dirs(3 * static_cast<size_t>(n));
        std::mt19937_64 rng(seed);
        std::normal_distribution<double> g;
        for (int i = 0; i < n; ++i) {
            double x = g(rng), y = g(rng), z = g(rng), r = std::sqrt(x * x + y * y + z * z);
            dirs[3 * i] = x / r, dirs[3 * i + 1] = y / r, dirs[3 * i + 2] = z / r;
        }
        const size_t bytes = single ? sizeof(float) : sizeof(double);
        std::vector<uint8_t> in(dirs.size() * bytes), out(static_cast<size_t>(n) * k * bytes);
        for (size_t i = 0; i < dirs.size(); ++i) {
            if (single) {
                const float f = static_cast<float>(dirs[i]);
                dirs[i] = f;
                std::memcpy(in.data() + i * bytes, &f, bytes);
            } else {
                std::memcpy(in.data() + i * bytes, &dirs[i], bytes);
            }
        }
        device->Run(spirv, n, 64, {vk::GpuDevice::In(&in), vk::GpuDevice::InOut(&out)});
        std::vector<double> gpu(static_cast<size_t>(n) * k);
        for (size_t i = 0; i < gpu.size(); ++i) {
            float f;
            if (single)
                std::memcpy(&f, out.data() + i * bytes, bytes), gpu[i] = f;
            else
                std::memcpy(&gpu[i], out.data() + i * bytes, bytes);
        }
        ChannelArray ray(std::vector<double>(27, 0.0));
        ray.SetObjectArguments(object_args);
        int differ = 0;
        std::string first;  // the first few that differ
        for (int i = 0; i < n; ++i) {
            std::copy(&dirs[3 * i], &dirs[3 * i + 3], ray.values().begin());
            for (int e = 0; e < k; ++e) {
                const double want = compiled[e].Evaluate(cx, &ray),
                             got = gpu[static_cast<size_t>(i) * k + e];
                if (std::fabs(got - want) <=
                    allow.tolerance * std::max(std::fabs(want), allow.floor))
                    continue;
                if (differ++ < 5) {
                    char line[256];
                    std::snprintf(line, sizeof line,
                                  "\n%s at (%.9g, %.9g, %.9g): GPU %.17g, "
                                  "interpreter %.17g",
                                  exprs[e].c_str(), dirs[3 * i], dirs[3 * i + 1], dirs[3 * i + 2],
                                  got, want);
                    first += line;
                }
            }
        }
        EXPECT_LE(differ, allow.allowed) << "in " << t << " on " << device->Name() << first;
        return gpu;
    }

    static vk::GpuDevice *device_, *single_device_;
    static std::string skip_reason_, single_skip_reason_;
};
vk::GpuDevice *GlslAgainstInterpreter::device_ = nullptr;
vk::GpuDevice *GlslAgainstInterpreter::single_device_ = nullptr;
std::string GlslAgainstInterpreter::skip_reason_;
std::string GlslAgainstInterpreter::single_skip_reason_;

// The test: a million random directions through every standard bin function. In float
// (the GPU's default, no shaderFloat64), the bins the interpreter gives on the same float
// directions, but where float arithmetic lands within its rounding (about 1e-7) of a bin's edge:
// 1 of these 4 million on lavapipe; 8 allowed.
TEST_F(GlslAgainstInterpreter, StandardBinFunctionsGiveIdenticalBins) {
    Context cx;
    cx.LoadRayInit();
    cx.LoadFile(Lib("tregenza.cal"));
    cx.Set("MF", 4, true);
    cx.LoadFile(Lib("reinhart.cal"));
    cx.LoadFile(Lib("klems_full.cal"));
    const std::vector<std::string> bins = {"tbin", "rbin", "kbin(0,0,1, 0,1,0)", "kbinS"};
    Compare(cx, bins, 1000000, 7);
    Compare(cx, bins, 1000000, 7, {0, 0, 8}, {}, GlslPrecision::kFloat);
}

TEST_F(GlslAgainstInterpreter, ReinhartbAndSmallerKlemsBases) {
    Context cx;
    cx.LoadRayInit();
    cx.LoadFile(Lib("reinhartb.cal"));
    cx.Set("MF", 6);
    cx.LoadFile(Lib("klems_half.cal"));
    Context cq;
    cq.LoadRayInit();
    cq.LoadFile(Lib("klems_quarter.cal"));
    Compare(cx, {"rbin", "khbin(0,0,-1, 0,1,0)"}, 200000, 8);
    Compare(cq, {"kqbin(1,0,0, 0,0,1)"}, 200000, 9);
}

// Two contexts in one shader, each with its own select() helpers (genBSDF's two Klems receivers,
// each with its -p): the helpers carry their context's prefix, so the shader compiles. Before,
// both were cal_select_10 and glslang refused the second body. (Compiling needs no device.)
TEST(GlslContexts, SelectHelpersOfTwoContextsInOneShader) {
    std::string src =
        "#version 450\nlayout(local_size_x = 1) in;\n"
        "layout(std430, binding = 0) writeonly buffer Out { double vals[]; };\n";
    Context contexts[2];
    std::vector<Expression> bins;
    bins.reserve(2);
    for (int g = 0; g < 2; ++g) {
        contexts[g].LoadRayInit();
        contexts[g].Set("RHS", g == 0 ? -1 : 1);
        contexts[g].LoadFile(Lib("klems_full.cal"));
        bins.push_back(contexts[g].Compile("kbin(0,0,1,0,-1,0)", FileLoc{"-b", 0}));
        GlslOptions o;
        o.prefix = g == 0 ? "cal_d" : "cal_c1_d";
        o.preamble = g == 0;
        src += GenerateGlsl(contexts[g], {{"bin" + std::to_string(g), &bins.back()}}, o);
    }
    src += "void main() { vals[0] = bin0(); vals[1] = bin1(); }\n";
    EXPECT_NE(src.find("cal_c1_d_select"), std::string::npos);
    EXPECT_FALSE(vk::GpuDevice::CompileGlsl(src, "two_contexts").empty());
}

// The double-precision math library agrees with the C library to ~1e-14; the float one within
// 4e-6 (relative, or absolute below 1; 1.9e-6 on lavapipe, most of it exp(20 Dx)'s argument
// rounded), select() and rand() left out (a floor at an integer's edge; rand's float stream is
// not double's).
TEST_F(GlslAgainstInterpreter, MathFunctionsMatchTheCLibrary) {
    Context cx;
    cx.LoadRayInit();
    std::vector<std::string> math = {"sin(7*Dx)",
                                     "cos(40*Dy)",
                                     "tan(Dz)",
                                     "asin(Dx)",
                                     "acos(Dy)",
                                     "atan(9*Dz)",
                                     "atan2(Dy, Dx)",
                                     "exp(20*Dx)",
                                     "log(Dx*Dx + 1e-3)",
                                     "log10(Dy*Dy + 2)",
                                     "(Dz + 2)^3.7",
                                     "(-2)^3",
                                     "sqrt(Dx*Dx)",
                                     "max(Dx, Dy, Dz) - min(Dx, Dy)",
                                     "if(Dx, 1/Dy, floor(Dz))"};
    Compare(cx, math, 20000, 10, {4e-6, 1, 0}, {}, GlslPrecision::kFloat);
    math.insert(math.end(), {"select(floor(3*Dx*Dx) + 1, 1, 2, 3, 4)", "rand(Dx)"});
    Compare(cx, math, 20000, 10, {2e-14});
}

// Where the C library gives NaN or infinity, both give 0 (libfunc()'s and epow()'s rule); GLSL's
// own sqrt of a negative number is undefined, so cal_sqrt, cal_asin and cal_acos test first.
TEST_F(GlslAgainstInterpreter, DomainAndRangeErrorsGiveZero) {
    Context cx;
    cx.LoadRayInit();
    testing::internal::CaptureStderr();
    Compare(cx,
            {"sqrt(Dx)", "log(Dy)", "log10(Dz)", "asin(3*Dx)", "acos(3*Dy)", "exp(800*abs(Dz))",
             "Dx^.5", "Dy^(-1)", "sqrt(-4) + 1"},
            20000, 13, {2e-14});
    // (in float, results past 3.4e38 are range errors: exp(800 |Dz|) would be 0 on the GPU)
    Compare(cx,
            {"sqrt(Dx)", "log(Dy)", "log10(Dz)", "asin(3*Dx)", "acos(3*Dy)", "exp(-800*abs(Dz))",
             "Dx^.5", "sqrt(-4) + 1"},
            20000, 13, {4e-6, 1, 0}, {}, GlslPrecision::kFloat);
    testing::internal::GetCapturedStderr();
}

// A sky pattern as gensky writes it: skybright.cal's skybr with the pattern's arguments.
TEST_F(GlslAgainstInterpreter, SkyPatternWithObjectArguments) {
    // Each pattern has a context of its own (the two files use the same names, as RADIANCE's do).
    Context gensky, gendaylit;
    gensky.LoadRayInit();
    gensky.LoadFile(Lib("skybright.cal"));
    gendaylit.LoadRayInit();
    gendaylit.LoadFile(Lib("perezlum.cal"));
    const std::vector<double> gensky_args = {1, 21.8, 3.9, 2.2, -0.42, -0.43, 0.80},
                              gendaylit_args = {7.5, 3.1, -1, -0.3, 3, -2, 0.5, 0.2, -0.4, 0.89};
    Compare(gensky, {"skybr"}, 20000, 11, {2e-14}, gensky_args);
    Compare(gendaylit, {"skybright"}, 20000, 12, {2e-14}, gendaylit_args);
    // In float: skybr within 3e-5 (1.1e-5 on lavapipe: its exponentials amplify the arguments'
    // rounding), perezlum's within 3e-6 (7.6e-7).
    Compare(gensky, {"skybr"}, 20000, 11, {3e-5}, gensky_args, GlslPrecision::kFloat);
    Compare(gendaylit, {"skybright"}, 20000, 12, {3e-6}, gendaylit_args, GlslPrecision::kFloat);
}

// rand() in float: frac(1e5 / x) from the remainder, so its numbers spread over the unit
// interval; taken from the float quotient they were 256 values.
TEST_F(GlslAgainstInterpreter, RandInFloatSpreads) {
    Context cx;
    cx.LoadRayInit();
    const std::vector<double> r =
        Compare(cx, {"rand(Dx)"}, 20000, 14, {1e300}, {}, GlslPrecision::kFloat);
    if (r.empty()) return;  // (skipped: no device)
    ASSERT_EQ(r.size(), 20000u);
    std::vector<double> sorted = r;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_GE(sorted.front(), 0);
    EXPECT_LT(sorted.back(), 1);
    const size_t distinct = std::unique(sorted.begin(), sorted.end()) - sorted.begin();
    EXPECT_GT(distinct, 19000u);
    double mean = 0;
    for (double x : r) mean += x / double(r.size());
    EXPECT_NEAR(mean, 0.5, 4 * std::sqrt(1.0 / 12 / double(r.size())));
}

}  // namespace
}  // namespace dayflux::cal
