#include "scene/octree.h"

#include <cmath>
#include <fstream>

#include "scene/binary.h"
#include "scene/reader.h"
#include "util/files.h"

namespace dayflux {

namespace {
constexpr int kMagicBase = 4 * 8 + 251;  // RADIANCE's OCTMAGIC: plus sizeof(OBJECT)
}  // namespace

bool IsOctreeFile(const std::string &path) {
    // A scene file never starts with a RADIANCE header line: a file that does is an octree, or
    // a truncated one, or another RADIANCE file given by mistake, and ReadOctree() says which.
    std::ifstream f(path, std::ios::binary);
    std::string line;
    return std::getline(f, line) && line == "#?RADIANCE";
}

OctreeInfo ReadOctree(const std::string &path, Scene *scene) {
    auto in = InputSource::Open(path);
    OctreeInfo info;
    RadianceBinaryInput oct(*in, "octree");
    info.header = oct.Header("Radiance_octree");
    const long objsize = oct.Int(2) - kMagicBase;
    if (objsize <= 0 || objsize > 8) oct.Fail("incompatible octree format");
    for (int i = 0; i < 3; ++i) info.cube_origin[i] = std::atof(oct.String().c_str());
    info.cube_size = std::atof(oct.String().c_str());
    for (std::string f; !(f = oct.String()).empty();) info.files.push_back(f);
    const long nobjects = oct.Int(static_cast<int>(objsize));
    oct.SkipTree(static_cast<int>(objsize));
    const size_t first = scene->objects.size();
    if (!info.files.empty()) {
        // An unfrozen octree: the scene is in the files oconv read (relative to where it ran).
        SceneReader reader(scene);
        for (const std::string &f : info.files) {
            const FileLoc loc{path, 0};  // oconv records "!command" inputs in the list
            auto source = InputSource::OpenNamedIn(f, loc);
            reader.Read(*source);
        }
        if (static_cast<long>(scene->objects.size() - first) != nobjects)
            oct.Fail("its scene files now hold " + std::to_string(scene->objects.size() - first) +
                     " objects, the octree " + std::to_string(nobjects) + " (octree stale?)");
        return info;
    }
    // A frozen octree: a table of type names, then the objects.
    oct.Objects(static_cast<int>(objsize), scene);
    if (static_cast<long>(scene->objects.size() - first) != nobjects)
        oct.Fail("holds " + std::to_string(scene->objects.size() - first) +
                 " objects, its header says " + std::to_string(nobjects));
    return info;
}

}  // namespace dayflux
