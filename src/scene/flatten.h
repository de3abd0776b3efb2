// Flattening a scene to what the backends trace: triangles (polygons triangulated, transforms
// applied, instances expanded) and analytic shapes (spheres, cones, cylinders, rings, distant
// sources), each pointing back to the primitive it came from for its material and modifiers.
#pragma once

#include <array>
#include <vector>

#include "scene/polygons.h"
#include "scene/primitives.h"

namespace dayflux {

struct AnalyticShape {
    enum Kind { kSphere, kCone, kCylinder, kRing, kSource };
    Kind kind;
    bool inward = false;  // bubble, cup, tube: normals point inside
    Vec3 p0{}, p1{};  // centres (cone/cylinder ends; ring/sphere centre in p0; ring normal in p1)
    double r0 = 0, r1 = 0;  // radii (ring: inner r0, outer r1); source: half angle in r0 (degrees)
    int object = -1;
};

struct FlatScene {
    std::vector<Vec3> vertices;
    std::vector<std::array<uint32_t, 3>> triangles;
    std::vector<int> triangle_object;  // primitive index of each triangle
    // The material of each triangle where it is not the primitive's modifier (mesh materials), else
    // -1.
    std::vector<int> triangle_material;
    std::vector<AnalyticShape> shapes;
    // Each polygon's transformed vertices, in order: vertices[first .. first + count - 1]
    // (count 0 for other objects and degenerate polygons); indexed by scene object.
    struct VertexRange {
        uint32_t first = 0, count = 0;
    };
    std::vector<VertexRange> polygon_vertices;
    int top_level_objects = 0;  // the scene's own objects; those after came from instances
    // Scene objects (from instances too), so triangle_object indexes into it.
    Scene scene;
};

// Flattens scene (taking ownership). Instances are read from their octrees on RAYPATH.
FlatScene Flatten(Scene scene);

}  // namespace dayflux
