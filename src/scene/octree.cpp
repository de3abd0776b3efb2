#include "scene/octree.h"

#include <cmath>
#include <fstream>

#include "matrix/header.h"
#include "scene/reader.h"
#include "util/files.h"

namespace dayflux {

namespace {

constexpr int kMagicBase = 4 * 8 + 251;  // RADIANCE's OCTMAGIC: plus sizeof(OBJECT)
enum { kEmpty = 0, kFull = 1, kTree = 2 };

class OctreeInput {
  public:
    explicit OctreeInput(InputSource &in) : in_(in) {}
    [[noreturn]] void Fail(const std::string &msg) const {
        FileLoc loc{in_.Name(), 0};
        ErrorExit(&loc, msg);
    }
    int Byte() {
        const int c = in_.Get();
        if (c < 0) Fail("truncated octree");
        return c;
    }
    // A big-endian, sign-extended integer of n bytes (RADIANCE's getint()).
    long Int(int n) {
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
    // RADIANCE's getflt(): a 31-bit mantissa and a one-byte exponent.
    double Real() {
        const long l = Int(4);
        if (l == 0) {
            Byte();
            return 0.0;
        }
        const double d = (l + .5 - (l < 0)) * (1. / 0x7fffffff);
        return std::ldexp(d, static_cast<int>(Int(1)));
    }
    void SkipTree(int objsize) {
        switch (Byte()) {
            case kEmpty:
                return;
            case kFull: {
                const long n = Int(objsize);
                for (long i = 0; i < n * objsize; ++i) Byte();
                return;
            }
            case kTree:
                for (int i = 0; i < 8; ++i) SkipTree(objsize);
                return;
            default:
                Fail("damaged octree");
        }
    }

  private:
    InputSource &in_;
};

}  // namespace

bool IsOctreeFile(const std::string &path) {
    std::ifstream f(path, std::ios::binary);
    std::string line;
    for (int i = 0; i < 200 && std::getline(f, line) && !line.empty(); ++i)
        if (line.rfind("FORMAT=Radiance_octree", 0) == 0) return true;
    return false;
}

OctreeInfo ReadOctree(const std::string &path, Scene *scene) {
    auto in = InputSource::Open(path);
    OctreeInfo info;
    MatrixHeader h;
    {
        // The header has FORMAT=Radiance_octree, which the matrix header reader does not know.
        std::string line;
        bool octree = false;
        FileLoc loc = in->LocNoLine();
        if (!in->ReadLine(&line) || line.rfind("#?", 0) != 0)
            ErrorExit(&loc, "not an octree (no header)");
        while (in->ReadLine(&line) && !line.empty()) {
            if (line == "FORMAT=Radiance_octree")
                octree = true;
            else
                info.header += line + "\n";
        }
        if (!octree) ErrorExit(&loc, "not an octree (no FORMAT=Radiance_octree in header)");
    }
    OctreeInput oct(*in);
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
        for (const std::string &f : info.files) reader.ReadFile(f);
        if (static_cast<long>(scene->objects.size() - first) != nobjects)
            oct.Fail("its scene files now hold " + std::to_string(scene->objects.size() - first) +
                     " objects, the octree " + std::to_string(nobjects) + " (octree stale?)");
        return info;
    }
    // A frozen octree: a table of type names, then the objects.
    std::vector<const PrimitiveType *> types;
    for (std::string t; !(t = oct.String()).empty();) types.push_back(FindPrimitiveType(t));
    for (;;) {
        const long ti = oct.Int(1);
        if (ti == -1) break;
        if (ti < 0 || ti >= static_cast<long>(types.size()) || !types[ti])
            oct.Fail("reference to unknown type");
        Primitive p;
        p.info = types[ti];
        p.type = p.info->name;
        const long mod = oct.Int(static_cast<int>(objsize));
        p.modifier = mod == -1 ? -1 : static_cast<int>(first + mod);
        if (p.modifier >= static_cast<int>(scene->objects.size()))
            oct.Fail("modifier refers to a later object");
        p.modifier_name = p.modifier < 0 ? "void" : scene->objects[p.modifier].name;
        p.name = oct.String();
        for (long n = oct.Int(2); n > 0; --n) p.sargs.push_back(oct.String());
        for (long n = oct.Int(2); n > 0; --n) p.fargs.push_back(oct.Real());
        p.loc = FileLoc{in->Name(), 0};
        scene->objects.push_back(std::move(p));
    }
    if (static_cast<long>(scene->objects.size() - first) != nobjects)
        oct.Fail("holds " + std::to_string(scene->objects.size() - first) +
                 " objects, its header says " + std::to_string(nobjects));
    return info;
}

}  // namespace dayflux
