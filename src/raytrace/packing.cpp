#include "raytrace/packing.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <map>
#include <tuple>

#include "raytrace/analytic.h"
#include "raytrace/klems.h"
#include "raytrace/virtuals.h"
#include "util/errors.h"

namespace dayflux {

// The std430 layouts the shader sees: vec4s, vec3s each followed by a 4-byte scalar, and 4-byte
// scalars.
static_assert(sizeof(core::PackedTriangle) == 32 && sizeof(core::PackedSurface) == 64);
static_assert(sizeof(core::PackedSource) == 144 && sizeof(core::PackedShape) == 48);
static_assert(sizeof(core::PackedBvhNode) == 64 && offsetof(core::PackedSurface, kind) == 32);
static_assert(offsetof(core::PackedBvhChild, ref) == 12 &&
              offsetof(core::PackedBvhChild, hi) == 16);
static_assert(sizeof(core::PackedBvhEntry) == 48 && offsetof(core::PackedBvhEntry, edge2) == 32);

namespace {

core::vec4 Vec4(double x, double y, double z, double w = 0) {
    return core::vec4(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z),
                      static_cast<float>(w));
}

// A triangle of the flat scene: its first vertex, its edges from it and their cross product
// (the normal by the winding, twice the area long).
struct TriangleEdges {
    const Vec3 *a;
    double u[3], w[3], n[3];
    double CrossLength() const { return std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]); }
};
TriangleEdges EdgesOf(const FlatScene &scene, size_t i) {
    const auto &t = scene.triangles[i];
    const Vec3 &a = scene.vertices[t[0]], &b = scene.vertices[t[1]], &c = scene.vertices[t[2]];
    TriangleEdges e{&a,
                    {b[0] - a[0], b[1] - a[1], b[2] - a[2]},
                    {c[0] - a[0], c[1] - a[1], c[2] - a[2]},
                    {0, 0, 0}};
    e.n[0] = e.u[1] * e.w[2] - e.u[2] * e.w[1];
    e.n[1] = e.u[2] * e.w[0] - e.u[0] * e.w[2];
    e.n[2] = e.u[0] * e.w[1] - e.u[1] * e.w[0];
    return e;
}

// The core's material kinds (tables.h).
int PackedKind(Material::Kind kind) {
    switch (kind) {
        case Material::kBlack:
            return core::kMatBlack;
        case Material::kDiffuse:
            return core::kMatDiffuse;
        case Material::kGlass:
            return core::kMatGlass;
        case Material::kMirror:
            return core::kMatMirror;
        case Material::kGlow:
            return core::kMatGlow;
        case Material::kLight:
            return core::kMatLight;
        case Material::kMix:
            return core::kMatMix;
        case Material::kBsdf:
            return core::kMatBsdf;
        case Material::kDielectric:
            return core::kMatDielectric;
        case Material::kIllum:
            return core::kMatIllum;
        case Material::kAntimatter:
            return core::kMatAntimatter;
    }
    CHECK(false);
    return core::kMatBlack;
}

// A BSDF's thickness and up vector, when they do not depend on the ray (false otherwise).
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

// A BSDF material's data: its scattering, then its own header fields (the frame, constant or as
// patterns, and the diffuse colours its real arguments add).
int PackKlems(const BsdfInfo &b, int thickness_pattern, int up_pattern, std::vector<float> *out) {
    using namespace core;
    const int at = PackKlemsData(*b.klems, out);
    std::vector<float> &v = *out;
    double thickness, up[3];
    ConstantBsdfFrame(b, &thickness, up);
    v[at + kKlemsThickness] = static_cast<float>(thickness);
    for (int i = 0; i < 3; ++i) v[at + kKlemsUp + i] = static_cast<float>(up[i]);
    for (int i = 0; i < 3; ++i) {
        v[at + kKlemsFrontReflection + i] = static_cast<float>(b.front_reflection[i]);
        v[at + kKlemsBackReflection + i] = static_cast<float>(b.back_reflection[i]);
        v[at + kKlemsTransmission + i] = static_cast<float>(b.transmission[i]);
    }
    v[at + kKlemsThicknessPattern] = static_cast<float>(thickness_pattern);
    v[at + kKlemsUpPattern] = static_cast<float>(up_pattern);
    if (v.size() >= (size_t(1) << 24))
        ErrorExit("BSDF '" + b.name + "': its data is too large for float offsets");
    return at;
}

