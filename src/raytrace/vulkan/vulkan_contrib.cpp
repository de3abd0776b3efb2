#include "raytrace/vulkan/vulkan_contrib.h"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <random>
#include <thread>

#include "cal/glsl.h"
#include "raytrace/analytic.h"
#include "raytrace/bvh.h"
#include "raytrace/materials.h"
#include "raytrace/virtuals.h"
#include "raytrace/vulkan/raytracing.h"
#include "shaders/common.h"
#include "shaders/embedded.h"
#include "util/errors.h"

namespace dayflux {

namespace fs = std::filesystem;

namespace {

// The std430 layouts the shader sees (common.h): vec4s and 4-byte scalars, doubles 8-aligned.
static_assert(sizeof(gpu::GpuTriangle) == 32 && sizeof(gpu::GpuSurface) == 64);
static_assert(sizeof(gpu::GpuSource) == 144 && sizeof(gpu::GpuTasks) == 128);
static_assert(offsetof(gpu::GpuTasks, lw) == 64 && offsetof(gpu::GpuTasks, centre_x) == 96);

constexpr int kLocalSize = 64;
constexpr int kStackSize = 64;
// Bytes of results per dispatch: within every device's maxStorageBufferRange (lavapipe: 128 MiB).
constexpr size_t kAccumBudget = size_t(64) << 20;
constexpr uint32_t kMaxTasksPerRun = 65535u * kLocalSize;
// Rows of the first hemisphere with RADIANCE's collision rule (-ad up to 65536); beyond, none.
constexpr int kMaxRows = 256;

gpu::vec4 Vec4(double x, double y, double z, double w = 0) {
    return gpu::vec4{static_cast<float>(x), static_cast<float>(y), static_cast<float>(z),
                     static_cast<float>(w)};
}

template <class T>
std::vector<uint8_t> Bytes(const std::vector<T> &v) {
    std::vector<uint8_t> b(std::max<size_t>(v.size() * sizeof(T), 16), 0);
    if (!v.empty()) std::memcpy(b.data(), v.data(), v.size() * sizeof(T));
    return b;
}

// SPIR-V cached on disk by the source's hash, so a second run does not compile again.
std::vector<uint32_t> CompileCached(const std::string &source) {
    const size_t key = std::hash<std::string>{}(source);
    char name[32];
    std::snprintf(name, sizeof name, "contrib-%016zx.spv", key);
    fs::path dir;
    if (const char *x = std::getenv("XDG_CACHE_HOME"); x && *x)
        dir = fs::path(x) / "dayflux";
    else if (const char *h = std::getenv("HOME"); h && *h)
        dir = fs::path(h) / ".cache" / "dayflux";
    if (!dir.empty()) {
        std::ifstream in(dir / name, std::ios::binary);
        std::vector<uint32_t> spirv;
        uint32_t word;
        while (in.read(reinterpret_cast<char *>(&word), sizeof word)) spirv.push_back(word);
        if (spirv.size() > 5 && spirv[0] == 0x07230203u) return spirv;  // SPIR-V magic
    }
    std::vector<uint32_t> spirv = vk::GpuDevice::CompileGlsl(source, "contrib.comp");
    if (!dir.empty()) {  // best effort: a read-only home only costs the next run a compile
        std::error_code ec;
        fs::create_directories(dir, ec);
        // A temporary of its own, renamed into place: readers never see a partial file.
        const fs::path temp = dir / (std::string(name) + ".tmp" + std::to_string(getpid()) + "-" +
                                     std::to_string(std::random_device{}()));
        std::ofstream out(temp, std::ios::binary);
        out.write(reinterpret_cast<const char *>(spirv.data()),
                  static_cast<std::streamsize>(spirv.size() * sizeof(uint32_t)));
        out.close();
        if (out) fs::rename(temp, dir / name, ec);
    }
    return spirv;
}

}  // namespace

// One device's share: the device, its compiled shader (ray queries or our BVH) and its copy of
// the scene's tables (GpuDevice::Resident handles; bvh_nodes and bvh_prims only without ray
// queries).
struct DeviceState {
    std::unique_ptr<vk::GpuDevice> device;
    std::vector<uint32_t> spirv;
    int positions = -1, indices = -1, triangles = -1, surfaces = -1, sources = -1, shapes = -1;
    int bvh_nodes = -1, bvh_prims = -1, klems = -1, relays = -1, tracked = -1;
    uint64_t dropped = 0;  // stack items lost in its last Trace
};

struct VulkanContribIntegrator::Impl {
    std::vector<DeviceState> devices;
    std::string names;  // the devices' names, " + " between them
    ContribOptions o;
    double centre[3] = {0, 0, 0};
    double extent = 0;
    size_t accum_bytes() const { return float_accumulators ? sizeof(float) : sizeof(double); }
    int nsources = 0, ndirect = 0;
    bool float_accumulators = false;
    mutable uint64_t dropped = 0;  // stack items lost, over the run (warned about once)
    int columns = 0;
    int max_rows = 1;  // divisions along one side of the first hemisphere (slices are rows)
    // Traces rays on one device, adding to their records.
    void TraceOn(DeviceState &dev, const double *rays, size_t n, uint64_t first_index, int replica,
                 double *records) const;
};

VulkanContribIntegrator::VulkanContribIntegrator(std::unique_ptr<Impl> impl, int columns)
    : impl_(std::move(impl)), columns_(columns) {}
VulkanContribIntegrator::~VulkanContribIntegrator() = default;
const std::string &VulkanContribIntegrator::DeviceName() const { return impl_->names; }

namespace {

// The shader's material kinds (common.h) for those it traces; the rest never reach it.
int GpuKind(Material::Kind kind) {
    switch (kind) {
        case Material::kBlack:
            return gpu::kMatBlack;
        case Material::kDiffuse:
            return gpu::kMatDiffuse;
        case Material::kGlass:
            return gpu::kMatGlass;
        case Material::kMirror:
            return gpu::kMatMirror;
        case Material::kGlow:
            return gpu::kMatGlow;
        case Material::kLight:
            return gpu::kMatLight;
        case Material::kMix:
            return gpu::kMatMix;
        case Material::kBsdf:
            return gpu::kMatBsdf;
        case Material::kDielectric:
            return gpu::kMatDielectric;
        case Material::kIllum:
            return gpu::kMatIllum;
        case Material::kAntimatter:
            return gpu::kMatAntimatter;
        default:
            CHECK(false);  // refused by Create's unsupported()
            return gpu::kMatBlack;
    }
}

// A BSDF material's data as the shader reads it (contrib.comp, DAYFLUX_BSDF), appended to out;
// returns its offset. Header: thickness, up vector, the Lambertian totals (rf rb tf tb), the
// material's own diffuse colours (front, back reflection, transmission), the four parts'
// offsets (-1: none). Part: in_front, out_front, max_hemi, nin, nout, in and out ring counts,
// then the offsets of the in basis's ring cosines, azimuth counts, first patches and projected
// solid angles, the same for the out basis, the values, and the two cumulative distributions.
int PackKlems(const BsdfInfo &b, double thickness, const double up[3], std::vector<float> *out) {
    std::vector<float> &v = *out;
    const int at = static_cast<int>(v.size());
    const KlemsScattering &k = *b.klems;
    v.push_back(static_cast<float>(thickness));
    for (int i = 0; i < 3; ++i) v.push_back(static_cast<float>(up[i]));
    for (double l : {k.ReflectionLambertian(true), k.ReflectionLambertian(false),
                     k.TransmissionLambertian(true), k.TransmissionLambertian(false)})
        v.push_back(static_cast<float>(l));
    for (const RGB *c : {&b.front_reflection, &b.back_reflection, &b.transmission})
        for (double x : *c) v.push_back(static_cast<float>(x));
    const size_t parts_at = v.size();
    v.resize(v.size() + 4, -1.f);
    const KlemsScattering::Part *parts[4] = {&k.rf(), &k.rb(), &k.tf(), &k.tb()};
    for (int pi = 0; pi < 4; ++pi) {
        const KlemsScattering::Part &p = *parts[pi];
        if (!p.present()) continue;
        v[parts_at + pi] = static_cast<float>(v.size());
        const size_t h = v.size();
        v.resize(v.size() + 18, 0.f);
        const int nin = p.data.in.Size(), nout = p.data.out.Size();
        v[h + 0] = p.in_front, v[h + 1] = p.out_front;
        v[h + 2] = static_cast<float>(p.data.max_hemi);
        v[h + 3] = static_cast<float>(nin), v[h + 4] = static_cast<float>(nout);
        v[h + 5] = static_cast<float>(p.in_table.nphis.size());
        v[h + 6] = static_cast<float>(p.out_table.nphis.size());
        const auto table = [&](const KlemsScattering::BasisTable &t, size_t slot) {
            v[h + slot] = static_cast<float>(v.size());
            for (double c : t.cos_bounds) v.push_back(static_cast<float>(c));
            v[h + slot + 1] = static_cast<float>(v.size());
            for (int n : t.nphis) v.push_back(static_cast<float>(n));
            v[h + slot + 2] = static_cast<float>(v.size());
            for (int f : t.first) v.push_back(static_cast<float>(f));
            v[h + slot + 3] = static_cast<float>(v.size());
            for (double o : t.ohm) v.push_back(static_cast<float>(o));
        };
        table(p.in_table, 7);
        table(p.out_table, 11);
        v[h + 15] = static_cast<float>(v.size());
        v.insert(v.end(), p.data.values.begin(), p.data.values.end());
        v[h + 16] = static_cast<float>(v.size());
        for (const auto &row : p.cdf)
            for (double c : row) v.push_back(static_cast<float>(c));
        v[h + 17] = static_cast<float>(v.size());
        for (const auto &row : p.reverse_cdf)
            for (double c : row) v.push_back(static_cast<float>(c));
    }
    if (v.size() >= (size_t(1) << 24)) ErrorExit("BSDF data too large for the GPU's float offsets");
    return at;
}

// A BSDF's thickness and up vector, when they do not depend on the ray (false otherwise): the
// GPU takes them as constants.
bool ConstantBsdfFrame(const BsdfInfo &b, double *thickness, double up[3]) {
    std::array<double, 27> a{}, c{};
    for (size_t i = 0; i < a.size(); ++i) a[i] = 0.1 * (i + 1), c[i] = -0.37 * (i + 2);
    double ta[3], tc[3], ua[3], uc[3];
    b.thickness->Evaluate(a, ta);
    b.thickness->Evaluate(c, tc);
    b.up->Evaluate(a, ua);
    b.up->Evaluate(c, uc);
    *thickness = ta[0];
    for (int k = 0; k < 3; ++k) up[k] = ua[k];
    return ta[0] == tc[0] && ua[0] == uc[0] && ua[1] == uc[1] && ua[2] == uc[2];
}

}  // namespace

std::unique_ptr<VulkanContribIntegrator> VulkanContribIntegrator::Create(
    const FlatScene &scene, const ContribOptions &options,
    const std::vector<TrackedModifier> &tracked,
    const std::function<std::unique_ptr<cal::Context>(int)> &make_context, bool float_accumulators,
    std::string *why) {
    if (options.specular_jitter > 16) {  // each sample waits on the ray stack
        *why = "-ss above 16 (more specular samples than the GPU's ray stack holds)";
        return nullptr;
    }
    SceneMaterials table(scene, tracked);
    // What a material needs that the shader lacks ("" if nothing).
    std::function<std::string(const Material &, int)> unsupported_in;
    const auto unsupported = [&](const Material &m) { return unsupported_in(m, 0); };
    const auto basic = [&](const Material &m) -> std::string {
        if (m.kind == Material::kAntimatter && m.alternate)
            return "antimatter with a material for its inside";
        if (m.kind == Material::kBsdf) {
            double thick, up[3];
            if (!ConstantBsdfFrame(*m.bsdf, &thick, up)) return "BSDF with a ray-dependent frame";
        }
        return "";
    };
    // mixes: how many mixfuncs m is a side of. A mirror's substitute and an illum's alternate
    // are judged in their places.
    unsupported_in = [&](const Material &m, int mixes) -> std::string {
        if (m.kind == Material::kMirror && m.mirror_alternate && m.alternate)
            return unsupported_in(*m.alternate, mixes);
        if (m.kind == Material::kIllum && m.alternate) {
            if (m.alternate->kind == Material::kIllum) return "illum with an illum behind it";
            return unsupported_in(*m.alternate, mixes);
        }
        if (m.kind != Material::kMix) return basic(m);
        if (mixes + 2 > gpu::kMixStack)
            return "a mixfunc nested more than " + std::to_string(gpu::kMixStack - 1) + " deep";
        for (int side = 0; side < 2; ++side) {
            if (m.mix->is_void[side]) continue;
            const Material &s = side ? m.mix->back : m.mix->fore;
            if (std::string u = unsupported_in(s, mixes + 1); !u.empty()) return u;
        }
        return "";
    };

    auto impl = std::make_unique<Impl>();
    impl->o = options;
    impl->float_accumulators = float_accumulators;
    int columns = 0;
    for (const TrackedModifier &t : tracked) columns = std::max(columns, t.first_column + t.nbins);
    impl->columns = columns;

    // Patterns (brightfunc, colorfunc): each compiled to GLSL once, by index.
    std::vector<const PatternFunction *> patterns;
    const auto pattern_of = [&](const PatternFunction *p) {
        if (!p) return -1;
        auto it = std::find(patterns.begin(), patterns.end(), p);
        if (it != patterns.end()) return static_cast<int>(it - patterns.begin());
        patterns.push_back(p);
        return static_cast<int>(patterns.size()) - 1;
    };
    const auto pattern_index = [&](const Material &m) { return pattern_of(m.pattern); };
    // The BSDF materials' data, each once.
    std::vector<float> klems;
    std::map<const BsdfInfo *, int> klems_of;
    const auto klems_index = [&](const BsdfInfo &b) {
        auto [it, added] = klems_of.emplace(&b, 0);
        if (added) {
            double thick, up[3];
            ConstantBsdfFrame(b, &thick, up);
            it->second = PackKlems(b, thick, up, &klems);
        }
        return it->second;
    };
    // Surfaces: one entry per (material, tracked modifier, antimatter bit of the modifier) the
    // triangles use. The shader's clip sets are 32 bits where the CPU's are 64.
    bool dielectric = false, warned_media = false;
    std::vector<gpu::GpuSurface> surfaces;
    std::map<std::tuple<const Material *, int, uint64_t>, int> surface_of;
    const auto clip_bits = [&](uint64_t mask) {
        if (mask >> 32) {
            *why = "antimatter clipping more than 32 modifiers";
            return false;
        }
        return true;
    };
    const auto surface = [&](auto &&self, const Material &m, int k, uint64_t clip) -> int {
        auto [it, added] = surface_of.emplace(std::make_tuple(&m, k, clip), int(surfaces.size()));
        if (added) {
            const int at = it->second;
            surfaces.emplace_back();  // its place, before a mixfunc's sides take theirs
            gpu::GpuSurface s{};
            s.fore = s.back = -1;
            s.color = Vec4(m.color[0], m.color[1], m.color[2], m.rindex);
            s.params = Vec4(m.spec, m.trans, m.tspec,
                            (m.metal ? gpu::kSurfaceMetal : 0) |
                                (m.transparent ? gpu::kSurfaceTransparent : 0));
            s.kind = GpuKind(m.kind);
            s.tracked = k;
            s.alpha2 = static_cast<float>(m.alpha2);
            s.pattern = pattern_index(m);
            s.clip = static_cast<uint32_t>(clip);
            if (m.kind == Material::kAntimatter) s.fore = static_cast<int>(m.clip_mask);
            if (m.kind == Material::kDielectric) {
                dielectric = true;
                // As the CPU integrator's: an absorbing medium's extinction is left out of
                // contributions (RADIANCE's raycontrib() says the same).
                if ((m.pattern || std::min({m.color[0], m.color[1], m.color[2]}) < 1) &&
                    !warned_media) {
                    Warning("ray contribution calculation does not support participating media");
                    warned_media = true;
                }
            }
            if (m.kind == Material::kBsdf) {
                s.fore = klems_index(*m.bsdf);
                if (m.bsdf->proxy) s.params.w = gpu::kSurfaceTransparent;
            }
            if (m.kind == Material::kLight || m.kind == Material::kIllum) {
                s.params = Vec4(m.spot_aim[0], m.spot_aim[1], m.spot_aim[2], m.spot_flen);
                s.alpha2 = static_cast<float>(m.spot_size);
            }
            if (m.kind == Material::kIllum && m.alternate) s.fore = self(self, *m.alternate, -1, 0);
            if (m.kind == Material::kMirror && m.mirror_alternate) {
                s.params.w = gpu::kSurfaceMirrorAlternate;
                if (m.alternate) s.fore = self(self, *m.alternate, -1, 0);
            }
            if (m.kind == Material::kMix) {
                s.pattern = pattern_of(m.mix->coef.get());
                if (!m.mix->is_void[0]) s.fore = self(self, m.mix->fore, -1, 0);
                if (!m.mix->is_void[1]) s.back = self(self, m.mix->back, -1, 0);
            }
            surfaces[at] = s;
        }
        return it->second;
    };
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    for (const Vec3 &v : scene.vertices)
        for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], v[k]), hi[k] = std::max(hi[k], v[k]);
    const double origin[3] = {0, 0, 0};
    for (const AnalyticShape &sh : scene.shapes) {
        if (sh.kind == AnalyticShape::kSource) continue;
        double a[3], b[3];
        ShapeBounds(sh, origin, a, b);
        for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], a[k]), hi[k] = std::max(hi[k], b[k]);
    }
    double extent = 0;
    if (lo[0] <= hi[0])
        for (int k = 0; k < 3; ++k) {
            impl->centre[k] = .5 * (lo[k] + hi[k]);
            extent = std::max(extent, hi[k] - lo[k]);
        }
    std::vector<float> pos;
    pos.reserve(scene.vertices.size() * 3);
    for (const Vec3 &v : scene.vertices)
        for (int k = 0; k < 3; ++k) pos.push_back(static_cast<float>(v[k] - impl->centre[k]));
    std::vector<uint32_t> idx;
    std::vector<gpu::GpuTriangle> tris;
    idx.reserve(scene.triangles.size() * 3);
    tris.reserve(scene.triangles.size());
    for (size_t i = 0; i < scene.triangles.size(); ++i) {
        const auto &t = scene.triangles[i];
        idx.insert(idx.end(), t.begin(), t.end());
        const int object = scene.triangle_object[i];
        const int mat = scene.triangle_material[i];
        const Material &m = mat >= 0 ? table.OfMeshMaterial(mat) : table.OfObject(object);
        const int k = mat >= 0 ? table.TrackedOfMeshMaterial(mat) : table.TrackedOfObject(object);
        if (std::string u = unsupported(m); !u.empty()) {
            *why = u + " (" + scene.scene.objects[object].name + ") is traced on the CPU only";
            return nullptr;
        }
        const Vec3 &a = scene.vertices[t[0]], &b = scene.vertices[t[1]], &c = scene.vertices[t[2]];
        const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]},
                     w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2],
                       u[0] * w[1] - u[1] * w[0]};
        const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        gpu::GpuTriangle gt{};
        gt.normal = len > 0 ? Vec4(n[0] / len, n[1] / len, n[2] / len) : Vec4(0, 0, 1);
        const uint64_t clip =
            mat >= 0 ? table.ClipMaskOfMeshMaterial(mat) : table.ClipMaskOfObject(object);
        if (!clip_bits(clip | m.clip_mask)) return nullptr;
        gt.surface = surface(surface, m, k, clip);
        gt.object = object;
        gt.mesh = scene.triangle_material[i] >= 0 ? 1 : 0;
        tris.push_back(gt);
    }
    // Analytic surfaces: procedural boxes the shader intersects itself.
    std::vector<gpu::GpuShape> shapes;
    std::vector<float> boxes;
    for (const AnalyticShape &sh : scene.shapes) {
        if (sh.kind == AnalyticShape::kSource) continue;
        const Material &m = table.OfObject(sh.object);
        if (std::string u = unsupported(m); !u.empty()) {
            *why = u + " (" + scene.scene.objects[sh.object].name + ") is traced on the CPU only";
            return nullptr;
        }
        gpu::GpuShape g{};
        const double *c = impl->centre;
        g.p0 = Vec4(sh.p0[0] - c[0], sh.p0[1] - c[1], sh.p0[2] - c[2], sh.r0);
        g.p1 = sh.kind == AnalyticShape::kRing
                   ? Vec4(sh.p1[0], sh.p1[1], sh.p1[2], sh.r1)
                   : Vec4(sh.p1[0] - c[0], sh.p1[1] - c[1], sh.p1[2] - c[2], sh.r1);
        g.kind = sh.kind == AnalyticShape::kSphere     ? gpu::kShapeSphere
                 : sh.kind == AnalyticShape::kCone     ? gpu::kShapeCone
                 : sh.kind == AnalyticShape::kCylinder ? gpu::kShapeCylinder
                                                       : gpu::kShapeRing;
        g.inward = sh.inward ? 1 : 0;
        const uint64_t clip = table.ClipMaskOfObject(sh.object);
        if (!clip_bits(clip | m.clip_mask)) return nullptr;
        g.surface = surface(surface, m, table.TrackedOfObject(sh.object), clip);
        g.object = sh.object;
        shapes.push_back(g);
        double a[3], b[3];
        ShapeBounds(sh, impl->centre, a, b);
        for (int k = 0; k < 3; ++k) boxes.push_back(static_cast<float>(a[k]));
        for (int k = 0; k < 3; ++k) boxes.push_back(static_cast<float>(b[k]));
    }
    // Sources, then their images in mirrors (as the CPU integrator has them), and the mirrors.
    std::vector<Source> sources = table.Sources();
    const std::vector<MirrorRelay> relays =
        AddMirrorImages(scene, table, options.direct_relays, false, &sources);
    std::vector<gpu::vec4> relay_data;
    for (const MirrorRelay &r : relays) {
        const double *c = impl->centre;
        relay_data.push_back(
            Vec4(r.normal[0], r.normal[1], r.normal[2],
                 r.offset - (r.normal[0] * c[0] + r.normal[1] * c[1] + r.normal[2] * c[2])));
        relay_data.push_back(
            Vec4(r.centre[0] - c[0], r.centre[1] - c[1], r.centre[2] - c[2], r.radius2));
        relay_data.push_back(Vec4(0, static_cast<double>(r.polygon.size() / 3), r.inner2));
    }
    for (size_t k = 0; k < relays.size(); ++k) {
        relay_data[3 * k + 2].x = static_cast<float>(relay_data.size());
        const std::vector<double> &p = relays[k].polygon;
        for (size_t v = 0; v + 2 < p.size(); v += 3)
            relay_data.push_back(Vec4(p[v] - impl->centre[0], p[v + 1] - impl->centre[1],
                                      p[v + 2] - impl->centre[2]));
    }
    std::vector<gpu::GpuSource> srcs;
    for (const Source &s : sources) {
        const Material &m = table.OfObject(s.emitter);
        if (std::string u = unsupported(m); !u.empty()) {
            *why = u + " (" + scene.scene.objects[s.emitter].name + ") is traced on the CPU only";
            return nullptr;
        }
        gpu::GpuSource g{};
        g.dir = Vec4(s.dir[0], s.dir[1], s.dir[2], s.solid_angle);
        g.colour = Vec4(s.colour[0], s.colour[1], s.colour[2], s.skip ? 1 : 0);
        g.u = Vec4(s.u[0], s.u[1], s.u[2]);
        g.v = Vec4(s.v[0], s.v[1], s.v[2]);
        if (s.shape != Source::kDistant) {
            g.dir = Vec4(s.loc[0] - impl->centre[0], s.loc[1] - impl->centre[1],
                         s.loc[2] - impl->centre[2], s.area);
            const bool cyl = s.shape == Source::kCylinder;
            g.u = Vec4(s.ss[0][0], s.ss[0][1], s.ss[0][2],
                       cyl                          ? gpu::kSourceCylinder
                       : s.shape == Source::kSphere ? gpu::kSourceSphere
                                                    : gpu::kSourceFlat);
            g.v = Vec4(s.ss[1][0], s.ss[1][1], s.ss[1][2],
                       (s.circular ? gpu::kSourceCircular : 0) |
                           (s.turned ? gpu::kSourceTurned : 0) | (s.weak ? gpu::kSourceWeak : 0));
            g.w = Vec4(s.ss[2][0], s.ss[2][1], s.ss[2][2], s.radius);
            const double *n = cyl ? s.axis : s.norm;
            g.norm = Vec4(n[0], n[1], n[2], m.spot_size);
            const double *aim = s.relay >= 0 ? s.spot_aim : m.spot_aim.data();
            g.spot = Vec4(aim[0], aim[1], aim[2], m.spot_flen);
        } else if (s.weak) {
            g.v.w = gpu::kSourceWeak;
        }
        g.object = s.object;
        g.tracked = table.TrackedOfObject(s.emitter);
        g.kind = GpuKind(m.kind);
        g.pattern = pattern_index(m);
        g.relay = s.relay;
        g.next = s.next;
        srcs.push_back(g);
    }

    // The bins, compiled from calcomp to GLSL: one function per distinct expression within
    // each context (-M may name thousands of modifiers sharing one; modifiers given different
    // -p parameters have contexts of their own), each context's definitions under a prefix of
    // its own.
    struct BinContext {
        std::unique_ptr<cal::Context> cx;
        std::vector<cal::Expression> bins;
        std::vector<cal::GlslEntry> entries;
        std::map<std::string, int> bin_function;  // expression -> global bin function index
    };
    std::vector<BinContext> contexts;
    std::vector<int> context_of_tracked(tracked.size());
    int nbin_functions = 0;
    std::vector<int> bin_function_of;  // per tracked modifier
    for (size_t k = 0; k < tracked.size(); ++k) {
        const TrackedModifier &t = tracked[k];
        if (t.context_of < 0) {
            context_of_tracked[k] = static_cast<int>(contexts.size());
            contexts.push_back({make_context(static_cast<int>(k)), {}, {}, {}});
            contexts.back().bins.reserve(tracked.size());  // entries point into it
        } else {
            context_of_tracked[k] = context_of_tracked[t.context_of];
        }
        BinContext &c = contexts[context_of_tracked[k]];
        auto [it, added] = c.bin_function.emplace(t.bin_expression, nbin_functions);
        if (added) {
            c.bins.push_back(c.cx->Compile(t.bin_expression, FileLoc{"-b", 0}));
            c.entries.push_back({"cal_bin" + std::to_string(nbin_functions), &c.bins.back()});
            ++nbin_functions;
        }
        bin_function_of.push_back(it->second);
    }
    std::vector<int32_t> tracked_table;  // kBindingTracked
    for (size_t k = 0; k < tracked.size(); ++k)
        for (int v : {tracked[k].first_column, tracked[k].nbins, bin_function_of[k], 0})
            tracked_table.push_back(v);
    std::string cal_glsl;
    try {
        for (size_t g = 0; g < contexts.size(); ++g) {
            cal::GlslOptions go;
            go.prefix = g == 0 ? go.prefix : "cal_c" + std::to_string(g) + "_d";
            go.preamble = g == 0;
            cal_glsl += cal::GenerateGlsl(*contexts[g].cx, contexts[g].entries, go);
        }
    } catch (const UserError &e) {
        *why = std::string("a bin expression GLSL cannot express: ") + e.what();
        return nullptr;
    }
    std::string pattern_glsl;
    try {
        for (size_t k = 0; k < patterns.size(); ++k)
            pattern_glsl += patterns[k]->Glsl("pat" + std::to_string(k));
    } catch (const UserError &e) {
        *why = std::string("a pattern GLSL cannot express: ") + e.what();
        return nullptr;
    }
    pattern_glsl += "vec3 PatternRGB(int k) {\n";
    for (size_t k = 0; k < patterns.size(); ++k)
        pattern_glsl += "    if (k == " + std::to_string(k) + ") return vec3(pat" +
                        std::to_string(k) + "());\n";
    pattern_glsl += "    return vec3(1);\n}\n";

    // lavapipe only when asked for: on a CPU, the Embree backend is faster. Ray queries where
    // the device has them, unless DAYFLUX_GPU_TRAVERSAL says otherwise (rayquery, bvh, auto).
    const char *named = std::getenv("DAYFLUX_VULKAN_DEVICE");
    vk::Traversal traversal = vk::Traversal::kAuto;
    if (const char *t = std::getenv("DAYFLUX_GPU_TRAVERSAL"); t && *t) {
        const std::string v = t;
        if (v == "rayquery")
            traversal = vk::Traversal::kRayQuery;
        else if (v == "bvh")
            traversal = vk::Traversal::kBvh;
        else if (v != "auto")
            ErrorExit("DAYFLUX_GPU_TRAVERSAL=" + v + ": auto, rayquery or bvh");
    }
    std::vector<std::unique_ptr<vk::GpuDevice>> opened =
        vk::GpuDevice::OpenAll(why, named && *named, traversal);
    if (opened.empty()) return nullptr;

    const auto &o = options;
    impl->max_rows = std::max(1, static_cast<int>(std::sqrt(double(o.ambient_divisions)) + 1.5));
    impl->extent = extent;
    impl->nsources = static_cast<int>(srcs.size());
    for (const gpu::GpuSource &g : srcs) impl->ndirect += g.colour.w > 0.5f ? 0 : 1;
    std::string src;  // after the header, which depends on the device
    const auto define = [&](const char *name, const std::string &value) {
        src += std::string("#define ") + name + " " + value + "\n";
    };
    // The options are read from the tasks buffer (common.h), so runs that differ only in them
    // share one compiled shader.
    define("AB", "tasks.ab");
    define("AD", "tasks.ad");
    define("LW", "tasks.lw");
    define("LR", "tasks.lr");
    define("IRRADIANCE", "tasks.irradiance");
    define("FIRST_HIT", "tasks.first_hit");
    define("CONTRIBUTIONS", "tasks.contributions");
    define("NSOURCES", "tasks.nsources");
    define("DJ", "tasks.dj");
    define("SEED", "tasks.seed");
    define("TMIN", "tasks.tmin");
    define("ST", "tasks.st");
    define("SS", "tasks.ss");
    define("DS", "tasks.ds");
    define("CENTRE_X", "tasks.centre_x");
    define("CENTRE_Y", "tasks.centre_y");
    define("CENTRE_Z", "tasks.centre_z");
    define("NCOLS", "tasks.ncols");
    define("MAXN", std::to_string(kMaxRows));
    define("LOCAL_SIZE", std::to_string(kLocalSize));
    define("STACK_SIZE", std::to_string(kStackSize));
    define("ACCUM_T", float_accumulators ? "float" : "double");
    if (o.ambient_subsamples > 1) define("ASUB", std::to_string(o.ambient_subsamples));
    if (!klems.empty()) define("DAYFLUX_BSDF", "1");
    if (dielectric) define("DAYFLUX_DIELECTRIC", "1");
    if (srcs.size() > table.Sources().size()) define("DAYFLUX_MIRROR_IMAGES", "1");
    for (const gpu::GpuSource &g : srcs)
        if (static_cast<int>(g.u.w) != gpu::kSourceDistant) {
            define("DAYFLUX_LOCAL_SOURCES", "1");
            break;
        }
    src += kShaderCommon;
    src += cal_glsl;
    src += pattern_glsl;
    src += "double EvalBin(int j) {\n";
    for (int j = 0; j < nbin_functions; ++j)
        src +=
            "    if (j == " + std::to_string(j) + ") return cal_bin" + std::to_string(j) + "();\n";
    src += "    return -1.0LF;\n}\n";
    src += kShaderContrib;

    // Our BVH over the triangles (entries i >= 0) and the analytic shapes (-(i + 1)), for
    // devices without ray queries; built once.
    std::vector<uint8_t> bvh_nodes, bvh_prims;
    const auto build_bvh = [&] {
        std::vector<float> bounds;
        bounds.reserve((idx.size() / 3 + boxes.size() / 6) * 6);
        for (size_t t = 0; t + 2 < idx.size(); t += 3) {
            float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
            for (size_t c = 0; c < 3; ++c)
                for (int k = 0; k < 3; ++k) {
                    const float x = pos[3 * static_cast<size_t>(idx[t + c]) + k];
                    lo[k] = std::min(lo[k], x), hi[k] = std::max(hi[k], x);
                }
            bounds.insert(bounds.end(), lo, lo + 3);
            bounds.insert(bounds.end(), hi, hi + 3);
        }
        bounds.insert(bounds.end(), boxes.begin(), boxes.end());
        const FlatBvh bvh = BuildBvh(bounds);
        const int32_t ntri = static_cast<int32_t>(idx.size() / 3);
        std::vector<gpu::GpuBvhNode> nodes(bvh.nodes.size());
        for (size_t i = 0; i < nodes.size(); ++i) {
            const FlatBvhNode &n = bvh.nodes[i];
            nodes[i].lo = Vec4(n.lo[0], n.lo[1], n.lo[2]);
            nodes[i].hi = Vec4(n.hi[0], n.hi[1], n.hi[2]);
            nodes[i].count = n.count;
            nodes[i].index = n.index;
        }
        std::vector<int32_t> prims(bvh.prims);
        for (int32_t &p : prims)
            if (p >= ntri) p = -(p - ntri + 1);
        bvh_nodes = Bytes(nodes);
        bvh_prims = Bytes(prims);
    };
    for (std::unique_ptr<vk::GpuDevice> &device : opened) {
        DeviceState dev;
        const bool rq = device->RayQueries();
        // ([[dont_unroll]] keeps the BSDF's small loops, so its code is not copied.)
        dev.spirv = CompileCached(
            std::string("#version 460\n#extension GL_EXT_control_flow_attributes : enable\n") +
            (rq ? "#extension GL_EXT_ray_query : require\n" : "#define DAYFLUX_BVH 1\n") + src);
        const uint64_t limit = device->MaxBufferBytes();
        if (pos.size() * sizeof(float) > limit || tris.size() * sizeof(gpu::GpuTriangle) > limit ||
            idx.size() * sizeof(uint32_t) > limit) {
            *why = "the scene is too large for " + device->Name() + "'s storage buffers";
            return nullptr;
        }
        if (rq) {
            device->BuildScene(pos, idx, boxes);
        } else {
            if (bvh_nodes.empty()) build_bvh();
            if (bvh_nodes.size() > limit) {
                *why = "the scene's BVH is too large for " + device->Name() + "'s storage buffers";
                return nullptr;
            }
            dev.bvh_nodes = device->Resident(bvh_nodes);
            dev.bvh_prims = device->Resident(bvh_prims);
        }
        dev.positions = device->Resident(Bytes(pos));
        dev.indices = device->Resident(Bytes(idx));
        dev.triangles = device->Resident(Bytes(tris));
        dev.surfaces = device->Resident(Bytes(surfaces));
        dev.sources = device->Resident(Bytes(srcs));
        dev.shapes = device->Resident(Bytes(shapes));
        dev.klems = device->Resident(Bytes(klems));
        dev.relays = device->Resident(Bytes(relay_data));
        dev.tracked = device->Resident(Bytes(tracked_table));
        impl->names += (impl->names.empty() ? "" : " + ") + device->Name();
        dev.device = std::move(device);
        impl->devices.push_back(std::move(dev));
    }
    return std::unique_ptr<VulkanContribIntegrator>(
        new VulkanContribIntegrator(std::move(impl), columns));
}

