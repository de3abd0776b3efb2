// Reading RADIANCE octrees (oconv output): the scene objects they carry, so programs take
// scene.oct wherever RADIANCE does. Frozen octrees (oconv -f) hold the objects in binary;
// unfrozen ones list the scene files, which are read again. RADIANCE's own octree structure is
// skipped: the backends build their own acceleration structures.
#pragma once

#include <string>

#include "scene/primitives.h"

namespace dayflux {

struct OctreeInfo {
    double cube_origin[3] = {0, 0, 0};
    double cube_size = 0;
    std::vector<std::string> files;  // empty for a frozen octree
    std::string header;              // the header lines (oconv's command line, ...)
};

// Reads the octree at path ("!command" allowed) into scene (appending), returning its details.
OctreeInfo ReadOctree(const std::string &path, Scene *scene);

// True if the file starts with an octree header (so tools can accept .oct and .rad alike).
bool IsOctreeFile(const std::string &path);

}  // namespace dayflux