// How deep mixfuncs nest in m: the core shades a mixfunc's sides through a stack of those
// waiting, as deep as this (a mirror's substitute and an illum's alternate count in their places).
int MixNesting(const Material &m) {
    if (m.kind == Material::kMix) {
        int deepest = 0;
        for (int side = 0; side < 2; ++side)
            if (!m.mix->is_void[side])
                deepest = std::max(deepest, MixNesting(side ? m.mix->back : m.mix->fore));
        return 1 + deepest;
    }
    const bool stands_in = (m.kind == Material::kMirror && m.mirror_alternate) ||
                           m.kind == Material::kIllum || m.kind == Material::kAntimatter;
    return stands_in && m.alternate ? MixNesting(*m.alternate) : 0;
}

// Packs the tables one at a time, remembering what it has packed.
class Packer {
  public:
    Packer(const FlatScene &scene, const SceneMaterials &table, double source_jitter,
           PackedScene *out)
        : scene_(scene), table_(table), source_jitter_(source_jitter), p_(*out) {}

    int Pattern(const PatternFunction *f) {
        if (!f) return -1;
        auto it = std::find(p_.patterns.begin(), p_.patterns.end(), f);
        if (it != p_.patterns.end()) return static_cast<int>(it - p_.patterns.begin());
        p_.patterns.push_back(f);
        return static_cast<int>(p_.patterns.size()) - 1;
    }

    int Klems(const BsdfInfo &b) {
        auto [it, added] = klems_of_.emplace(&b, 0);
        if (added) {
            double thick, up[3];
            const bool constant = ConstantBsdfFrame(b, &thick, up);
            it->second = PackKlems(b, constant ? -1 : Pattern(b.thickness.get()),
                                   constant ? -1 : Pattern(b.up.get()), &p_.klems);
        }
        return it->second;
    }

    // One entry per (material, tracked modifier, antimatter bit of the modifier) the surfaces
    // use.
    int Surface(const Material &m, int k, uint64_t clip) {
        auto [it, added] =
            surface_of_.emplace(std::make_tuple(&m, k, clip), int(p_.surfaces.size()));
        if (!added) return it->second;
        const int at = it->second;
        p_.surfaces.emplace_back();  // its place, before a mixfunc's sides take theirs
        core::PackedSurface s{};
        s.fore = s.back = -1;
        s.color = Vec4(m.color[0], m.color[1], m.color[2], m.rindex);
        s.params = Vec4(
            m.spec, m.trans, m.tspec,
            (m.metal ? core::kSurfaceMetal : 0) | (m.transparent ? core::kSurfaceTransparent : 0));
        s.kind = PackedKind(m.kind);
        s.tracked = k;
        s.alpha2 = static_cast<float>(m.alpha2);
        s.pattern = Pattern(m.pattern);
        s.clip = static_cast<uint32_t>(clip);
        s.counter = table_.InsideCounterOfClipMask(clip);
        switch (m.kind) {
            case Material::kAntimatter:  // (read by tables.h's Antimatter*)
                s.fore = static_cast<int>(m.clip_mask);
                s.pattern = static_cast<int>(m.inside_counters);
                if (m.alternate) {
                    p_.inside = true;
                    s.back = Surface(*m.alternate, -1, 0);
                }
                break;
            case Material::kDielectric:
                p_.dielectric = true;
                // An absorbing medium's extinction is left out of contributions (RADIANCE's
                // raycontrib() says the same).
                if ((m.pattern || std::min({m.color[0], m.color[1], m.color[2]}) < 1) &&
                    !warned_media_) {
                    Warning("ray contribution calculation does not support participating media");
                    warned_media_ = true;
                }
                break;
            case Material::kBsdf:
                p_.bsdf = true;
                s.fore = Klems(*m.bsdf);
                if (m.bsdf->proxy) s.params.w = core::kSurfaceTransparent;
                // (RADIANCE's T_TRANSP: -i passes through it, as through a proxy)
                if (m.bsdf->aperture) {
                    p_.aperture = true;
                    s.params.w = core::kSurfaceTransparent | core::kSurfaceAperture;
                }
                break;
            case Material::kLight:
            case Material::kIllum:
                s.params = Vec4(m.spot_aim[0], m.spot_aim[1], m.spot_aim[2], m.spot_flen);
                s.alpha2 = static_cast<float>(m.spot_size);
                if (m.kind == Material::kIllum && m.alternate)
                    s.fore = Surface(*m.alternate, -1, 0);
                break;
            case Material::kMirror:
                if (m.mirror_alternate) {
                    s.params.w = core::kSurfaceMirrorAlternate;
                    if (m.alternate) s.fore = Surface(*m.alternate, -1, 0);
                }
                break;
            case Material::kMix:
                s.pattern = Pattern(m.mix->coef.get());
                if (!m.mix->is_void[0]) s.fore = Surface(m.mix->fore, -1, 0);
                if (!m.mix->is_void[1]) s.back = Surface(m.mix->back, -1, 0);
                break;
            default:
                break;
        }
        p_.surfaces[at] = s;
        return at;
    }

