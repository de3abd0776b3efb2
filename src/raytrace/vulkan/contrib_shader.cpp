#include "raytrace/vulkan/contrib_shader.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <random>

#include "cal/glsl.h"
#include "raytrace/vulkan/raytracing.h"
#include "raytrace/vulkan/shaders/embedded.h"
#include "util/errors.h"

namespace dayflux {

namespace fs = std::filesystem;

namespace {

// GLSL of the tracked modifiers' bins: one function per distinct bin expression within each
// calcomp context (-M may name thousands of modifiers sharing one; modifiers given different -p
// parameters have contexts of their own, each's definitions under a prefix of its own), and
// EvalBin(j), which runs function j. Sets bin_function per modifier.
std::string BinGlsl(const std::vector<TrackedModifier> &tracked, const MakeContext &make_context,
                    cal::GlslPrecision precision, std::vector<int> *bin_function) {
    struct BinContext {
        std::unique_ptr<cal::Context> cx;
        std::vector<cal::Expression> bins;
        std::vector<cal::GlslEntry> entries;
        std::map<std::string, int> function_of;  // expression -> global bin function index
    };
    std::vector<BinContext> contexts;
    std::vector<int> context_of(tracked.size());
    int nfunctions = 0;
    for (size_t k = 0; k < tracked.size(); ++k) {
        const TrackedModifier &t = tracked[k];
        if (t.context_of < 0) {
            context_of[k] = static_cast<int>(contexts.size());
            contexts.push_back({make_context(static_cast<int>(k)), {}, {}, {}});
            contexts.back().bins.reserve(tracked.size());  // entries point into it
        } else {
            context_of[k] = context_of[t.context_of];
        }
        BinContext &c = contexts[context_of[k]];
        auto [it, added] = c.function_of.emplace(t.bin_expression, nfunctions);
        if (added) {
            // the tree alone becomes GLSL: nothing specialised for the CPU
            c.bins.push_back(c.cx->CompileInterpreted(t.bin_expression, FileLoc{"-b", 0}));
            c.entries.push_back({"cal_bin" + std::to_string(nfunctions), &c.bins.back()});
            ++nfunctions;
        }
        bin_function->push_back(it->second);
    }
    std::string glsl;
    for (size_t g = 0; g < contexts.size(); ++g) {
        cal::GlslOptions go;
        go.precision = precision;
        go.prefix = g == 0 ? go.prefix : "cal_c" + std::to_string(g) + "_d";
        go.preamble = g == 0;
        glsl += cal::GenerateGlsl(*contexts[g].cx, contexts[g].entries, go);
    }
    glsl += "cal_real EvalBin(int j) {\n";
    for (int j = 0; j < nfunctions; ++j)
        glsl +=
            "    if (j == " + std::to_string(j) + ") return cal_bin" + std::to_string(j) + "();\n";
    return glsl + "    return -1.0;\n}\n";
}

// GLSL of the patterns the tables name, and PatternRGB(k), which runs pattern k.
std::string PatternGlsl(const std::vector<const PatternFunction *> &patterns,
                        cal::GlslPrecision precision) {
    std::string glsl;
    for (size_t k = 0; k < patterns.size(); ++k)
        glsl += patterns[k]->Glsl("pat" + std::to_string(k), precision);
    glsl += "vec3 PatternRGB(int k) {\n";
    for (size_t k = 0; k < patterns.size(); ++k)
        glsl += "    if (k == " + std::to_string(k) + ") return vec3(pat" + std::to_string(k) +
                "());\n";
    return glsl + "    return vec3(1);\n}\n";
}

// The run's macros: its sizes and the features its scene needs (its options are in the
// parameters buffer, so that runs differing only in them share one compiled shader).
std::string Macros(const PackedScene &packed, const ContribOptions &options,
                   const EngineOptions &engine) {
    std::string src;
    const auto define = [&](const char *name, const std::string &value) {
        src += std::string("#define ") + name + " " + value + "\n";
    };
    define("DEEP_N", std::to_string(kGpuDeepN));
    define("DEEP_LEVELS", std::to_string(kGpuDeepLevels));
    define("MIX_STACK", std::to_string(kGpuMixStack));
    define("LOCAL_SIZE", std::to_string(kGpuLocalSize));
    define("STACK_SIZE", std::to_string(kGpuStackSize));
    define("ACCUM_T", engine.accumulators == GpuAccum::kDouble ? "double" : "float");
    if (engine.accumulators == GpuAccum::kPair) define("DAYFLUX_ACCUM_PAIR", "1");
    define("cal_real", engine.gpu_double_cal ? "double" : "float");
    if (engine.gpu_ray_log > 0) define("DAYFLUX_RAY_LOG", "1");
    if (engine.gpu_engine == GpuEngine::kPaths) define("DAYFLUX_PATHS", "1");
    if (options.ambient_subsamples > 1) define("DAYFLUX_ASUB", "1");
    if (packed.bsdf) define("DAYFLUX_BSDF", "1");
    if (packed.aperture) define("DAYFLUX_APERTURE", "1");
    if (packed.dielectric) define("DAYFLUX_DIELECTRIC", "1");
    if (packed.mirror_images) define("DAYFLUX_MIRROR_IMAGES", "1");
    if (packed.local_sources) define("DAYFLUX_LOCAL_SOURCES", "1");
    if (packed.inside) define("DAYFLUX_INSIDE", "1");
    return src;
}

// The includer for the core's files, embedded at build time (shaders/embedded.h).
std::string IncludedFile(const std::string &name) {
    for (const EmbeddedFile &f : kShaderIncludes)
        if (name == f.name) return f.text;
    CHECK(false);  // contrib.comp includes only the embedded files
    return "";
}

// SPIR-V cached on disk by the source's hash (and the embedded files'), so that a second run
// does not compile again.
fs::path CachePath(const std::string &source) {
    size_t key = std::hash<std::string>{}(source);
    for (const EmbeddedFile &f : kShaderIncludes)
        key = key * 1000003u ^ std::hash<std::string>{}(f.text);
    char name[32];
    std::snprintf(name, sizeof name, "contrib-%016zx.spv", key);
    if (const char *x = std::getenv("XDG_CACHE_HOME"); x && *x)
        return fs::path(x) / "dayflux" / name;
    if (const char *h = std::getenv("HOME"); h && *h)
        return fs::path(h) / ".cache" / "dayflux" / name;
    return {};
}

std::vector<uint32_t> ReadSpirv(const fs::path &path) {
    std::ifstream in(path, std::ios::binary);
    std::vector<uint32_t> spirv;
    uint32_t word;
    while (in.read(reinterpret_cast<char *>(&word), sizeof word)) spirv.push_back(word);
    if (spirv.size() > 5 && spirv[0] == 0x07230203u) return spirv;  // SPIR-V magic
    return {};
}

// Best effort: a read-only home only costs the next run a compile. A temporary of its own,
// renamed into place: readers never see a partial file.
void WriteSpirv(const fs::path &path, const std::vector<uint32_t> &spirv) {
    std::error_code ec;
    fs::create_directories(path.parent_path(), ec);
    const fs::path temp = path.string() + ".tmp" + std::to_string(getpid()) + "-" +
                          std::to_string(std::random_device{}());
    std::ofstream out(temp, std::ios::binary);
    out.write(reinterpret_cast<const char *>(spirv.data()),
              static_cast<std::streamsize>(spirv.size() * sizeof(uint32_t)));
    out.close();
    if (out) fs::rename(temp, path, ec);
    if (ec) fs::remove(temp, ec);
}

}  // namespace

bool MakeContribShader(const PackedScene &packed, const ContribOptions &options,
                       const std::vector<TrackedModifier> &tracked, const MakeContext &make_context,
                       const EngineOptions &engine, ContribShader *shader, std::string *why) {
    const cal::GlslPrecision precision =
        engine.gpu_double_cal ? cal::GlslPrecision::kDouble : cal::GlslPrecision::kFloat;
    std::string bins, patterns;
    try {
        bins = BinGlsl(tracked, make_context, precision, &shader->bin_function);
    } catch (const UserError &e) {
        *why = std::string("a bin expression GLSL cannot express: ") + e.what();
        return false;
    }
    try {
        patterns = PatternGlsl(packed.patterns, precision);
    } catch (const UserError &e) {
        *why = std::string("a pattern GLSL cannot express: ") + e.what();
        return false;
    }
    shader->source = Macros(packed, options, engine) +
                     "#include \"raytrace/vulkan/shaders/common.h\"\n" + bins + patterns +
                     kShaderContrib;
    return true;
}

std::vector<uint32_t> CompileSliceSumShader(GpuAccum accumulators) {
    CHECK(accumulators != GpuAccum::kFloat);
    const bool pairs = accumulators == GpuAccum::kPair;
    const std::string type = pairs ? "float" : "double";
    // Entry j of ray `ray`'s record, summed over its slices: doubles as the host adds them (0 +
    // the first slice, then the others); pairs (contrib.comp's AddToEntry) with TwoSum, the lost
    // parts and the slices' own second floats summed beside, in the slices' order.
    const std::string sum = pairs ? R"glsl(
    precise float sum = 0.0, lost = 0.0;
    for (uint k = 0u; k < slices; ++k) {
        uint at = 2u * ((ray * slices + k) * record + j);
        precise float v = accum[at], s = sum + v, b = s - sum;
        lost += ((sum - (s - b)) + (v - b)) + accum[at + 1u];
        sum = s;
    }
    sums[2u * i] = sum;
    sums[2u * i + 1u] = lost;
)glsl"
                                  : R"glsl(
    precise double sum = 0.0;
    for (uint k = 0u; k < slices; ++k) sum += accum[(ray * slices + k) * record + j];
    sums[i] = sum;
)glsl";
    const std::string source =
        "#version 460\n#include \"raytrace/vulkan/shaders/common.h\"\nlayout(local_size_x = " +
        std::to_string(kSliceSumLocalSize) + ") in;\n" +
        "layout(std430, set = 0, binding = kBindingAccum) readonly buffer Accum { " + type +
        " accum[]; };\n" +
        "layout(std430, set = 0, binding = kBindingTasks) readonly buffer Tasks { GpuTasks tasks; "
        "};\n" +
        "layout(std430, set = 0, binding = kBindingSliceSums) buffer Sums { " + type +
        " sums[]; };\n" + R"glsl(
