// RADIANCE compiled triangle meshes (.rtm, made by obj2mesh): vertices quantised in the mesh's
// bounding cube, triangles grouped in patches of up to 256 vertices, and the mesh's own materials.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "scene/polygons.h"
#include "scene/primitives.h"

namespace dayflux {

struct MeshTriangle {
    std::array<Vec3, 3> v;
    int material;  // index into the scene (the mesh's materials are appended), -1: the mesh's
                   // modifier
};

// Reads a .rtm file, appending its materials to scene and returning its triangles.
std::vector<MeshTriangle> ReadMesh(const std::string &path, Scene *scene);

// The mesh's bounding cube (RADIANCE's IO_BOUNDS), as oconv needs for a mesh instance.
struct MeshCube {
    double origin[3];
    double size;
};
MeshCube ReadMeshBounds(const std::string &path);

}  // namespace dayflux