    void Centre() {
        double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
        for (const Vec3 &v : scene_.vertices)
            for (int k = 0; k < 3; ++k)
                lo[k] = std::min(lo[k], v[k]), hi[k] = std::max(hi[k], v[k]);
        const double origin[3] = {0, 0, 0};
        for (const AnalyticShape &sh : scene_.shapes) {
            if (sh.kind == AnalyticShape::kSource) continue;
            double a[3], b[3];
            ShapeBounds(sh, origin, a, b);
            for (int k = 0; k < 3; ++k)
                lo[k] = std::min(lo[k], a[k]), hi[k] = std::max(hi[k], b[k]);
        }
        if (lo[0] <= hi[0])
            for (int k = 0; k < 3; ++k) {
                p_.centre[k] = .5 * (lo[k] + hi[k]);
                p_.extent = std::max(p_.extent, hi[k] - lo[k]);
            }
    }

    void Triangles() {
        p_.triangles.reserve(scene_.triangles.size());
        for (size_t i = 0; i < scene_.triangles.size(); ++i) {
            const int object = scene_.triangle_object[i];
            const int mat = scene_.triangle_material[i];
            const Material &m = mat >= 0 ? table_.OfMeshMaterial(mat) : table_.OfObject(object);
            const int k =
                mat >= 0 ? table_.TrackedOfMeshMaterial(mat) : table_.TrackedOfObject(object);
            const TriangleEdges e = EdgesOf(scene_, i);
            const double *n = e.n, len = e.CrossLength();
            core::PackedTriangle pt{};
            pt.normal = len > 0 ? Vec4(n[0] / len, n[1] / len, n[2] / len) : Vec4(0, 0, 1);
            const uint64_t clip =
                mat >= 0 ? table_.ClipMaskOfMeshMaterial(mat) : table_.ClipMaskOfObject(object);
            pt.surface = Surface(m, k, clip);
            NoteMixNesting(m, object);
            pt.object = object;
            pt.mesh = mat >= 0 ? 1 : 0;
            // (RADIANCE shades a mesh's triangle as a face where the mesh's modifier is void
            // and the triangle's is not)
            const Primitive &o = scene_.scene.objects[object];
            pt.planar = o.type == "polygon" || (mat >= 0 && o.modifier < 0) ? 1 : 0;
            p_.triangles.push_back(pt);
        }
    }

    void Shapes() {
        const double *c = p_.centre;
        for (const AnalyticShape &sh : scene_.shapes) {
            if (sh.kind == AnalyticShape::kSource) {
                p_.shape_of.push_back(-1);
                continue;
            }
            core::PackedShape g{};
            g.p0 = Vec4(sh.p0[0] - c[0], sh.p0[1] - c[1], sh.p0[2] - c[2], sh.r0);
            g.p1 = sh.kind == AnalyticShape::kRing
                       ? Vec4(sh.p1[0], sh.p1[1], sh.p1[2], sh.r1)
                       : Vec4(sh.p1[0] - c[0], sh.p1[1] - c[1], sh.p1[2] - c[2], sh.r1);
            g.kind = CoreShapeKind(sh.kind);
            g.inward = sh.inward ? 1 : 0;
            g.surface = Surface(table_.OfObject(sh.object), table_.TrackedOfObject(sh.object),
                                table_.ClipMaskOfObject(sh.object));
            NoteMixNesting(table_.OfObject(sh.object), sh.object);
            g.object = sh.object;
            p_.shape_of.push_back(static_cast<int>(p_.shapes.size()));
            p_.flat_shape.push_back(static_cast<int>(&sh - scene_.shapes.data()));
            p_.shapes.push_back(g);
        }
    }

