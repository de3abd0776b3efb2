#include "scene/octree.h"

#include <cmath>
#include <fstream>
#include <map>

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

namespace {

// The header, format number, cube and file list; returns sizeof(OBJECT) of the writer.
int ReadBounds(RadianceBinaryInput &oct, OctreeInfo *info) {
    info->header = oct.Header("Radiance_octree");
    const long objsize = oct.Int(2) - kMagicBase;
    if (objsize <= 0 || objsize > 8) oct.Fail("incompatible octree format");
    for (int i = 0; i < 3; ++i) info->cube_origin[i] = std::atof(oct.String().c_str());
    info->cube_size = std::atof(oct.String().c_str());
    for (double x : {info->cube_origin[0], info->cube_origin[1], info->cube_origin[2]})
        if (!std::isfinite(x) || std::fabs(x) > 1e12) oct.Fail("bad octree bounds");
    if (!(info->cube_size >= 0 && info->cube_size <= 1e12)) oct.Fail("bad octree bounds");
    for (std::string f; !(f = oct.String()).empty();) info->files.push_back(f);
    return static_cast<int>(objsize);
}

// gettree(): a pre-order tree whose leaves are sets, each interned once (as fullnode() does).
int ReadTree(RadianceBinaryInput &oct, int objsize, long nobjects, OctreeNodes *tree,
             std::map<std::vector<int>, int> *interned, int depth = 0) {
    constexpr int kMaxTreeDepth = 128;  // as SkipTree: a damaged file must not exhaust the stack
    if (depth > kMaxTreeDepth) oct.Fail("damaged octree (tree deeper than 128 levels)");
    switch (oct.Byte()) {
        case 0:
            return -1;
        case 1: {
            const long n = oct.Int(objsize);
            if (n <= 0 || n > 511) oct.Fail("bad set in octree");
            std::vector<int> set;
            for (long i = 0; i < n; ++i) {
                const long o = oct.Int(objsize);
                if (o < 0 || o >= nobjects || (!set.empty() && o <= set.back()))
                    oct.Fail("bad set in octree");
                set.push_back(static_cast<int>(o));
            }
            auto [it, added] = interned->emplace(set, static_cast<int>(tree->sets.size()));
            if (added) tree->sets.push_back(std::move(set));
            return -it->second - 2;
        }
        case 2: {
            std::array<int, 8> kids;
            for (int &k : kids) k = ReadTree(oct, objsize, nobjects, tree, interned, depth + 1);
            tree->branches.push_back(kids);
            return static_cast<int>(tree->branches.size()) - 1;
        }
        default:
            oct.Fail("damaged octree");
    }
}

}  // namespace

OctreeInfo ReadOctreeBounds(const std::string &path) {
    auto in = InputSource::Open(path);
    OctreeInfo info;
    RadianceBinaryInput oct(*in, "octree");
    ReadBounds(oct, &info);
    return info;
}

OctreeInfo ReadOctree(const std::string &path, Scene *scene, OctreeNodes *tree) {
    auto in = InputSource::Open(path);
    OctreeInfo info;
    RadianceBinaryInput oct(*in, "octree");
    const int objsize = ReadBounds(oct, &info);
    const long nobjects = oct.Int(objsize);
    if (tree) {
        std::map<std::vector<int>, int> interned;
        *tree = OctreeNodes{};
        tree->root = ReadTree(oct, objsize, nobjects, tree, &interned);
    } else {
        oct.SkipTree(objsize);
    }
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
    oct.Objects(objsize, scene);
    if (static_cast<long>(scene->objects.size() - first) != nobjects)
        oct.Fail("holds " + std::to_string(scene->objects.size() - first) +
                 " objects, its header says " + std::to_string(nobjects));
    return info;
}

}  // namespace dayflux
