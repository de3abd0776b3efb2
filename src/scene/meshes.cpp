#include "scene/meshes.h"

#include <cmath>
#include <cstdlib>

#include "util/files.h"

namespace dayflux {

namespace {

constexpr int kMeshMagic = 1 * 8 + 311;  // RADIANCE's MESHMAGIC: plus sizeof(OBJECT)
enum { kHasVertices = 1, kHasNormals = 2, kHasUV = 4 };

class MeshInput {
  public:
    explicit MeshInput(InputSource &in) : in_(in) {}
    [[noreturn]] void Fail(const std::string &msg) const {
        FileLoc loc{in_.Name(), 0};
        ErrorExit(&loc, msg);
    }
    int Byte() {
        const int c = in_.Get();
        if (c < 0) Fail("truncated mesh file");
        return c;
    }
    long Int(int n) {  // big-endian, sign-extended (RADIANCE's getint())
        long r = Byte();
        if (r & 0x80) r |= -256L;
        while (--n > 0) r = (r << 8) | Byte();
        return r;
    }
    std::string String() {
        std::string s;
        for (int c; (c = Byte()) != 0;) s.push_back(static_cast<char>(c));
        return s;
    }
    double Real() {
        const long l = Int(4);
        if (l == 0) {
            Byte();
            return 0.0;
        }
        return std::ldexp((l + .5 - (l < 0)) * (1. / 0x7fffffff), static_cast<int>(Int(1)));
    }
    void SkipTree(int objsize) {
        switch (Byte()) {
            case 0:
                return;
            case 1: {
                const long n = Int(objsize);
                for (long i = 0; i < n * objsize; ++i) Byte();
                return;
            }
            case 2:
                for (int i = 0; i < 8; ++i) SkipTree(objsize);
                return;
            default:
                Fail("damaged mesh octree");
        }
    }

  private:
    InputSource &in_;
};

struct Patch {
    std::vector<std::array<uint32_t, 3>> xyz;
};

}  // namespace

std::vector<MeshTriangle> ReadMesh(const std::string &path, Scene *scene) {
    auto in = InputSource::Open(path);
    {
        std::string line;
        bool mesh = false;
        FileLoc loc = in->LocNoLine();
        if (!in->ReadLine(&line) || line.rfind("#?", 0) != 0)
            ErrorExit(&loc, "not a mesh file (no header)");
        while (in->ReadLine(&line) && !line.empty()) mesh |= line == "FORMAT=Radiance_tmesh";
        if (!mesh) ErrorExit(&loc, "not a RADIANCE mesh (no FORMAT=Radiance_tmesh in header)");
    }
    MeshInput m(*in);
    const long objsize = m.Int(2) - kMeshMagic;
    if (objsize <= 0 || objsize > 8) m.Fail("incompatible mesh format");
    double origin[3], size;
    for (double &o : origin) o = std::atof(m.String().c_str());
    size = std::atof(m.String().c_str());
    for (int i = 0; i < 4; ++i) m.Real();  // (u,v) limits
    m.SkipTree(static_cast<int>(objsize));
    // The mesh's materials, stored as a frozen octree stores objects.
    const int mat0 = static_cast<int>(scene->objects.size());
    std::vector<const PrimitiveType *> types;
    for (std::string t; !(t = m.String()).empty();) types.push_back(FindPrimitiveType(t));
    for (;;) {
        const long ti = m.Int(1);
        if (ti == -1) break;
        if (ti < 0 || ti >= static_cast<long>(types.size()) || !types[ti])
            m.Fail("reference to unknown type");
        Primitive p;
        p.info = types[ti];
        p.type = p.info->name;
        const long mod = m.Int(static_cast<int>(objsize));
        p.modifier = mod == -1 ? -1 : static_cast<int>(mat0 + mod);
        p.modifier_name = p.modifier < 0 ? "void" : scene->objects[p.modifier].name;
        p.name = m.String();
        for (long n = m.Int(2); n > 0; --n) p.sargs.push_back(m.String());
        for (long n = m.Int(2); n > 0; --n) p.fargs.push_back(m.Real());
        p.loc = FileLoc{in->Name(), 0};
        scene->objects.push_back(std::move(p));
    }
    const long npatches = m.Int(4);
    if (npatches < 0) m.Fail("bad patch count");
    std::vector<Patch> patches(npatches);
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
        Patch &p = patches[pn];
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
        if (mt.material >= static_cast<int>(scene->objects.size()))
            m.Fail("triangle refers to a missing material");
        out.push_back(mt);
    }
    return out;
}

}  // namespace dayflux
