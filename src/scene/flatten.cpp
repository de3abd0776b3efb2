#include "scene/flatten.h"

#include <algorithm>
#include <cmath>

#include "scene/meshes.h"
#include "scene/octree.h"
#include "util/raypath.h"

namespace dayflux {

namespace {

constexpr double kFtiny = 1e-6;  // RADIANCE's FTINY

Vec3 Point(const Transform &t, const double *p) {
    Vec3 out;
    t.Apply(p, out.data());
    return out;
}

Vec3 Direction(const Transform &t, const double *d) {
    Vec3 out;
    t.ApplyDirection(d, out.data());
    return out;
}

// An instance's or mesh's transform words (xform's options).
Transform InstanceTransform(const Primitive &p) {
    Transform xf;
    for (size_t i = 1; i < p.sargs.size(); ++i)
        if (!ApplyTransformOption(p.sargs, &i, p.loc, p.type + " '" + p.name + "'", &xf))
            ErrorExit(&p.loc, p.type + " '" + p.name + "': unsupported transform option '" +
                                  p.sargs[i] + "'");
    return xf;
}

class Flattener {
  public:
    explicit Flattener(FlatScene *out) : out_(out) {}

    void Add(int first, int last, const Transform &outer, int depth) {
        for (int i = first; i < last; ++i) {
            const Primitive p = out_->scene.objects[i];  // copy: instances append to the scene
            const Transform xf = p.xf.Then(outer);
            const std::string &t = p.type;
            if (t == "polygon") {
                Polygon(p, xf, i);
            } else if (t == "sphere" || t == "bubble") {
                AnalyticShape s{AnalyticShape::kSphere, t == "bubble"};
                s.p0 = Point(xf, &p.fargs[0]);
                s.r0 = p.fargs[3] * xf.scale;
                s.object = i;
                if (SphereRadius(p, &s)) out_->shapes.push_back(s);
            } else if (t == "cone" || t == "cup" || t == "cylinder" || t == "tube") {
                const bool cyl = t == "cylinder" || t == "tube";
                AnalyticShape s{cyl ? AnalyticShape::kCylinder : AnalyticShape::kCone,
                                t == "cup" || t == "tube"};
                s.p0 = Point(xf, &p.fargs[0]);
                s.p1 = Point(xf, &p.fargs[3]);
                s.r0 = p.fargs[6] * xf.scale;
                s.r1 = (cyl ? p.fargs[6] : p.fargs[7]) * xf.scale;
                s.object = i;
                if (ConeRadii(p, &s)) out_->shapes.push_back(s);
            } else if (t == "ring") {
                AnalyticShape s{AnalyticShape::kRing};
                s.p0 = Point(xf, &p.fargs[0]);
                s.p1 = Direction(xf, &p.fargs[3]);
                s.r0 = p.fargs[6] * xf.scale;
                s.r1 = p.fargs[7] * xf.scale;
                s.object = i;
                if (ConeRadii(p, &s)) out_->shapes.push_back(s);
            } else if (t == "source") {
                AnalyticShape s{AnalyticShape::kSource};
                s.p0 = Direction(xf, &p.fargs[0]);
                s.r0 = p.fargs[3];
                s.object = i;
                out_->shapes.push_back(s);
            } else if (t == "instance") {
                if (depth > 8) ErrorExit(&p.loc, "instances nested too deep");
                const std::string path = FindOnRaypath(p.sargs[0]);
                const int before = static_cast<int>(out_->scene.objects.size());
                ReadOctree(path, &out_->scene);
                Add(before, static_cast<int>(out_->scene.objects.size()),
                    InstanceTransform(p).Then(xf), depth + 1);
            } else if (t == "mesh") {
                const Transform mxf = InstanceTransform(p).Then(xf);
                const bool flip = mxf.Mirrors();
                for (const MeshTriangle &mt : ReadMesh(FindOnRaypath(p.sargs[0]), &out_->scene)) {
                    const uint32_t base = static_cast<uint32_t>(out_->vertices.size());
                    for (const Vec3 &v : mt.v) out_->vertices.push_back(Point(mxf, v.data()));
                    if (flip)
                        out_->triangles.push_back({base, base + 2, base + 1});
                    else
                        out_->triangles.push_back({base, base + 1, base + 2});
                    out_->triangle_object.push_back(i);
                    out_->triangle_material.push_back(mt.material);
                }
            }
        }
    }