    // The receivers -asub samples (tables.h): the triangles of glow surfaces that count for a
    // modifier, clipped by no antimatter, where no analytic shape has the same surface (a hit
    // on it must be weighed as the samples are: only triangles are sampled) and no mesh does
    // (a sample counts on the object it picked, and a mesh's faces are one object: one face
    // could stand for another).
    void Receivers(bool sampled) {
        p_.receivers.assign(1, Vec4(0, 0, 0, 0));  // the header, even where none
        if (!sampled) return;
        std::vector<char> unsampled(p_.surfaces.size(), 0);
        for (const core::PackedShape &g : p_.shapes) unsampled[g.surface] = 1;
        for (size_t i = 0; i < p_.triangles.size(); ++i)  // (with its own materials or not)
            if (scene_.scene.objects[scene_.triangle_object[i]].type == "mesh")
                unsampled[p_.triangles[i].surface] = 1;
        const auto receives = [&](int s) {
            const core::PackedSurface &m = p_.surfaces[s];
            return m.kind == core::kMatGlow && m.tracked >= 0 && m.clip == 0 && !unsampled[s];
        };
        const double *c = p_.centre;
        double area = 0;
        int count = 0;
        for (size_t i = 0; i < scene_.triangles.size(); ++i) {
            if (!receives(p_.triangles[i].surface)) continue;
            const TriangleEdges e = EdgesOf(scene_, i);
            const double half = 0.5 * e.CrossLength();
            if (!(half > 0)) continue;                     // degenerate: never met
            if (scene_.triangle_object[i] >= (1 << 24)) {  // beyond float's integers: none
                p_.receivers.assign(1, Vec4(0, 0, 0, 0));
                return;
            }
            area += half;
            ++count;
            const Vec3 &a = *e.a;
            p_.receivers.push_back(Vec4(a[0] - c[0], a[1] - c[1], a[2] - c[2], area));
            p_.receivers.push_back(Vec4(e.u[0], e.u[1], e.u[2], scene_.triangle_object[i]));
            p_.receivers.push_back(Vec4(e.w[0], e.w[1], e.w[2]));
        }
        if (count == 0) return;
        p_.receivers[0] = Vec4(area, count, 0, 0);
        for (core::PackedSurface &m : p_.surfaces)
            if (receives(static_cast<int>(&m - p_.surfaces.data())))
                m.params.w =
                    static_cast<float>(static_cast<int>(m.params.w) | core::kSurfaceSampled);
    }

    // Sources, then their images in mirrors, and the mirrors: relay r's vec4s at 3r are
    // (normal, offset), (centre, radius squared), (first vertex, vertices, inner radius squared
    // of a ring); all relays' vertices follow.
    void Sources(int direct_relays) {
        std::vector<Source> sources = table_.Sources();
        const size_t own = sources.size();
        const std::vector<MirrorRelay> relays =
            AddMirrorImages(scene_, table_, direct_relays, true, &sources);
        p_.mirror_images = sources.size() > own;
        const double *c = p_.centre;
        for (const MirrorRelay &r : relays) {
            p_.relays.push_back(
                Vec4(r.normal[0], r.normal[1], r.normal[2],
                     r.offset - (r.normal[0] * c[0] + r.normal[1] * c[1] + r.normal[2] * c[2])));
            p_.relays.push_back(
                Vec4(r.centre[0] - c[0], r.centre[1] - c[1], r.centre[2] - c[2], r.radius2));
            p_.relays.push_back(Vec4(0, static_cast<double>(r.polygon.size() / 3), r.inner2));
        }
        for (size_t k = 0; k < relays.size(); ++k) {
            p_.relays[3 * k + 2].x = static_cast<float>(p_.relays.size());
            const std::vector<double> &v = relays[k].polygon;
            for (size_t i = 0; i + 2 < v.size(); i += 3)
                p_.relays.push_back(Vec4(v[i] - c[0], v[i + 1] - c[1], v[i + 2] - c[2]));
        }
        for (const Source &s : sources) p_.sources.push_back(PackSource(s));
        for (const core::PackedSource &s : p_.sources) p_.ndirect += s.colour.w > 0.5f ? 0 : 1;
    }

