// The CPU backend: Embree 3 triangles, and RADIANCE's analytic surfaces (spheres, cones,
// cylinders, rings) as Embree user geometry intersected in double precision. Geometry is moved so
// the scene's centre is at the origin, so float precision follows the scene's size, not its
// distance from the world origin (a room 1000 km away traces as one at the origin).
#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "raytrace/analytic.h"
#include "raytrace/backend.h"
#include "raytrace/core/shapes.h"
#include "util/errors.h"

namespace dayflux {

namespace {

// The rays being traced on this thread, in double (Embree's copy is float), and the distance of
// the analytic surface hit each accepted last, so shapes are intersected and reported without
// float rounding: a point on a sphere stays on it.
// For a packet, its rays: Embree's ray id is the lane's index in rays.
struct ShapeQuery {
    const TraceRay *rays = nullptr;
    double t[8] = {};
};
thread_local ShapeQuery shape_query;

void EmbreeError(void *, RTCError code, const char *message) {
    ErrorExit(std::string("Embree error ") + std::to_string(static_cast<int>(code)) + ": " +
              (message ? message : ""));
}

class EmbreeBackend : public Backend {
  public:
    EmbreeBackend() {
        device_ = rtcNewDevice(nullptr);
        if (!device_) ErrorExit("cannot start Embree (rtcNewDevice failed)");
        rtcSetDeviceErrorFunction(device_, EmbreeError, nullptr);
    }
    ~EmbreeBackend() override {
        if (blockers_scene_) rtcReleaseScene(blockers_scene_);
        if (bare_scene_) rtcReleaseScene(bare_scene_);
        if (filtered_blockers_scene_) rtcReleaseScene(filtered_blockers_scene_);
        if (scene_) rtcReleaseScene(scene_);
        rtcReleaseDevice(device_);
    }
    std::string Name() const override { return "embree"; }

    void SetBlockers(std::vector<uint32_t> triangles) override { blockers_ = std::move(triangles); }

