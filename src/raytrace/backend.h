// What the integrators need from a ray tracer, and nothing more: build once from a flattened
// scene, then closest-hit and any-hit queries on batches of rays. Embree implements it for the CPU
// driver (embree/). Like Embree's own API: an opaque object, an explicit commit, one error path.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "scene/flatten.h"

namespace dayflux {

struct TraceRay {
    double org[3];
    double dir[3];  // unit length
    double tmax;    // infinity for unbounded rays
    // The scene object the ray leaves, or -1. Its own surface is not met again where it starts
    // (a polygon, being planar, not at all), while any other surface is met however near: a
    // ray leaving a floor next to a wall finds the wall, whatever the scene's size.
    int from_object = -1;
};

struct TraceHit {
    bool hit = false;
    double t = 0;
    uint32_t triangle = 0;         // index into FlatScene::triangles (when shape < 0)
    int shape = -1;                // else index into FlatScene::shapes (analytic surfaces)
    double normal[3] = {0, 0, 0};  // unit geometric normal: triangle winding, shape's outside
    // The hit point in double precision, on the surface: for triangles, the ray's intersection
    // with the triangle's plane, moved into the triangle where float traversal reported a hit
    // a hair beyond an edge (so new rays from it never start outside a closed room).
    double point[3] = {0, 0, 0};
};

class Backend {
  public:
    virtual ~Backend() = default;
    virtual std::string Name() const = 0;
    // Triangles (indices into FlatScene::triangles) that Blocked tests alone, built by the next
    // Commit; none by default.
    virtual void SetBlockers(std::vector<uint32_t> triangles) = 0;
    // Builds the acceleration structure; the scene must outlive the backend.
    virtual void Commit(const FlatScene &scene) = 0;
    virtual void Closest(const TraceRay *rays, TraceHit *hits, size_t n) const = 0;
    // true where something lies between the origin and tmax.
    virtual void Occluded(const TraceRay *rays, bool *occluded, size_t n) const = 0;
    // true where one of the blockers lies between the origin and tmax (a ray leaving a blocker
    // does not meet it where it starts, as in Closest).
    virtual void Blocked(const TraceRay *rays, bool *blocked, size_t n) const = 0;
};

// A caster that passes every call on to another: the base of EngineOptions::wrap_cpu_backend's
// wrappers (benchmarks' and tests' counters), which override what they watch.
class ForwardingBackend : public Backend {
  public:
    explicit ForwardingBackend(std::unique_ptr<Backend> inner) : inner_(std::move(inner)) {}
    std::string Name() const override { return inner_->Name(); }
    void SetBlockers(std::vector<uint32_t> triangles) override {
        inner_->SetBlockers(std::move(triangles));
    }
    void Commit(const FlatScene &scene) override { inner_->Commit(scene); }
    void Closest(const TraceRay *rays, TraceHit *hits, size_t n) const override {
        inner_->Closest(rays, hits, n);
    }
    void Occluded(const TraceRay *rays, bool *occluded, size_t n) const override {
        inner_->Occluded(rays, occluded, n);
    }
    void Blocked(const TraceRay *rays, bool *blocked, size_t n) const override {
        inner_->Blocked(rays, blocked, n);
    }

  protected:
    std::unique_ptr<Backend> inner_;
};

// The CPU ray caster. (The GPU driver finds its hits itself, in the shader.)
std::unique_ptr<Backend> CreateEmbreeBackend();

}  // namespace dayflux