  private:
    void NoteMixNesting(const Material &m, int object) {
        if (m.kind != Material::kMix && !m.alternate) return;
        const int depth = MixNesting(m);
        if (depth <= p_.mix_depth) return;
        p_.mix_depth = depth;
        p_.mix_deepest = scene_.scene.objects[object].name;
    }

    core::PackedSource PackSource(const Source &s) {
        const Material &m = table_.OfObject(s.emitter);
        const double *c = p_.centre;
        core::PackedSource g{};
        g.dir = Vec4(s.dir[0], s.dir[1], s.dir[2], s.solid_angle);
        g.colour = Vec4(s.colour[0], s.colour[1], s.colour[2], s.skip ? 1 : 0);
        g.u = Vec4(s.u[0], s.u[1], s.u[2]);
        g.v = Vec4(s.v[0], s.v[1], s.v[2]);
        if (s.shape != Source::kDistant) {
            p_.local_sources = true;
            g.dir = Vec4(s.loc[0] - c[0], s.loc[1] - c[1], s.loc[2] - c[2], s.area);
            const bool cyl = s.shape == Source::kCylinder;
            g.u = Vec4(s.ss[0][0], s.ss[0][1], s.ss[0][2],
                       cyl                          ? core::kSourceCylinder
                       : s.shape == Source::kSphere ? core::kSourceSphere
                                                    : core::kSourceFlat);
            g.v = Vec4(s.ss[1][0], s.ss[1][1], s.ss[1][2],
                       (s.circular ? core::kSourceCircular : 0) |
                           (s.turned ? core::kSourceTurned : 0) | (s.weak ? core::kSourceWeak : 0));
            g.w = Vec4(s.ss[2][0], s.ss[2][1], s.ss[2][2], s.radius);
            const double *n = cyl ? s.axis : s.norm;
            g.norm = Vec4(n[0], n[1], n[2], m.spot_size);
            const double *aim = s.relay >= 0 ? s.spot_aim : m.spot_aim.data();
            g.spot = Vec4(aim[0], aim[1], aim[2], m.spot_flen);
        } else {
            if (s.weak) g.v.w = core::kSourceWeak;
            // An image's spread: nextssamp() moves a sample at most dj (1.13 dj with the disc's
            // trim) along each half side, so 1.2 dj (|u| + |v|) bounds the angle it turns.
            const double spread =
                1.2 * source_jitter_ *
                    (std::sqrt(s.u[0] * s.u[0] + s.u[1] * s.u[1] + s.u[2] * s.u[2]) +
                     std::sqrt(s.v[0] * s.v[0] + s.v[1] * s.v[1] + s.v[2] * s.v[2])) +
                1e-6;
            // (-2: wider than a right angle, no cone)
            g.w = spread < M_PI / 2 ? Vec4(std::cos(spread), std::sin(spread), 0) : Vec4(-2, 0, 0);
        }
        g.object = s.object;
        g.tracked = table_.TrackedOfObject(s.emitter);
        g.kind = PackedKind(m.kind);
        g.pattern = Pattern(m.pattern);
        g.relay = s.relay;
        g.next = s.next;
        return g;
    }

    const FlatScene &scene_;
    const SceneMaterials &table_;
    const double source_jitter_;  // -dj
    PackedScene &p_;
    std::map<const BsdfInfo *, int> klems_of_;
    std::map<std::tuple<const Material *, int, uint64_t>, int> surface_of_;
    bool warned_media_ = false;
};

}  // namespace