// Several devices split the rays between them, each taking a contiguous share on a thread of
// its own: rays' random numbers are keyed by their index, so the records do not depend on how
// many devices there are.
void VulkanContribIntegrator::Trace(const double *rays, size_t n, uint64_t first_index, int replica,
                                    double *records) const {
    Impl &d = *impl_;
    if (n == 0) return;
    const size_t nd = d.devices.size(), record = 3 * static_cast<size_t>(d.columns);
    std::vector<std::thread> threads;
    for (size_t k = 0; k < nd; ++k) {
        const size_t lo = n * k / nd, hi = n * (k + 1) / nd;
        if (hi == lo) continue;
        const auto run = [&, k, lo, hi] {
            d.TraceOn(d.devices[k], rays + 6 * lo, hi - lo, first_index + lo, replica,
                      records + lo * record);
        };
        if (nd == 1)
            run();
        else
            threads.emplace_back(run);
    }
    for (std::thread &t : threads) t.join();
    uint64_t lost = 0;
    for (DeviceState &dev : d.devices) lost += dev.dropped, dev.dropped = 0;
    if (lost > 0 && d.dropped == 0)
        Warning("the GPU integrator's ray stack overflowed; " + std::to_string(lost) +
                " rays were dropped (results are low): use -backend embree");
    d.dropped += lost;
}

