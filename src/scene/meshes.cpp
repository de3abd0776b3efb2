#include "scene/meshes.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "scene/binary.h"
#include "util/files.h"

namespace dayflux {

namespace {

constexpr int kMeshMagic = 1 * 8 + 311;  // RADIANCE's MESHMAGIC: plus sizeof(OBJECT)
enum { kHasVertices = 1, kHasNormals = 2, kHasUV = 4 };

struct Patch {
    std::vector<std::array<uint32_t, 3>> xyz;
};

// The header, format number and cube; returns sizeof(OBJECT) of the writer.
int ReadCube(RadianceBinaryInput &m, MeshCube *cube) {
    m.Header("Radiance_tmesh");
    const long objsize = m.Int(2) - kMeshMagic;
    if (objsize <= 0 || objsize > 8) m.Fail("incompatible mesh format");
    for (double &o : cube->origin) o = std::atof(m.String().c_str());
    cube->size = std::atof(m.String().c_str());
    for (double x : {cube->origin[0], cube->origin[1], cube->origin[2], cube->size})
        if (!std::isfinite(x) || std::fabs(x) > 1e12) m.Fail("bad mesh bounds");
    if (!(cube->size > 0)) m.Fail("bad mesh bounds");
    return static_cast<int>(objsize);
}

}  // namespace

MeshCube ReadMeshBounds(const std::string &path) {
    auto in = InputSource::Open(path);
    RadianceBinaryInput m(*in, "mesh file");
    MeshCube cube;
    ReadCube(m, &cube);
    return cube;
}

std::vector<MeshTriangle> ReadMesh(const std::string &path, Scene *scene) {
    auto in = InputSource::Open(path);
    RadianceBinaryInput m(*in, "mesh file");
    MeshCube cube;
    const long objsize = ReadCube(m, &cube);
    const double *origin = cube.origin, size = cube.size;
    for (int i = 0; i < 4; ++i) m.Real();  // (u,v) limits
    m.SkipTree(static_cast<int>(objsize));
    // The mesh's materials, stored as a frozen octree stores objects.
    const int mat0 = static_cast<int>(scene->objects.size());
    m.Objects(static_cast<int>(objsize), scene);
    const long npatches = m.Int(4);
    if (npatches < 0) m.Fail("bad patch count");
    // The count is untrusted: patches are added as they are read (each takes 17 bytes or more),
    // so a short file claiming many fails at its end instead of allocating them all first.
    std::vector<Patch> patches;
    patches.reserve(static_cast<size_t>(std::min(npatches, 4096L)));
    struct Pending {
        long v[3];  // global vertex ids: patch << 8 | local
        long mat;
    };
    std::vector<Pending> tris;
    for (long pn = 0; pn < npatches; ++pn) {
        const long flags = m.Int(1);
        if (!(flags & kHasVertices) || (flags & ~(kHasVertices | kHasNormals | kHasUV)))
            m.Fail("bad patch flags");
        const long nverts = m.Int(2);
        if (nverts <= 0 || nverts > 256) m.Fail("bad number of patch vertices");
        Patch &p = patches.emplace_back();
        p.xyz.resize(nverts);
        for (auto &v : p.xyz)
            for (uint32_t &c : v) c = static_cast<uint32_t>(m.Int(4));
        if (flags & kHasNormals)
            for (long i = 0; i < nverts; ++i) m.Int(4);
        if (flags & kHasUV)
            for (long i = 0; i < 2 * nverts; ++i) m.Int(4);
        const long ntris = m.Int(2);
        if (ntris < 0 || ntris > 512) m.Fail("bad number of local triangles");
        const size_t first = tris.size();
        for (long i = 0; i < ntris; ++i) {
            Pending t;
            for (long &v : t.v) v = pn << 8 | (m.Int(1) & 0xff);
            tris.push_back(t);
        }
        if (m.Int(2) > 1) {
            for (long i = 0; i < ntris; ++i) tris[first + i].mat = m.Int(2);
        } else {
            const long sole = m.Int(2);
            for (long i = 0; i < ntris; ++i) tris[first + i].mat = sole;
        }
        const long nj1 = m.Int(2);
        if (nj1 < 0 || nj1 > 256) m.Fail("bad number of joiner triangles");
        for (long i = 0; i < nj1; ++i) {
            Pending t;
            t.v[0] = m.Int(4);
            t.v[1] = pn << 8 | (m.Int(1) & 0xff);
            t.v[2] = pn << 8 | (m.Int(1) & 0xff);
            t.mat = m.Int(2);
            tris.push_back(t);
        }
        const long nj2 = m.Int(2);
        if (nj2 < 0 || nj2 > 256) m.Fail("bad number of double joiner triangles");
        for (long i = 0; i < nj2; ++i) {
            Pending t;
            t.v[0] = m.Int(4);
            t.v[1] = m.Int(4);
            t.v[2] = pn << 8 | (m.Int(1) & 0xff);
            t.mat = m.Int(2);
            tris.push_back(t);
        }
    }
    // Vertices sit at the centres of their quantisation cells in the mesh's cube.
    const double res = size / 4294967296.;
    auto vertex = [&](long id) {
        const long pn = id >> 8, local = id & 0xff;
        if (pn < 0 || pn >= npatches || local >= static_cast<long>(patches[pn].xyz.size()))
            m.Fail("triangle refers to a missing vertex");
        Vec3 v;
        for (int k = 0; k < 3; ++k) v[k] = origin[k] + (patches[pn].xyz[local][k] + .5) * res;
        return v;
    };
    std::vector<MeshTriangle> out;
    out.reserve(tris.size());
    for (const Pending &t : tris) {
        MeshTriangle mt;
        for (int k = 0; k < 3; ++k) mt.v[k] = vertex(t.v[k]);
        mt.material = t.mat == -1 ? -1 : static_cast<int>(mat0 + t.mat);
        if (t.mat < -1 || mt.material >= static_cast<int>(scene->objects.size()))
            m.Fail("triangle refers to a missing material");
        out.push_back(mt);
    }
    return out;
}

}  // namespace dayflux