int PackKlemsData(const KlemsScattering &k, std::vector<float> *out) {
    using namespace core;
    std::vector<float> &v = *out;
    const int at = static_cast<int>(v.size());
    v.resize(v.size() + kKlemsHeader, 0.f);
    const double lambertian[4] = {k.ReflectionLambertian(true), k.ReflectionLambertian(false),
                                  k.TransmissionLambertian(true), k.TransmissionLambertian(false)};
    for (int i = 0; i < 4; ++i) v[at + kKlemsLambertian + i] = static_cast<float>(lambertian[i]);
    v[at + kKlemsThicknessPattern] = v[at + kKlemsUpPattern] = -1.f;
    const KlemsScattering::Part *parts[4] = {&k.rf(), &k.rb(), &k.tf(), &k.tb()};
    for (int pi = 0; pi < 4; ++pi) {
        const KlemsScattering::Part &p = *parts[pi];
        v[at + kKlemsParts + pi] = p.present() ? static_cast<float>(v.size()) : -1.f;
        if (!p.present()) continue;
        const size_t h = v.size();
        v.resize(v.size() + kPartHeader, 0.f);
        v[h + kPartInFront] = p.in_front, v[h + kPartOutFront] = p.out_front;
        v[h + kPartMaxHemi] = static_cast<float>(p.data.max_hemi);
        double min_psa = M_PI;  // get_extrema()'s minProjSA: the smallest patch of either basis
        for (const double o : p.out_table.ohm) min_psa = std::min(min_psa, o);
        for (const double o : p.in_table.ohm) min_psa = std::min(min_psa, o);
        v[h + kPartMinProjSA] = static_cast<float>(min_psa);
        v[h + kPartInSize] = static_cast<float>(p.data.in.Size());
        v[h + kPartOutSize] = static_cast<float>(p.data.out.Size());
        v[h + kPartInRings] = static_cast<float>(p.in_table.nphis.size());
        v[h + kPartOutRings] = static_cast<float>(p.out_table.nphis.size());
        const auto table = [&](const KlemsScattering::BasisTable &t, int slot) {
            v[h + slot + kBasisCosines] = static_cast<float>(v.size());
            for (double c : t.cos_bounds) v.push_back(static_cast<float>(c));
            v[h + slot + kBasisAzimuths] = static_cast<float>(v.size());
            for (int n : t.nphis) v.push_back(static_cast<float>(n));
            v[h + slot + kBasisFirst] = static_cast<float>(v.size());
            for (int f : t.first) v.push_back(static_cast<float>(f));
            v[h + slot + kBasisSolidAngles] = static_cast<float>(v.size());
            for (double o : t.ohm) v.push_back(static_cast<float>(o));
        };
        table(p.in_table, kPartInBasis);
        table(p.out_table, kPartOutBasis);
        v[h + kPartValues] = static_cast<float>(v.size());
        v.insert(v.end(), p.data.values.begin(), p.data.values.end());
        v[h + kPartCdf] = static_cast<float>(v.size());
        for (const auto &row : p.cdf)
            for (double c : row) v.push_back(static_cast<float>(c));
        v[h + kPartReverseCdf] = static_cast<float>(v.size());
        for (const auto &row : p.reverse_cdf)
            for (double c : row) v.push_back(static_cast<float>(c));
    }
    return at;
}

PackedScene PackScene(const FlatScene &scene, const SceneMaterials &table,
                      const std::vector<TrackedModifier> &tracked, const ContribOptions &options) {
    PackedScene p;
    for (const TrackedModifier &t : tracked) {
        p.columns = std::max(p.columns, t.first_column + t.nbins);
        p.tracked.push_back(core::ivec4(t.first_column, t.nbins, 0, 0));
    }
    Packer packer(scene, table, options.source_jitter, &p);
    packer.Centre();
    packer.Triangles();
    packer.Shapes();
    packer.Sources(options.direct_relays);
    packer.Receivers(options.ambient_subsamples > 1);
    return p;
}

std::string UnsupportedOnGpu(const PackedScene &packed, const ContribOptions &options) {
    if (options.specular_jitter > kGpuMaxSpecularSamples)  // each waits on the ray stack
        return "-ss above 16 (more specular samples than the GPU's ray stack holds)";
    if (packed.mix_depth > kGpuMixStack - 1)
        return "a mixfunc nested more than " + std::to_string(kGpuMixStack - 1) + " deep (" +
               packed.mix_deepest + ") is traced on the CPU only";
    return "";
}

}  // namespace dayflux