    void Commit(const FlatScene &flat) override {
        flat_ = &flat;
        for (size_t i = 0; i < flat.shapes.size(); ++i)
            if (flat.shapes[i].kind != AnalyticShape::kSource)
                surfaces_.push_back(static_cast<int>(i));
        double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
        for (const Vec3 &v : flat.vertices)
            for (int k = 0; k < 3; ++k)
                lo[k] = std::min(lo[k], v[k]), hi[k] = std::max(hi[k], v[k]);
        const double zero[3] = {0, 0, 0};
        for (int i : surfaces_) {
            double slo[3], shi[3];
            ShapeBounds(flat.shapes[i], zero, slo, shi);
            for (int k = 0; k < 3; ++k)
                lo[k] = std::min(lo[k], slo[k]), hi[k] = std::max(hi[k], shi[k]);
        }
        const bool empty = flat.vertices.empty() && surfaces_.empty();
        extent_ = 0;
        for (int k = 0; k < 3; ++k) {
            centre_[k] = empty ? 0 : 0.5 * (lo[k] + hi[k]);
            extent_ = std::max(extent_, empty ? 0 : hi[k] - lo[k]);
        }
        near_ = 1e-6 * extent_;
        inverse_extent_ = extent_ > 0 ? 1 / extent_ : 0;
        scene_ = NewScene(true);
        bare_scene_ = NewScene(true);
        if (!flat.triangles.empty()) {
            RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
            auto *vb = static_cast<float *>(
                rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                        3 * sizeof(float), flat.vertices.size()));
            for (size_t i = 0; i < flat.vertices.size(); ++i)
                for (int k = 0; k < 3; ++k)
                    vb[3 * i + k] = static_cast<float>(flat.vertices[i][k] - centre_[k]);
            auto *ib = static_cast<unsigned *>(
                rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                        3 * sizeof(unsigned), flat.triangles.size()));
            for (size_t i = 0; i < flat.triangles.size(); ++i)
                for (int k = 0; k < 3; ++k) ib[3 * i + k] = flat.triangles[i][k];
            normals_.reserve(flat.triangles.size());
            for (const auto &t : flat.triangles) {
                const Vec3 &a = flat.vertices[t[0]], &b = flat.vertices[t[1]],
                           &c = flat.vertices[t[2]];
                const core::real3 n =
                    glm::cross(core::real3(b[0] - a[0], b[1] - a[1], b[2] - a[2]),
                               core::real3(c[0] - a[0], c[1] - a[1], c[2] - a[2]));
                const double len = glm::length(n);
                normals_.push_back(len > 0 ? n / len : core::real3(0));
            }
            for (size_t i = 0; i < flat.triangles.size(); ++i) margins_.push_back(EdgeMargin(i));
            rtcSetGeometryUserData(g, this);
            rtcSetGeometryIntersectFilterFunction(g, TriangleFilterFunction);
            rtcSetGeometryOccludedFilterFunction(g, TriangleFilterFunction);
            rtcCommitGeometry(g);
            triangles_id_ = 0;
            rtcAttachGeometryByID(scene_, g, triangles_id_);
            rtcReleaseGeometry(g);
            RTCGeometry bare = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
            rtcSetSharedGeometryBuffer(bare, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, vb, 0,
                                       3 * sizeof(float), flat.vertices.size());
            rtcSetSharedGeometryBuffer(bare, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, ib, 0,
                                       3 * sizeof(unsigned), flat.triangles.size());
            rtcCommitGeometry(bare);
            rtcAttachGeometryByID(bare_scene_, bare, triangles_id_);
            rtcReleaseGeometry(bare);
            if (!blockers_.empty()) {
                FindPlanes();
                CommitBlockers(vb, flat.vertices.size());
            }
        }
        if (!surfaces_.empty()) {
            RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_USER);
            rtcSetGeometryUserPrimitiveCount(g, static_cast<unsigned>(surfaces_.size()));
            rtcSetGeometryUserData(g, this);
            rtcSetGeometryBoundsFunction(g, ShapeBoundsFunction, nullptr);
            rtcSetGeometryIntersectFunction(g, ShapeIntersectFunction);
            rtcSetGeometryOccludedFunction(g, ShapeOccludedFunction);
            rtcCommitGeometry(g);
            shapes_id_ = 1;
            rtcAttachGeometryByID(scene_, g, shapes_id_);
            rtcAttachGeometryByID(bare_scene_, g, shapes_id_);
            rtcReleaseGeometry(g);
        }
        rtcCommitScene(scene_);
        rtcCommitScene(bare_scene_);
    }

    // One ray alone, or several in packets of eight (rays from different points, such as the
    // lanes of the CPU estimator, still cost less together: Embree tests a node for eight rays
    // at once). Embree's filter calls cost packets all they gain, so rays go through the scene
    // without the filter, and the few that meet their own object where the filter would have
    // passed it (none of the tutorial room's 4 million) again through the filtered scene: the
    // same hits.
    void Closest(const TraceRay *rays, TraceHit *hits, size_t n) const override {
        if (n == 1) {
            ClosestAlone(bare_scene_, rays[0], &hits[0]);
            return;
        }
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        for (size_t first = 0; first < n; first += 8) {
            const int lanes = static_cast<int>(std::min<size_t>(8, n - first));
            alignas(32) RTCRayHit8 packet;
            alignas(32) int valid[8];
            for (int k = 0; k < 8; ++k) {
                valid[k] = k < lanes ? -1 : 0;
                RTCRay r;
                Fill(rays[first + std::min(k, lanes - 1)], &r);
                r.id = static_cast<unsigned>(k);
                SetLane(r, k, &packet.ray);
                packet.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
                packet.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
            }
            shape_query.rays = rays + first;
            rtcIntersect8(valid, bare_scene_, &ctx, &packet);
            for (int k = 0; k < lanes; ++k) {
                const TraceRay &ray = rays[first + k];
                if (MetItself(ray, packet.hit.geomID[k], packet.hit.primID[k],
                              packet.ray.tfar[k])) {
                    ClosestAlone(scene_, ray, &hits[first + k]);
                    shape_query.rays = rays + first;
                    continue;
                }
                FinishHit(ray, packet.ray.tfar[k], packet.hit.geomID[k], packet.hit.primID[k],
                          packet.hit.u[k], packet.hit.v[k], shape_query.t[k], &hits[first + k]);
            }
        }
    }

    void Occluded(const TraceRay *rays, bool *occluded, size_t n) const override {
        AnyHit(scene_, rays, occluded, n);
    }

    // A ray leaving a flat object (plane_of_object_) starts past where float rounding could let
    // it meet that object again, and asks the blockers without a filter (Embree's filter calls
    // cost the direct runs 10 %); others ask them filtered as in Closest. What the blockers miss
    // near a ray's start the walk still finds: they may only say less. Rays for the bare
    // blockers go eight at a time (a vertex's shadow rays toward many suns share their origin).
    void Blocked(const TraceRay *rays, bool *blocked, size_t n) const override {
        if (!blockers_scene_) {
            std::fill(blocked, blocked + n, false);
            return;
        }
        BlockerContext ctx;
        rtcInitIntersectContext(&ctx.embree);
        ctx.self = this;
        alignas(32) RTCRay8 packet;
        alignas(32) int valid[8];
        size_t lanes[8];
        int used = 0;
        auto flush = [&] {
            if (used == 0) return;
            for (int k = used; k < 8; ++k) valid[k] = 0;
            rtcOccluded8(valid, blockers_scene_, &ctx.embree, &packet);
            for (int k = 0; k < used; ++k) blocked[lanes[k]] = packet.tfar[k] < 0;
            used = 0;
        };
        for (size_t i = 0; i < n; ++i) {
            RTCRay r;
            const RTCScene scene = PrepareBlocked(rays[i], &r);
            if (!scene) {
                blocked[i] = false;
            } else if (scene == blockers_scene_ && n > 1) {
                SetLane(r, used, &packet);
                valid[used] = -1;
                lanes[used++] = i;
                if (used == 8) flush();
            } else {
                ctx.from = rays[i].from_object;
                rtcOccluded1(scene, &ctx.embree, &r);
                blocked[i] = r.tfar < 0;
            }
        }
        flush();
    }

  private:
    // An empty scene of the best build quality, robust (no ray slips between two triangles
    // sharing an edge) or not.
    RTCScene NewScene(bool robust) const {
        RTCScene scene = rtcNewScene(device_);
        if (robust) rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
        rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
        return scene;
    }

    // Ray alone through scene (bare_scene_, or scene_ where it met itself there).
    void ClosestAlone(RTCScene scene, const TraceRay &ray, TraceHit *hit) const {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        RTCRayHit rh;
        Fill(ray, &rh.ray);
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        shape_query.rays = &ray;
        rtcIntersect1(scene, &ctx, &rh);
        if (scene == bare_scene_ && MetItself(ray, rh.hit.geomID, rh.hit.primID, rh.ray.tfar)) {
            ClosestAlone(scene_, ray, hit);
            return;
        }
        FinishHit(ray, rh.ray.tfar, rh.hit.geomID, rh.hit.primID, rh.hit.u, rh.hit.v,
                  shape_query.t[0], hit);
    }

    // Whether the bare scene's hit is one the triangles' filter would have passed.
    bool MetItself(const TraceRay &ray, unsigned geom, unsigned prim, float t) const {
        return geom != RTC_INVALID_GEOMETRY_ID && geom == triangles_id_ && Skips(prim, t, ray);
    }

    // Embree's hit (geometry, primitive, float distance and barycentrics; shape_t: the double
    // distance of an analytic surface's) of ray as TraceHit.
    void FinishHit(const TraceRay &ray, float tfar, unsigned geom, unsigned prim, float hu,
                   float hv, double shape_t, TraceHit *out) const {
        TraceHit &h = *out;
        h.hit = geom != RTC_INVALID_GEOMETRY_ID;
        if (!h.hit) return;
        h.t = tfar;
        if (geom == shapes_id_) {
            h.t = shape_t;
            h.shape = surfaces_[prim];
            double p[3];
            for (int k = 0; k < 3; ++k) p[k] = ray.org[k] - centre_[k] + h.t * ray.dir[k];
            ShapeNormal(flat_->shapes[h.shape], centre_, p, h.normal);
            for (int k = 0; k < 3; ++k) h.point[k] = ray.org[k] + h.t * ray.dir[k];
            return;
        }
        h.shape = -1;
        h.triangle = prim;
        // The normal from the double-precision vertices, in the triangle's winding; the hit
        // refined in double (core/shapes.h, as the GPU refines its hits).
        const auto &t = flat_->triangles[h.triangle];
        const Vec3 &a = flat_->vertices[t[0]], &b = flat_->vertices[t[1]],
                   &c = flat_->vertices[t[2]];
        const core::real3 n = normals_[h.triangle];
        for (int k = 0; k < 3; ++k) h.normal[k] = n[k];
        const core::real3 org(ray.org[0], ray.org[1], ray.org[2]);
        const core::real3 dir(ray.dir[0], ray.dir[1], ray.dir[2]);
        const core::real3 va(a[0], a[1], a[2]);
        const bool on_plane = core::OntoPlane(org, dir, va, n, h.t);
        core::real3 p = org + h.t * dir;
        // Only a hit near an edge can lie outside in double (Embree's barycentrics are of its
        // float ray): it is moved in; the others are in by a wide margin, which grows as the ray
        // grazes the plane (an offset of the ray moves its hit by 1 / cos as far) and as the
        // ray's float error does (with its origin's distance from the centre and its length). A
        // hit the plane did not refine (behind the origin) is projected as well.
        const double cosine = std::abs(glm::dot(dir, n));
        double reach = h.t;
        for (int k = 0; k < 3; ++k) reach += std::abs(org[k] - centre_[k]);
        const double m = margins_[h.triangle] * std::max(1.0, reach * inverse_extent_);
        const double u = hu, v = hv;
        if (!on_plane || !(u * cosine > m && v * cosine > m && (1. - u - v) * cosine > m))
            p = core::ClosestPointOnTriangle(p, va, core::real3(b[0], b[1], b[2]),
                                             core::real3(c[0], c[1], c[2]));
        for (int k = 0; k < 3; ++k) h.point[k] = p[k];
    }

    // Embree's context, extended (as its documentation allows) for the blockers' filter.
    struct BlockerContext {
        RTCIntersectContext embree;
        const EmbreeBackend *self = nullptr;
        int from = -1;
    };
    // How far off its own plane float rounding may put a ray's origin (of the recentred scene's
    // extent): the origin's and the vertices' rounding, 5e-8 each, with room to spare.
    static constexpr double kSelfReach = 1e-6;

    // The blockers' structure a ray asks (the filtered one with its context's object), with the
    // ray for it; none where it runs along the plane of the flat object it leaves (the walk
    // decides those).
    RTCScene PrepareBlocked(const TraceRay &in, RTCRay *r) const {
        Fill(in, r);
        if (in.from_object < 0) return blockers_scene_;
        CHECK(static_cast<size_t>(in.from_object) < plane_of_object_.size());
        const core::real3 &plane = plane_of_object_[in.from_object];
        if (plane == core::real3(0)) return filtered_blockers_scene_;
        const double cosine =
            std::abs(glm::dot(plane, core::real3(in.dir[0], in.dir[1], in.dir[2])));
        if (cosine < 1e-9) return nullptr;
        r->tnear = std::max(r->tnear, static_cast<float>(self_reach_[in.from_object] / cosine));
        return blockers_scene_;
    }
    static void SetLane(const RTCRay &r, int k, RTCRay8 *p) {
        p->org_x[k] = r.org_x, p->org_y[k] = r.org_y, p->org_z[k] = r.org_z;
        p->dir_x[k] = r.dir_x, p->dir_y[k] = r.dir_y, p->dir_z[k] = r.dir_z;
        p->tnear[k] = r.tnear, p->tfar[k] = r.tfar;
        p->time[k] = r.time, p->mask[k] = r.mask, p->id[k] = r.id, p->flags[k] = r.flags;
    }

    // Whether anything of scene lies on each ray (to its tmax).
    void AnyHit(RTCScene scene, const TraceRay *rays, bool *hit, size_t n) const {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        for (size_t i = 0; i < n; ++i) {
            RTCRay r;
            Fill(rays[i], &r);
            shape_query.rays = &rays[i];
            rtcOccluded1(scene, &ctx, &r);
            hit[i] = r.tfar < 0;
        }
    }

    // The blockers' own structures: their triangles on the scene's vertices (Embree's buffer,
    // shared), twice: bare, and with Closest's rule for the object a ray leaves (MeetsItself: a
    // filter of their own, as their triangles are numbered apart). Not robust (10 % faster): at
    // a seam of a blocker and glass they may settle a ray either way, as the walk may.
    void CommitBlockers(const float *vertices, size_t nvertices) {
        blockers_scene_ = BlockersScene(vertices, nvertices, false);
        filtered_blockers_scene_ = BlockersScene(vertices, nvertices, true);
    }
    RTCScene BlockersScene(const float *vertices, size_t nvertices, bool filtered) const {
        RTCScene scene = NewScene(false);
        RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, vertices, 0,
                                   3 * sizeof(float), nvertices);
        auto *ib = static_cast<unsigned *>(rtcSetNewGeometryBuffer(
            g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), blockers_.size()));
        for (size_t i = 0; i < blockers_.size(); ++i) {
            CHECK(blockers_[i] < flat_->triangles.size());
            for (int k = 0; k < 3; ++k) ib[3 * i + k] = flat_->triangles[blockers_[i]][k];
        }
        if (filtered) rtcSetGeometryOccludedFilterFunction(g, BlockerFilterFunction);
        rtcCommitGeometry(g);
        rtcAttachGeometry(scene, g);
        rtcReleaseGeometry(g);
        rtcCommitScene(scene);
        return scene;
    }

    static void ShapeBoundsFunction(const RTCBoundsFunctionArguments *args) {
        const auto *self = static_cast<const EmbreeBackend *>(args->geometryUserPtr);
        double lo[3], hi[3];
        ShapeBounds(self->flat_->shapes[self->surfaces_[args->primID]], self->centre_, lo, hi);
        // Widened by a float step so that rounding cannot cut a surface off.
        RTCBounds *b = args->bounds_o;
        const double pad = 1e-6 * (self->extent_ + 1);
        b->lower_x = static_cast<float>(lo[0] - pad), b->upper_x = static_cast<float>(hi[0] + pad);
        b->lower_y = static_cast<float>(lo[1] - pad), b->upper_y = static_cast<float>(hi[1] + pad);
        b->lower_z = static_cast<float>(lo[2] - pad), b->upper_z = static_cast<float>(hi[2] + pad);
    }

    // plane_of_object_: the objects whose triangles all lie in one plane (a polygon, or a flat
    // mesh of one modifier); two parallel faces of one mesh are not one plane. Their reach
    // (self_reach_): how far off the plane Embree's float normal of their narrowest triangle
    // may let a ray meet them, kSelfReach of the extent over the sine of its smallest angle
    // (a fan of a 400-sided disc met itself 9e-6 of the extent off the plane); an object with a
    // triangle narrower than 1e-4 radians is not taken as flat.
    void FindPlanes() {
        plane_of_object_.assign(flat_->scene.objects.size(), core::real3(0));
        self_reach_.assign(plane_of_object_.size(), 0);
        std::vector<double> offset(plane_of_object_.size(), 0);
        std::vector<char> curved(plane_of_object_.size(), 0);
        const double tolerance = 1e-9 * (extent_ + 1e-30);
        for (size_t i = 0; i < flat_->triangles.size(); ++i) {
            const int object = flat_->triangle_object[i];
            CHECK(object >= 0 && static_cast<size_t>(object) < plane_of_object_.size());
            if (curved[object]) continue;
            const core::real3 n = normals_[i];
            const Vec3 &a = flat_->vertices[flat_->triangles[i][0]];
            const double d = n.x * a[0] + n.y * a[1] + n.z * a[2];
            core::real3 &plane = plane_of_object_[object];
            const double sine = SmallestSine(i);
            if (flat_->triangle_material[i] >= 0 || n == core::real3(0) || sine < 1e-4) {
                curved[object] = 1;
            } else if (plane == core::real3(0)) {
                plane = n, offset[object] = d;
            } else if (glm::length(n - plane) > 1e-9 || std::abs(d - offset[object]) > tolerance) {
                curved[object] = 1;
            }
            if (!curved[object])
                self_reach_[object] = std::max(self_reach_[object], kSelfReach * extent_ / sine);
        }
        for (size_t o = 0; o < plane_of_object_.size(); ++o)
            if (curved[o]) plane_of_object_[o] = core::real3(0);
    }

    // The sine of triangle i's smallest angle (the one opposite its shortest side).
    double SmallestSine(size_t i) const {
        const TriangleSize size = SizeOf(i);  // twice the area over the two longer sides
        const double product = size.sides[1] * size.sides[2];
        return product > 0 ? size.twice_area / product : 0;
    }

    // How far inside its triangle (in barycentric coordinates, for a ray along the normal) a hit
    // Embree reports must lie for the refined hit to be inside too: the float ray's origin and
    // direction are off the double ones by about 1e-7 of the scene's extent, which moves a
    // barycentric coordinate by that over the triangle's least height; the margin is 100 times
    // that, and 1 (never inside) for slivers.
    float EdgeMargin(size_t i) const {
        const TriangleSize size = SizeOf(i);
        const double height = size.sides[2] > 0 ? size.twice_area / size.sides[2] : 0;
        const double margin = height > 0 ? 1e-5 * (extent_ + 1e-30) / height : 1;
        return static_cast<float>(std::min(margin, 1.0));
    }

    // Triangle i's sides, shortest first, and twice its area.
    struct TriangleSize {
        double sides[3];
        double twice_area;
    };
    TriangleSize SizeOf(size_t i) const {
        const auto &t = flat_->triangles[i];
        TriangleSize size;
        for (int e = 0; e < 3; ++e) {
            const Vec3 &p = flat_->vertices[t[e]], &q = flat_->vertices[t[(e + 1) % 3]];
            size.sides[e] =
                std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
                          (p[2] - q[2]) * (p[2] - q[2]));
        }
        std::sort(size.sides, size.sides + 3);
        const Vec3 &a = flat_->vertices[t[0]], &b = flat_->vertices[t[1]],
                   &c = flat_->vertices[t[2]];
        size.twice_area =
            glm::length(glm::cross(core::real3(b[0] - a[0], b[1] - a[1], b[2] - a[2]),
                                   core::real3(c[0] - a[0], c[1] - a[1], c[2] - a[2])));
        return size;
    }

    // Lane k's ray of this thread's query (by its Embree ray id), in double, recentred.
    const TraceRay &QueryRay(const RTCRayN *ray, unsigned n, unsigned k) const {
        return shape_query.rays[RTCRayN_id(const_cast<RTCRayN *>(ray), n, k)];
    }
    void RayOf(const TraceRay &r, double org[3], double dir[3]) const {
        for (int k = 0; k < 3; ++k) org[k] = r.org[k] - centre_[k], dir[k] = r.dir[k];
    }

    // A triangle of the object the ray leaves: a polygon's never (it is planar, as RADIANCE's
    // polygons are), a mesh's not within near_ of the origin; and none the ray runs along
    // (Skips).
    static void TriangleFilterFunction(const RTCFilterFunctionNArguments *args) {
        const auto *self = static_cast<const EmbreeBackend *>(args->geometryUserPtr);
        for (unsigned k = 0; k < args->N; ++k) {
            if (!args->valid[k]) continue;
            if (self->Skips(RTCHitN_primID(args->hit, args->N, k),
                            RTCRayN_tfar(args->ray, args->N, k),
                            self->QueryRay(args->ray, args->N, k)))
                args->valid[k] = 0;
        }
    }

    // The same for the filtered blockers, whose triangles are numbered apart (the ray's object
    // comes in its context).
    static void BlockerFilterFunction(const RTCFilterFunctionNArguments *args) {
        CHECK(args->N == 1);
        if (!args->valid[0]) return;
        const auto *ctx = reinterpret_cast<const BlockerContext *>(args->context);
        if (ctx->self->MeetsItself(ctx->self->blockers_[RTCHitN_primID(args->hit, 1, 0)],
                                   RTCRayN_tfar(args->ray, 1, 0), ctx->from))
            args->valid[0] = 0;
    }

    // Whether a hit of ray on triangle at distance t is none: one on the object it leaves
    // (MeetsItself), or one along the triangle's plane, |cos| at most 1e-6 (RADIANCE's o_face()
    // finds no hit there, FTINY; Embree may report one, whose shading divides by the cosine; a
    // triangle without area, whose normal is nought, likewise).
    bool Skips(unsigned triangle, float t, const TraceRay &ray) const {
        if (MeetsItself(triangle, t, ray.from_object)) return true;
        const core::real3 &n = normals_[triangle];
        return std::abs(n[0] * ray.dir[0] + n[1] * ray.dir[1] + n[2] * ray.dir[2]) <= 1e-6;
    }

    // Whether a ray leaving object `from` would meet, at distance t, triangle of that object:
    // never a polygon's (or a mesh's with the mesh's own modifier), not a mesh's within near_.
    bool MeetsItself(unsigned triangle, float t, int from) const {
        if (from < 0 || flat_->triangle_object[triangle] != from) return false;
        return flat_->triangle_material[triangle] < 0 || t < near_;
    }

    // The nearest distance an analytic surface is met at by ray: its own surface, near_.
    double ShapeNear(const TraceRay &ray, int prim, float tnear) const {
        return ray.from_object == flat_->shapes[surfaces_[prim]].object
                   ? std::max(static_cast<double>(tnear), near_)
                   : tnear;
    }

    // Where lane k's ray meets analytic surface prim (double precision), or -1.
    double ShapeDistance(const RTCRayN *ray, unsigned n, unsigned k, unsigned prim) const {
        const TraceRay &r = QueryRay(ray, n, k);
        double org[3], dir[3];
        RayOf(r, org, dir);
        RTCRayN *rn = const_cast<RTCRayN *>(ray);
        return IntersectShape(flat_->shapes[surfaces_[prim]], centre_, org, dir,
                              ShapeNear(r, prim, RTCRayN_tnear(rn, n, k)), RTCRayN_tfar(rn, n, k));
    }

    static void ShapeIntersectFunction(const RTCIntersectFunctionNArguments *args) {
        const auto *self = static_cast<const EmbreeBackend *>(args->geometryUserPtr);
        const unsigned n = args->N;
        RTCRayN *ray = RTCRayHitN_RayN(args->rayhit, n);
        RTCHitN *hit = RTCRayHitN_HitN(args->rayhit, n);
        for (unsigned k = 0; k < n; ++k) {
            if (!args->valid[k]) continue;
            const double t = self->ShapeDistance(ray, n, k, args->primID);
            if (t < 0) continue;
            shape_query.t[RTCRayN_id(ray, n, k)] = t;
            RTCRayN_tfar(ray, n, k) = static_cast<float>(t);
            RTCHitN_Ng_x(hit, n, k) = 0, RTCHitN_Ng_y(hit, n, k) = 0, RTCHitN_Ng_z(hit, n, k) = 1;
            RTCHitN_u(hit, n, k) = 0, RTCHitN_v(hit, n, k) = 0;
            RTCHitN_primID(hit, n, k) = args->primID;
            RTCHitN_geomID(hit, n, k) = args->geomID;
            RTCHitN_instID(hit, n, k, 0) = args->context->instID[0];
        }
    }

    static void ShapeOccludedFunction(const RTCOccludedFunctionNArguments *args) {
        const auto *self = static_cast<const EmbreeBackend *>(args->geometryUserPtr);
        for (unsigned k = 0; k < args->N; ++k)
            if (args->valid[k] && self->ShapeDistance(args->ray, args->N, k, args->primID) >= 0)
                RTCRayN_tfar(args->ray, args->N, k) = -std::numeric_limits<float>::infinity();
    }

    void Fill(const TraceRay &in, RTCRay *r) const {
        r->org_x = static_cast<float>(in.org[0] - centre_[0]);
        r->org_y = static_cast<float>(in.org[1] - centre_[1]);
        r->org_z = static_cast<float>(in.org[2] - centre_[2]);
        r->dir_x = static_cast<float>(in.dir[0]);
        r->dir_y = static_cast<float>(in.dir[1]);
        r->dir_z = static_cast<float>(in.dir[2]);
        // Rays leaving a surface start at once (their own surface is filtered out); others
        // just off where they start, relative to the scene's size.
        r->tnear = static_cast<float>(in.from_object >= 0 ? 1e-9 * extent_ : near_);
        r->tfar = std::isinf(in.tmax) ? std::numeric_limits<float>::infinity()
                                      : static_cast<float>(in.tmax);
        r->mask = 0xffffffffu;
        r->time = 0;
        r->flags = 0;
        r->id = 0;
    }

    RTCDevice device_ = nullptr;
    RTCScene scene_ = nullptr;           // the scene, with MeetsItself as the triangles' filter
    RTCScene bare_scene_ = nullptr;      // the same without the filter (Closest)
    RTCScene blockers_scene_ = nullptr;  // the blockers alone (Blocked), or none
    RTCScene filtered_blockers_scene_ = nullptr;  // the same with MeetsItself as a filter
    std::vector<uint32_t> blockers_;              // their indices in flat_->triangles
    const FlatScene *flat_ = nullptr;
    std::vector<core::real3> normals_;  // per triangle: its unit normal in double (winding)
    std::vector<float> margins_;        // per triangle: EdgeMargin
    // per object: the unit normal of its plane where it is flat and never met by the rays that
    // leave it (all its triangles in one plane and of its own modifier), else 0
    std::vector<core::real3> plane_of_object_;
    std::vector<double> self_reach_;  // per flat object: FindPlanes
    std::vector<int> surfaces_;  // indices of the analytic surfaces (not sources) in flat_->shapes
    unsigned triangles_id_ = RTC_INVALID_GEOMETRY_ID, shapes_id_ = RTC_INVALID_GEOMETRY_ID;
    double centre_[3] = {0, 0, 0};
    double extent_ = 0;
    double inverse_extent_ = 0;  // 1 / extent_ (0 for an empty scene)
    double near_ = 0;  // 1e-6 of the scene's size: closer than that, a surface meets itself
};

}  // namespace

std::unique_ptr<Backend> CreateEmbreeBackend() { return std::make_unique<EmbreeBackend>(); }

}  // namespace dayflux