  private:
    // o_sphere(): a negative radius turns a sphere into a bubble (and back), with a warning; a
    // zero one is an error.
    static bool SphereRadius(const Primitive &p, AnalyticShape *s) {
        if (s->r0 < -kFtiny) {
            Warning(&p.loc, p.type + " '" + p.name + "': negative radius");
            s->inward = !s->inward;
            s->r0 = -s->r0;
        } else if (!(s->r0 > kFtiny)) {
            ErrorExit(&p.loc, p.type + " '" + p.name + "': zero radius");
        }
        return true;
    }

    // getcone(), as oconv meets it: negative radii turn a cone into a cup (a cylinder into a
    // tube) with a warning; radii that cancel, a ring's negative or equal ones, a cylinder's zero
    // one and an axis (a ring's normal) of no length leave the object out, with a warning; a
    // cone of equal radii is a cylinder. False: left out.
    static bool ConeRadii(const Primitive &p, AnalyticShape *s) {
        const bool ring = s->kind == AnalyticShape::kRing;
        const auto illegal = [&](const char *why) {
            Warning(&p.loc, p.type + " '" + p.name + "': " + why + " (left out)");
            return false;
        };
        if (s->kind == AnalyticShape::kCylinder) {
            if (s->r0 < -kFtiny) {
                Warning(&p.loc, p.type + " '" + p.name + "': negative radius");
                s->inward = !s->inward;
                s->r0 = s->r1 = -s->r0;
            } else if (!(s->r0 > kFtiny)) {
                return illegal("illegal radii");
            }
        } else {
            const auto sign = [](double r) { return r < -kFtiny ? -1 : r > kFtiny ? 1 : 0; };
            const int sign0 = sign(s->r0), sign1 = sign(s->r1);
            if (sign0 + sign1 == 0) return illegal("illegal radii");
            if (sign0 < 0 || sign1 < 0) {
                if (ring) return illegal("illegal radii");
                Warning(&p.loc, p.type + " '" + p.name + "': negative radii");
                s->inward = !s->inward;
            }
            s->r0 *= sign0;
            s->r1 *= sign1;
            if (ring && s->r0 > s->r1) std::swap(s->r0, s->r1);  // inner, then outer
            if (std::fabs(s->r1 - s->r0) <= kFtiny) {
                if (ring) return illegal("illegal radii");
                s->kind = AnalyticShape::kCylinder;
                s->r1 = s->r0;
            }
        }
        double axis2 = 0;  // a ring's normal, the others' ends apart
        for (int k = 0; k < 3; ++k) {
            const double a = ring ? s->p1[k] : s->p1[k] - s->p0[k];
            axis2 += a * a;
        }
        if (!(axis2 > 0)) return illegal("unknown orientation");
        return true;
    }

    void Polygon(const Primitive &p, const Transform &xf, int object) {
        const size_t n = p.fargs.size() / 3;
        std::vector<Vec3> v(n);
        for (size_t k = 0; k < n; ++k) v[k] = Point(xf, &p.fargs[3 * k]);
        // A mirroring transform turns the polygon over; xform reverses its vertices to keep the
        // side the normal points to.
        if (xf.Mirrors()) std::reverse(v.begin(), v.end());
        const auto tris = TriangulatePolygon(v);
        if (tris.empty()) return;
        const uint32_t base = static_cast<uint32_t>(out_->vertices.size());
        out_->vertices.insert(out_->vertices.end(), v.begin(), v.end());
        if (out_->polygon_vertices.size() <= static_cast<size_t>(object))
            out_->polygon_vertices.resize(object + 1);
        out_->polygon_vertices[object] = {base, static_cast<uint32_t>(v.size())};
        for (const auto &t : tris) {
            out_->triangles.push_back({base + t[0], base + t[1], base + t[2]});
            out_->triangle_object.push_back(object);
            out_->triangle_material.push_back(-1);
        }
    }

    FlatScene *out_;
};

}  // namespace

FlatScene Flatten(Scene scene) {
    FlatScene flat;
    flat.scene = std::move(scene);
    flat.top_level_objects = static_cast<int>(flat.scene.objects.size());
    Flattener f(&flat);
    f.Add(0, flat.top_level_objects, Transform{}, 0);
    flat.polygon_vertices.resize(flat.scene.objects.size());
    return flat;
}

}  // namespace dayflux
