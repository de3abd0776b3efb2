// The CPU backend: Embree 3 triangles. Geometry is moved so the scene's centre is at the origin,
// so float precision follows the scene's size, not its distance from the world origin (a room
// 100 km away traces as well as one at the origin).
#include <embree3/rtcore.h>

#include <cmath>
#include <limits>

#include "raytrace/backend.h"
#include "util/errors.h"

namespace dayflux {

namespace {

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
        if (scene_) rtcReleaseScene(scene_);
        rtcReleaseDevice(device_);
    }
    std::string Name() const override { return "embree"; }

    void Commit(const FlatScene &flat) override {
        flat_ = &flat;
        if (!flat.shapes.empty())
            for (const AnalyticShape &s : flat.shapes)
                if (s.kind != AnalyticShape::kSource)
                    ErrorExit("spheres, cones, cylinders and rings are not traced yet (object '" +
                              flat.scene.objects[s.object].name + "')");
        double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
        for (const Vec3 &v : flat.vertices)
            for (int k = 0; k < 3; ++k)
                lo[k] = std::min(lo[k], v[k]), hi[k] = std::max(hi[k], v[k]);
        extent_ = 0;
        for (int k = 0; k < 3; ++k) {
            centre_[k] = flat.vertices.empty() ? 0 : 0.5 * (lo[k] + hi[k]);
            extent_ = std::max(extent_, flat.vertices.empty() ? 0 : hi[k] - lo[k]);
        }
        scene_ = rtcNewScene(device_);
        rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST);
        rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_HIGH);
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
            rtcCommitGeometry(g);
            rtcAttachGeometry(scene_, g);
            rtcReleaseGeometry(g);
        }
        rtcCommitScene(scene_);
    }

    void Closest(const TraceRay *rays, TraceHit *hits, size_t n) const override {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        for (size_t i = 0; i < n; ++i) {
            RTCRayHit rh;
            Fill(rays[i], &rh.ray);
            rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
            rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
            rtcIntersect1(scene_, &ctx, &rh);
            TraceHit &h = hits[i];
            h.hit = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
            if (!h.hit) continue;
            h.t = rh.ray.tfar;
            h.triangle = rh.hit.primID;
            // The normal from the double-precision vertices, in the triangle's winding.
            const auto &t = flat_->triangles[h.triangle];
            const Vec3 &a = flat_->vertices[t[0]], &b = flat_->vertices[t[1]],
                       &c = flat_->vertices[t[2]];
            const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]},
                         v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
            double nn[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                            u[0] * v[1] - u[1] * v[0]};
            const double len = std::sqrt(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
            for (int k = 0; k < 3; ++k) h.normal[k] = len > 0 ? nn[k] / len : 0;
        }
    }

    void Occluded(const TraceRay *rays, bool *occluded, size_t n) const override {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        for (size_t i = 0; i < n; ++i) {
            RTCRay r;
            Fill(rays[i], &r);
            rtcOccluded1(scene_, &ctx, &r);
            occluded[i] = r.tfar < 0;
        }
    }

  private:
    void Fill(const TraceRay &in, RTCRay *r) const {
        r->org_x = static_cast<float>(in.org[0] - centre_[0]);
        r->org_y = static_cast<float>(in.org[1] - centre_[1]);
        r->org_z = static_cast<float>(in.org[2] - centre_[2]);
        r->dir_x = static_cast<float>(in.dir[0]);
        r->dir_y = static_cast<float>(in.dir[1]);
        r->dir_z = static_cast<float>(in.dir[2]);
        // Start just off the surface: relative to the scene's size, not a fixed length.
        r->tnear = static_cast<float>(1e-6 * extent_);
        r->tfar = std::isinf(in.tmax) ? std::numeric_limits<float>::infinity()
                                      : static_cast<float>(in.tmax);
        r->mask = 0xffffffffu;
        r->time = 0;
        r->flags = 0;
        r->id = 0;
    }

    RTCDevice device_ = nullptr;
    RTCScene scene_ = nullptr;
    const FlatScene *flat_ = nullptr;
    double centre_[3] = {0, 0, 0};
    double extent_ = 0;
};

}  // namespace

std::unique_ptr<Backend> CreateEmbreeBackend() { return std::make_unique<EmbreeBackend>(); }

}  // namespace dayflux