void main() {
    uint i = gl_GlobalInvocationID.x +
             gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x;
    uint record = 3u * uint(tasks.ncols), slices = uint(tasks.slices);
    uint rays = uint(tasks.count) / slices;
    if (i >= rays * record) return;
    uint ray = i / record, j = i - ray * record;)glsl" +
        sum + "}\n";
    return vk::GpuDevice::CompileGlsl(source, "slice_sum.comp", IncludedFile);
}

std::vector<uint32_t> CompileContribShader(const ContribShader &shader, const ShaderTarget &target,
                                           bool replay) {
    // ([[dont_unroll]] keeps the BSDF's small loops, so its code is not copied.)
    const std::string source =
        std::string("#version 460\n#extension GL_EXT_control_flow_attributes : enable\n") +
        // SignedZeroInfNanPreserve (4461, capability 4466) for 32-bit floats: a bin of inf - inf
        // is NaN, reported and ignored, as calcomp's, not folded to 0
        (target.inf_nan ? "#extension GL_EXT_spirv_intrinsics : require\n"
                          "spirv_execution_mode(extensions = [\"SPV_KHR_float_controls\"], "
                          "capabilities = [4466], 4461, 32);\n"
                        : "") +
        (replay ? "#define DAYFLUX_REPLAY 1\n" : "") +
        (target.ray_queries ? "#extension GL_EXT_ray_query : require\n"
                            : "#define DAYFLUX_BVH 1\n") +
        (target.scratch ? "#define DAYFLUX_SCRATCH 1\n"
                        : "#define MAXN " + std::to_string(kGpuMaxRows) + "\n") +
        shader.source;
    // (the cache's key: the source, and the optimiser's level where it is not the default)
    const int level = static_cast<int>(target.optimization);
    const fs::path cache = CachePath(level == 0 ? source : source + "// O" + std::to_string(level));
    if (!cache.empty())
        if (std::vector<uint32_t> spirv = ReadSpirv(cache); !spirv.empty()) return spirv;
    std::vector<uint32_t> spirv =
        vk::GpuDevice::CompileGlsl(source, "contrib.comp", IncludedFile, target.optimization);
    if (!cache.empty()) WriteSpirv(cache, spirv);
    return spirv;
}

}  // namespace dayflux
