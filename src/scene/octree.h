// Reading RADIANCE octrees (oconv output): the scene objects they carry, so programs take
// scene.oct wherever RADIANCE does. Frozen octrees (oconv -f) hold the objects in binary;
// unfrozen ones list the scene files, which are read again. The backends build their own
// acceleration structures, so RADIANCE's octree structure is read only for oconv -i.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "scene/primitives.h"

namespace dayflux {

struct OctreeInfo {
    double cube_origin[3] = {0, 0, 0};
    double cube_size = 0;
    std::vector<std::string> files;  // empty for a frozen octree
    std::string header;              // the header lines (oconv's command line, ...)
};

// RADIANCE's octree structure (common/octree.h): a node >= 0 indexes `branches` (eight children,
// in RADIANCE's order: bit 0 x, bit 1 y, bit 2 z), -1 is empty, and a node < -1 holds the object
// set sets[-node - 2] (ascending object indices).
struct OctreeNodes {
    std::vector<std::array<int, 8>> branches;
    std::vector<std::vector<int>> sets;
    int root = -1;
};

// Reads the octree at path ("!command" allowed) into scene (appending), returning its details;
// and its structure into tree where one is given.
OctreeInfo ReadOctree(const std::string &path, Scene *scene, OctreeNodes *tree = nullptr);
// Only the header, cube and file list (RADIANCE's IO_BOUNDS), as instances need.
OctreeInfo ReadOctreeBounds(const std::string &path);

// True if the file starts with an octree header (so tools can accept .oct and .rad alike).
bool IsOctreeFile(const std::string &path);

}  // namespace dayflux
