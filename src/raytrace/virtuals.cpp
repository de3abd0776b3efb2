#include "raytrace/virtuals.h"

#include <cmath>
#include <functional>

#include "util/errors.h"

namespace dayflux {

namespace {

double Dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// The mirror image of a point (offset: the plane's) or of a direction (offset 0).
void Mirror(const MirrorRelay &m, const double in[3], double offset, double out[3]) {
    const double d = 2. * (Dot(m.normal, in) - offset);
    for (int k = 0; k < 3; ++k) out[k] = in[k] - d * m.normal[k];
}

// mir_proj(): a source is imaged only if some of it lies in front of the mirror. Its extreme
// point is judged against the plane's offset for local sources and 0 for distant ones, also
// per half-size vector (RADIANCE's comparison, kept as it is).
bool InFront(const Source &s, const MirrorRelay &m) {
    const bool distant = s.shape == Source::kDistant;
    const double offs = distant ? 0. : m.offset;
    double corr = 1.;
    if (distant || (s.circular && s.shape == Source::kFlat))
        corr = 1.12837917;  // setflatss()'s square
    else if (s.circular)
        corr = 1. / 0.7236;  // sphsetsrc()'s
    double sc[3], sv[3], sw[3];
    const double *axes[3] = {distant ? s.u : s.ss[0], distant ? s.v : s.ss[1], s.ss[2]};
    if (s.shape == Source::kCylinder) {  // cylsetsrc()'s SV and SW (we turn them per sample)
        Tangents(s.axis, sw, sv);
        for (int k = 0; k < 3; ++k) sv[k] *= .8559 * s.radius, sw[k] *= .8559 * s.radius;
        axes[1] = sv;
        axes[2] = sw;
    }
    const int n = s.shape == Source::kFlat || distant ? 2 : 3;
    for (int k = 0; k < 3; ++k) sc[k] = distant ? s.dir[k] : s.loc[k];
    for (int i = 0; i < n; ++i) {
        const double sign = Dot(m.normal, axes[i]) > offs ? corr : -corr;
        for (int k = 0; k < 3; ++k) sc[k] += sign * axes[i][k];
    }
    return Dot(sc, m.normal) > offs + kTiny;
}

// getdisk() for an image of an image: the new mirror must lie on the real side of the mirror
// that made the parent, or reach across it.
bool BeyondPrevious(const Source &parent, const MirrorRelay &previous, const MirrorRelay &m) {
    const bool distant = parent.shape == Source::kDistant;
    const double rd =
        Dot(previous.normal, distant ? parent.dir : parent.loc) - (distant ? 0. : previous.offset);
    const double d = Dot(previous.normal, m.centre) - previous.offset;
    if ((d > 0) != (rd > 0)) return true;
    const double cosine = Dot(previous.normal, m.normal);
    return d * d < m.radius2 && d * d < m.radius2 * (1. - cosine * cosine);
}

}  // namespace

bool MirrorRelay::Meets(const double org[3], const double dir[3]) const {
    const double dn = Dot(dir, normal);
    if (dn == 0) return false;
    const double t = (offset - Dot(org, normal)) / dn;
    if (t <= 0) return false;
    double p[3];
    for (int k = 0; k < 3; ++k) p[k] = org[k] + t * dir[k];
    if (polygon.empty()) {
        double d2 = 0;
        for (int k = 0; k < 3; ++k) d2 += (p[k] - centre[k]) * (p[k] - centre[k]);
        return d2 >= inner2 && d2 <= radius2;
    }
    // Crossings of a ray in the plane, projected along the normal's largest axis.
    int ax = 0;
    for (int k = 1; k < 3; ++k)
        if (std::fabs(normal[k]) > std::fabs(normal[ax])) ax = k;
    const int a = (ax + 1) % 3, b = (ax + 2) % 3;
    const size_t n = polygon.size() / 3;
    bool inside = false;
    for (size_t i = 0, j = n - 1; i < n; j = i++) {
        const double xi = polygon[3 * i + a], yi = polygon[3 * i + b];
        const double xj = polygon[3 * j + a], yj = polygon[3 * j + b];
        if ((yi > p[b]) != (yj > p[b]) && p[a] < (xj - xi) * (p[b] - yi) / (yj - yi) + xi)
            inside = !inside;
    }
    return inside;
}

std::vector<MirrorRelay> AddMirrorImages(const FlatScene &scene, const SceneMaterials &table,
                                         int depth, bool warn, std::vector<Source> *sources) {
    std::vector<MirrorRelay> relays;
    if (depth <= 0) return relays;
    const auto &objs = scene.scene.objects;
    // markvirtuals(): surfaces among the scene's own objects (not those of instances) whose
    // material is a mirror.
    for (int i = 0; i < scene.top_level_objects; ++i) {
        const Primitive &p = objs[i];
        if (p.info->kind != PrimitiveKind::kSurface || table.OfObject(i).kind != Material::kMirror)
            continue;
        MirrorRelay m;
        m.object = i;
        if (p.type == "polygon") {
            const FlatScene::VertexRange range = scene.polygon_vertices[i];
            if (range.count < 3) continue;
            double area[3] = {0, 0, 0}, c[3] = {0, 0, 0};
            for (uint32_t v = 0; v < range.count; ++v) {
                const Vec3 &a = scene.vertices[range.first + v];
                const Vec3 &b = scene.vertices[range.first + (v + 1) % range.count];
                area[0] += (a[1] - b[1]) * (a[2] + b[2]);  // Newell's normal
                area[1] += (a[2] - b[2]) * (a[0] + b[0]);
                area[2] += (a[0] - b[0]) * (a[1] + b[1]);
                for (int k = 0; k < 3; ++k) c[k] += a[k] / range.count;
                m.polygon.insert(m.polygon.end(), a.begin(), a.end());
            }
            const double l = std::sqrt(Dot(area, area));
            if (l == 0) continue;
            for (int k = 0; k < 3; ++k) m.normal[k] = area[k] / l;
            m.offset = Dot(m.normal, c);  // the average plane, through the centre
            m.radius2 = 0;
            for (int k = 0; k < 3; ++k) m.centre[k] = c[k];
            for (uint32_t v = 0; v < range.count; ++v) {
                double d2 = 0;
                for (int k = 0; k < 3; ++k) {
                    const double e = scene.vertices[range.first + v][k] - m.centre[k];
                    d2 += e * e;
                }
                m.radius2 = std::max(m.radius2, d2);
            }
        } else if (p.type == "ring") {
            for (const AnalyticShape &sh : scene.shapes) {
                if (sh.object != i) continue;
                const double l = std::sqrt(Dot(sh.p1.data(), sh.p1.data()));
                for (int k = 0; k < 3; ++k) m.normal[k] = sh.p1[k] / l, m.centre[k] = sh.p0[k];
                m.offset = Dot(m.normal, m.centre);
                m.inner2 = sh.r0 * sh.r0;
                m.radius2 = sh.r1 * sh.r1;
            }
        } else {
            if (warn) Warning(&p.loc, "'" + p.name + "': secondary sources not supported");
            continue;
        }
        relays.push_back(std::move(m));
    }
    if (relays.empty()) return relays;
    // addvirtuals(): each source's images in each mirror but the one that made it, and theirs,
    // depth first, from the last real source to the first.
    const std::function<void(int, int)> add = [&](int parent_index, int left) {
        const Source parent = (*sources)[parent_index];  // a copy: the list grows
        if (left <= 0 || parent.skip) return;
        for (size_t r = 0; r < relays.size(); ++r) {
            if (parent.relay == static_cast<int>(r)) continue;
            const MirrorRelay &m = relays[r];
            if (!InFront(parent, m)) continue;
            if (parent.relay >= 0 && !BeyondPrevious(parent, relays[parent.relay], m)) continue;
            Source image = parent;
            image.object = m.object;
            image.relay = static_cast<int>(r);
            image.next = parent_index;
            image.weak = false;  // an illum lets rays aimed at an image pass
            const double *aim = parent.relay >= 0 ? parent.spot_aim
                                                  : table.OfObject(parent.emitter).spot_aim.data();
            Mirror(m, aim, 0, image.spot_aim);
            if (parent.shape == Source::kDistant) {
                Mirror(m, parent.dir, 0, image.dir);
                Mirror(m, parent.u, 0, image.u);
                Mirror(m, parent.v, 0, image.v);
            } else {
                Mirror(m, parent.loc, m.offset, image.loc);
                Mirror(m, parent.norm, 0, image.norm);
                Mirror(m, parent.axis, 0, image.axis);
                for (int i = 0; i < 3; ++i) Mirror(m, parent.ss[i], 0, image.ss[i]);
            }
            sources->push_back(image);
            add(static_cast<int>(sources->size()) - 1, left - 1);
        }
    };
    for (size_t i = sources->size(); i-- > 0;) add(static_cast<int>(i), depth);
    return relays;
}

}  // namespace dayflux