void VulkanContribIntegrator::Impl::TraceOn(DeviceState &dev, const double *rays, size_t n,
                                            uint64_t first_index, int replica,
                                            double *records) const {
    const Impl &d = *this;
    std::vector<gpu::vec4> in(2 * n);
    for (size_t i = 0; i < n; ++i) {
        const double *r = rays + 6 * i;
        const bool zero = r[3] == 0 && r[4] == 0 && r[5] == 0;
        in[2 * i] = Vec4(r[0] - d.centre[0], r[1] - d.centre[1], r[2] - d.centre[2]);
        in[2 * i + 1] = Vec4(r[3], r[4], r[5], zero ? -1 : 0);
    }
    // -I rays split their first hemisphere's rows between several tasks, enough to keep the
    // device busy; other rays are one task each.
    const size_t want_tasks = 1 << 16;
    int slices = 1;
    if (d.o.irradiance)
        slices = static_cast<int>(
            std::clamp<size_t>((want_tasks + n - 1) / n, 1, static_cast<size_t>(d.max_rows)));
    const size_t record = 3 * static_cast<size_t>(d.columns);
    const size_t total = n * static_cast<size_t>(slices);
    const size_t per_run =
        std::clamp<size_t>(kAccumBudget / (record * d.accum_bytes()), 1, kMaxTasksPerRun);
    std::vector<uint8_t> ray_bytes = Bytes(in);
    for (size_t offset = 0; offset < total; offset += per_run) {
        const size_t count = std::min(per_run, total - offset);
        gpu::GpuTasks tasks{};
        tasks.rays = static_cast<int>(n);
        tasks.slices = slices;
        tasks.first_ray = static_cast<int>(first_index);
        tasks.replica = replica;
        tasks.task_offset = static_cast<int>(offset);
        tasks.count = static_cast<int>(count);
        tasks.ab = d.o.ambient_bounces;
        tasks.ad = d.o.ambient_divisions;
        tasks.lr = d.o.limit_reflections;
        tasks.irradiance = d.o.irradiance;
        tasks.first_hit = d.o.first_hit_irradiance;
        tasks.contributions = d.o.contributions;
        tasks.nsources = d.nsources;
        tasks.ndirect = d.ndirect;
        tasks.ncols = d.columns;
        tasks.seed = static_cast<uint32_t>(d.o.seed ^ (d.o.seed >> 32));
        tasks.lw = static_cast<float>(d.o.limit_weight);
        tasks.dj = static_cast<float>(d.o.source_jitter);
        tasks.tmin = static_cast<float>(std::max(1e-6 * d.extent, 1e-9));
        tasks.st = static_cast<float>(d.o.specular_threshold);
        tasks.ss = static_cast<float>(d.o.specular_jitter);
        tasks.ds = static_cast<float>(d.o.source_size_ratio);
        tasks.centre_x = d.centre[0];
        tasks.centre_y = d.centre[1];
        tasks.centre_z = d.centre[2];
        std::vector<uint8_t> task_bytes(sizeof tasks);
        std::memcpy(task_bytes.data(), &tasks, sizeof tasks);
        std::vector<uint8_t> accum(count * record * d.accum_bytes(), 0), stats(16, 0);
        using G = vk::GpuDevice;
        std::vector<G::Binding> buffers = {G::In(&ray_bytes),         G::OnDevice(dev.positions),
                                           G::OnDevice(dev.indices),  G::OnDevice(dev.triangles),
                                           G::OnDevice(dev.surfaces), G::OnDevice(dev.sources),
                                           G::InOut(&accum),          G::In(&task_bytes),
                                           G::InOut(&stats),          G::OnDevice(dev.shapes)};
        std::vector<uint8_t> none;
        if (!dev.device->RayQueries()) {  // our BVH at binding 0, its entries after the rest
            buffers.insert(buffers.begin(), G::OnDevice(dev.bvh_nodes));
            buffers.push_back(G::OnDevice(dev.bvh_prims));
        } else {
            buffers.push_back(G::In(&none));  // binding 11 unused
        }
        buffers.push_back(G::OnDevice(dev.klems));    // kBindingKlems
        buffers.push_back(G::OnDevice(dev.relays));   // kBindingRelays
        buffers.push_back(G::OnDevice(dev.tracked));  // kBindingTracked
        dev.device->Run(dev.spirv, static_cast<uint32_t>(count), kLocalSize, buffers);
        uint32_t lost;
        std::memcpy(&lost, stats.data(), sizeof lost);
        dev.dropped += lost;
        const auto add = [&](const auto *a) {
            for (size_t t = 0; t < count; ++t) {
                double *dst = records + ((offset + t) / slices) * record;
                const auto *src = a + t * record;
                for (size_t j = 0; j < record; ++j) dst[j] += src[j];
            }
        };
        if (d.float_accumulators)
            add(reinterpret_cast<const float *>(accum.data()));
        else
            add(reinterpret_cast<const double *>(accum.data()));
    }
}

}  // namespace dayflux
