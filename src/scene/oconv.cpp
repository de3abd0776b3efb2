#include "scene/oconv.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <map>
#include <span>

#include "scene/binary.h"
#include "scene/meshes.h"
#include "scene/octree.h"
#include "scene/reader.h"
#include "scene/xform_text.h"
#include "util/raypath.h"

// The arithmetic below follows RADIANCE's (src/ot, common/face.c, cone.c, clip.c, plocate.c,
// fvect.c) operation for operation: a cube an object barely touches is in or out of its set by
// the same rounding, so the trees, and the files, are the same bytes.

namespace dayflux {

namespace {

constexpr double kFtiny = 1e-6;            // FTINY (RREAL double)
constexpr double kMargin = 10 * kFtiny;    // OMARGIN around the scene's cube
constexpr double kVertexError = 1e-5;      // VERTEPS: a vertex off the polygon's plane
constexpr double kRoot3 = 1.732050808;     // as RADIANCE writes it
constexpr int kMaxSet = 511;               // MAXSET
constexpr int kObjectSize = 4;             // sizeof(OBJECT): int32
constexpr int kOctreeMagic = 4 * 8 + 251;  // OCTMAGIC
enum { kMiss = 0, kHit = 1, kIn = 2 };     // O_MISS, O_HIT, O_IN

using V3 = std::array<double, 3>;

double Dot(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

double Dist2(const double *a, const double *b) {
    const V3 d{b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    return Dot(d.data(), d.data());
}

double Dist2Segment(const double *p, const double *e1, const double *e2) {
    const double d = Dist2(e1, e2), d1 = Dist2(e1, p);
    double d2 = Dist2(e2, p);
    if (d2 > d1) {
        if (d2 - d1 > d) return d1;
    } else if (d1 - d2 > d) {
        return d2;
    }
    d2 = d + d1 - d2;
    return d1 - 0.25 * d2 * d2 / d;
}

// normalize(): the first-order square root near one is RADIANCE's, and so are its bits.
double Normalize(double *v) {
    double d = Dot(v, v), len;
    if (d == 0.0) return 0.0;
    if (d <= 1.0 + kFtiny && d >= 1.0 - kFtiny) {
        len = 0.5 + 0.5 * d;
        d = 2.0 - len;
    } else {
        len = std::sqrt(d);
        d = 1.0 / len;
    }
    for (int i = 0; i < 3; ++i) v[i] *= d;
    return len;
}

bool RelativelyEqual(double a, double b) {  // FRELEQ
    return std::fabs(a - b) <= kFtiny * 0.5 * (std::fabs(a) + std::fabs(b));
}

struct Cube {
    V3 org{};
    double size = 0;
    int tree = -1;
};

// plocate(): where p lies against a box, two bits per axis.
constexpr int kBelow = 025, kAbove = 052;
int Position(int axis) { return 3 << (axis << 1); }

int Locate(const double *p, const V3 &min, const V3 &max) {
    int loc = 0;
    for (int i = 0; i < 3; ++i) {
        if (p[i] < min[i] - kFtiny)
            loc |= Position(i) & kBelow;
        else if (p[i] > max[i] + kFtiny)
            loc |= Position(i) & kAbove;
    }
    return loc;
}

// clip(): Cohen-Sutherland; true if some of the segment is in the box.
bool Clip(V3 a, V3 b, const V3 &min, const V3 &max) {
    double *ep1 = a.data(), *ep2 = b.data();
    int loc1 = Locate(ep1, min, max), loc2 = Locate(ep2, min, max);
    bool accept;
    for (int iterations = 6; !((accept = !(loc1 | loc2)) || (loc1 & loc2));) {
        if (iterations-- <= 0) return false;
        if (!loc1) {
            std::swap(ep1, ep2);
            std::swap(loc1, loc2);
        }
        for (int i = 0; i < 3; ++i) {
            double d;
            if (loc1 & Position(i) & kBelow) {
                d = (min[i] - ep1[i]) / (ep2[i] - ep1[i]);
                ep1[i] = min[i];
            } else if (loc1 & Position(i) & kAbove) {
                d = (max[i] - ep1[i]) / (ep2[i] - ep1[i]);
                ep1[i] = max[i];
            } else {
                continue;
            }
            for (int j = 0; j < 3; ++j)
                if (j != i) ep1[j] += (ep2[j] - ep1[j]) * d;
            break;
        }
        loc1 = Locate(ep1, min, max);
    }
    return accept;
}

V3 Apply(const Transform &t, const double *p) {
    V3 out;
    t.Apply(p, out.data());
    return out;
}

// invxf(): the inverse of an instance's transform, built from its options' own inverses in
// reverse order (as RADIANCE does, so the rotations' sines and cosines are the same numbers).
Transform InverseOf(const std::vector<std::string> &words, size_t first) {
    Transform inv;
    for (size_t i = first; i < words.size(); ++i) {
        const std::string &a = words[i];
        const auto number = [&] { return std::atof(words[++i].c_str()); };
        Transform t;
        t.identity = false;
        if (a == "-t") {
            for (int k = 0; k < 3; ++k) t.m[12 + k] = -number();
        } else if (a == "-rx" || a == "-ry" || a == "-rz") {
            const double ang = -number() * (M_PI / 180.), c = std::cos(ang), s = std::sin(ang);
            const int ax = a[2] - 'x', u = (ax + 1) % 3, w = (ax + 2) % 3;
            t.m[4 * u + u] = c, t.m[4 * u + w] = s, t.m[4 * w + u] = -s, t.m[4 * w + w] = c;
        } else if (a == "-s") {
            const double s = 1.0 / number();
            for (int k = 0; k < 3; ++k) t.m[5 * k] = s;
        } else if (a == "-mx" || a == "-my" || a == "-mz") {
            t.m[5 * (a[2] - 'x')] = -1;
        } else if (a == "-i") {
            ++i;  // "-i 1": a group marker (ApplyTransformOption refuses other counts)
            continue;
        }
        inv = t.Then(inv);
    }
    return inv;
}

// One object as oconv holds it: its arguments as xform printed them, changed as RADIANCE's
// getcone() and o_sphere() change them, and what its cube test needs.
struct Object {
    enum Shape { kNone, kFace, kSphere, kCone, kOctreeInstance, kMeshInstance };
    Shape shape = kNone;
    // polygon (getface()), first: the tests read these most
    int nv = 0, ax = 0;
    const double *va = nullptr;  // p.fargs
    V3 norm{};
    double offset = 0, area = 0;
    // cone, cup, cylinder, tube, ring (getcone()): argument indices of ends and radii
    bool cone_ok = false;
    int p0 = 0, p1 = 0, r0 = 0, r1 = 0;
    V3 ad{};
    // instance, mesh: the cube of what they place, and their transform both ways
    V3 cube_org{};
    double cube_size = 0;
    Transform forward, backward;
    int modifier = -1;  // omod: an alias of the same modifier points at the object it copies
    Primitive p;

    const double *Vertex(int i) const { return va + 3 * i; }
};

// fullnode()'s table: each distinct object set stored once (its count, then its objects, in one
// pool), so that equal leaves are the same node.
class SetTable {
  public:
    int Intern(std::span<const int> set) {
        if (2 * (start_.size() + 1) > slots_.size()) Grow();
        const size_t mask = slots_.size() - 1;
        for (size_t i = Hash(set) & mask;; i = (i + 1) & mask) {
            if (slots_[i] < 0) {
                slots_[i] = static_cast<int>(start_.size());
                start_.push_back(pool_.size());
                pool_.push_back(static_cast<int>(set.size()));
                pool_.insert(pool_.end(), set.begin(), set.end());
                return slots_[i];
            }
            const std::span<const int> old = Get(slots_[i]);
            if (std::equal(old.begin(), old.end(), set.begin(), set.end())) return slots_[i];
        }
    }
    std::span<const int> Get(int id) const {
        const size_t at = start_[id];
        return {pool_.data() + at + 1, static_cast<size_t>(pool_[at])};
    }

  private:
    static size_t Hash(std::span<const int> set) {
        uint64_t h = set.size();
        for (int o : set) h = (h ^ static_cast<uint32_t>(o)) * 0x9e3779b97f4a7c15ull;
        return static_cast<size_t>(h ^ h >> 29);
    }
    void Grow() {
        slots_.assign(slots_.size() * 2, -1);
        const size_t mask = slots_.size() - 1;
        for (size_t id = 0; id < start_.size(); ++id) {
            size_t i = Hash(Get(static_cast<int>(id))) & mask;
            while (slots_[i] >= 0) i = (i + 1) & mask;
            slots_[i] = static_cast<int>(id);
        }
    }

    std::vector<int> pool_;
    std::vector<size_t> start_;
    std::vector<int> slots_ = std::vector<int>(1024, -1);
};

class OctreeMaker {
  public:
    explicit OctreeMaker(const OconvOptions &o) : options_(o) {}

    void Make(const std::vector<std::string> &files, const std::string &command_line,
              const RadianceBinaryOutput::Sink &write);

  private:
    void Warn(const Primitive &p, const std::string &message) const {
        if (options_.warnings) Warning(&p.loc, p.type + " '" + p.name + "': " + message);
    }
    int LastModifier(int before, const std::string &name) const;
    bool SameDefinition(int a, int b) const;
    void ResolveModifiers(int first_by_name);
    void Prepare(Object *o);
    void PrepareFace(Object *o) const;
    bool PrepareCone(Object *o) const;
    void PrepareInstance(Object *o) const;
    void AddToBox(const Object &o, V3 *min, V3 *max) const;
    void FitCube(const V3 &min, const V3 &max);

    int Test(Object &o, const Cube &cu);
    int TestFace(const Object &o, const Cube &cu) const;
    int TestSphere(Object &o, const Cube &cu);
    int TestCone(const Object &o, const Cube &cu) const;
    int TestCube(const Object &o, const Cube &cu) const;

    void AddObject(Cube *cu, int obj);
    void AddToFull(Cube *cu, int obj, int inc);
    int FullNode(std::span<const int> set) { return -sets_.Intern(set) - 2; }
    int Combine(int node);
    void WriteTree(int node, RadianceBinaryOutput *out) const;
    void WriteObjects(RadianceBinaryOutput *out) const;

    OconvOptions options_;
    std::vector<Object> objects_;
    Cube scene_;
    double min_cube_size_ = 0;
    OctreeNodes nodes_;
    SetTable sets_;
    std::map<std::string, int> modifiers_;  // RADIANCE's modifier table (modobject.c)
};

void OctreeMaker::Make(const std::vector<std::string> &files, const std::string &command_line,
                       const RadianceBinaryOutput::Sink &write) {
    Scene scene;
    std::string header = "#?RADIANCE\n";
    std::vector<std::string> names;
    bool frozen = options_.frozen, input_frozen = false;
    if (!options_.input_octree.empty()) {
        if (options_.bounded) ErrorExit("only one of '-b' or '-i'");
        const OctreeInfo in = ReadOctree(options_.input_octree, &scene, &nodes_);
        header += in.header;
        names = in.files;
        input_frozen = names.empty();
        for (int i = 0; i < 3; ++i) scene_.org[i] = in.cube_origin[i];
        scene_.size = in.cube_size;
        scene_.tree = nodes_.root;
        for (const auto &set : nodes_.sets) sets_.Intern(set);  // the same ids, in order
    } else if (options_.bounded) {
        for (int i = 0; i < 3; ++i) scene_.org[i] = options_.bounds_origin[i] - kMargin;
        scene_.size = options_.bounds_size + 2 * kMargin;
    }
    const int first_new = static_cast<int>(scene.objects.size());
    SceneReader reader(&scene);
    reader.KnowExistingModifiers();
    for (const std::string &f : files) {
        const size_t before = scene.objects.size();
        reader.ReadFile(f);
        if (scene.objects.size() == before && options_.warnings)
            Warning("(" + (f == "-" ? std::string("standard input") : f) + "): empty file");
        if (f == "-")
            frozen = true;
        else
            names.push_back(f);
    }
    if (input_frozen && !frozen) {
        if (options_.warnings) Warning("frozen octree");
        frozen = true;
    }
    objects_.resize(scene.objects.size());
    for (size_t i = 0; i < scene.objects.size(); ++i)
        objects_[i].p = AsXformPrints(scene.objects[i]);
    ResolveModifiers(input_frozen ? first_new : 0);
    for (Object &o : objects_) Prepare(&o);

    V3 min, max;
    min.fill(1e10);  // FHUGE
    max.fill(-1e10);
    for (size_t i = first_new; i < objects_.size(); ++i) AddToBox(objects_[i], &min, &max);
    FitCube(min, max);
    min_cube_size_ = scene_.size / options_.resolution - kFtiny;
    for (size_t i = first_new; i < objects_.size(); ++i) AddObject(&scene_, static_cast<int>(i));
    scene_.tree = Combine(scene_.tree);

    write(header + command_line + "FORMAT=Radiance_octree\n\n");
    RadianceBinaryOutput out(write);
    out.Int(kOctreeMagic + kObjectSize, 2);
    char number[64];
    for (int i = 0; i < 3; ++i) {
        std::snprintf(number, sizeof number, "%.12g", scene_.org[i]);
        out.String(number);
    }
    std::snprintf(number, sizeof number, "%.12g", scene_.size);
    out.String(number);
    if (!frozen)
        for (const std::string &n : names) out.String(n);
    out.String("");
    out.Int(static_cast<long>(objects_.size()), kObjectSize);
    WriteTree(scene_.tree, &out);
    if (frozen) WriteObjects(&out);
    out.Flush();
}

void OctreeMaker::FitCube(const V3 &min, const V3 &max) {
    if (scene_.size == 0.0) {
        if (min[0] <= max[0]) {
            V3 lo = min, hi = max;
            for (int i = 0; i < 3; ++i) {
                lo[i] -= kMargin;
                hi[i] += kMargin;
            }
            for (int i = 0; i < 3; ++i)
                if (hi[i] - lo[i] > scene_.size) scene_.size = hi[i] - lo[i];
            for (int i = 0; i < 3; ++i) scene_.org[i] = (hi[i] + lo[i] - scene_.size) * .5;
        }
        return;
    }
    for (int i = 0; i < 3; ++i)
        if (min[i] < scene_.org[i] || max[i] > scene_.org[i] + scene_.size)
            ErrorExit("boundary does not encompass scene");
}

void OctreeMaker::Prepare(Object *o) {
    const std::string &t = o->p.type;
    if (t == "polygon") {
        o->shape = Object::kFace;
        PrepareFace(o);
    } else if (t == "sphere" || t == "bubble") {
        o->shape = Object::kSphere;
    } else if (t == "cone" || t == "cup" || t == "cylinder" || t == "tube" || t == "ring") {
        o->shape = Object::kCone;
        o->cone_ok = PrepareCone(o);
    } else if (t == "instance" || t == "mesh") {
        o->shape = t == "instance" ? Object::kOctreeInstance : Object::kMeshInstance;
        PrepareInstance(o);
    }
}

bool IsModifier(const Primitive &p) {
    return p.info->kind != PrimitiveKind::kSurface && p.info->kind != PrimitiveKind::kVolume;
}

// eqreal()
bool NearlyEqual(double a, double b) {
    if (b != 0.0) a = a / b - 1.0;
    return -kFtiny <= a && a <= kFtiny;
}

// lastmod(): the definition of name in force before object `before`.
int OctreeMaker::LastModifier(int before, const std::string &name) const {
    const auto it = modifiers_.find(name);
    const int i = it == modifiers_.end() ? -1 : it->second;
    if (before < 0 || i < before) return i;
    for (int k = before; k-- > 0;)
        if (IsModifier(objects_[k].p) && objects_[k].p.name == name) return k;
    return -1;
}

// eqobjects(): the same type, arguments equal to a millionth, and equal modifiers down the
// chain, modifier names among the strings (alias, illum, mirror, mixtures, antimatter) compared
// by what they name.
bool OctreeMaker::SameDefinition(int a, int b) const {
    while (a != b) {
        if (a < 0 || b < 0) return false;
        const Primitive &p = objects_[a].p, &q = objects_[b].p;
        if (p.info != q.info || p.sargs.size() != q.sargs.size() ||
            p.fargs.size() != q.fargs.size())
            return false;
        for (size_t i = p.fargs.size(); i-- > 0;)
            if (!NearlyEqual(p.fargs[i], q.fargs[i])) return false;
        const std::string &t = p.type;
        size_t n = 0;
        if (t == "alias" || t == "illum" || t == "mirror")
            n = !p.sargs.empty();
        else if (t == "mixfunc" || t == "mixdata" || t == "mixtext" || t == "mixpict")
            n = 2 * (p.sargs.size() >= 2);
        else if (t == "antimatter")
            n = p.sargs.size();
        for (size_t i = p.sargs.size(); i-- > n;)
            if (p.sargs[i] != q.sargs[i]) return false;
        while (n-- > 0)
            if (!SameDefinition(LastModifier(a, p.sargs[n]), LastModifier(b, q.sargs[n])))
                return false;
        a = objects_[a].modifier;
        b = objects_[b].modifier;
    }
    return true;
}

// readobj()'s modifiers, as RADIANCE keeps them: a name means its latest definition unless that
// repeats the one before it (insertobject()), and an alias of the modifier its original has (or
// "inherit") becomes a reference to that original, with no arguments. Objects read from a frozen
// octree keep the modifiers stored with them.
void OctreeMaker::ResolveModifiers(int first_by_name) {
    for (int i = 0; i < static_cast<int>(objects_.size()); ++i) {
        Object &o = objects_[i];
        Primitive &p = o.p;
        if (i >= first_by_name) {
            const bool inherit = p.modifier_name == "inherit";
            const auto it = modifiers_.find(p.modifier_name);
            o.modifier =
                p.modifier_name == "void" || inherit || it == modifiers_.end() ? -1 : it->second;
            if (p.type == "alias") {
                const auto orig = modifiers_.find(p.sargs[0]);
                const int original = orig == modifiers_.end() ? -1 : orig->second;
                if (original >= 0 && (inherit || o.modifier == objects_[original].modifier)) {
                    o.modifier = original;
                    p.sargs.clear();
                }
            }
        } else {
            o.modifier = p.modifier;
        }
        if (!IsModifier(p)) continue;
        const auto it = modifiers_.find(p.name);
        if (it == modifiers_.end() || !SameDefinition(i, it->second)) modifiers_[p.name] = i;
    }
}

// getface(): vertex count (a closing vertex repeated is dropped), normal, area, plane offset and
// the dominant axis.
void OctreeMaker::PrepareFace(Object *o) const {
    o->va = o->p.fargs.data();
    o->nv = static_cast<int>(o->p.fargs.size() / 3);
    if (o->nv > 3 && Dist2(o->Vertex(0), o->Vertex(o->nv - 1)) <= kFtiny * kFtiny) --o->nv;
    V3 v1, v2, v3;
    for (int k = 0; k < 3; ++k) v1[k] = o->Vertex(1)[k] - o->Vertex(0)[k];
    o->norm = {0, 0, 0};
    for (int i = 2; i < o->nv; ++i) {
        for (int k = 0; k < 3; ++k) v2[k] = o->Vertex(i)[k] - o->Vertex(0)[k];
        v3 = {v1[1] * v2[2] - v1[2] * v2[1], v1[2] * v2[0] - v1[0] * v2[2],
              v1[0] * v2[1] - v1[1] * v2[0]};
        for (int k = 0; k < 3; ++k) o->norm[k] += v3[k];
        v1 = v2;
    }
    o->area = Normalize(o->norm.data());
    if (o->area == 0.0) {
        Warn(o->p, "zero area");
        return;
    }
    o->area *= 0.5;
    int bad = 0;
    o->offset = Dot(o->norm.data(), o->Vertex(0));
    const bool small = std::fabs(o->offset) <= kVertexError;
    for (int i = 1; i < o->nv; ++i) {
        const double d = Dot(o->norm.data(), o->Vertex(i));
        if (small)
            bad += std::fabs(d - o->offset / i) > kVertexError;
        else
            bad += std::fabs(1.0 - d * i / o->offset) > kVertexError;
        o->offset += d;
    }
    o->offset /= o->nv;
    if (o->nv > 3 && bad) Warn(o->p, "non-planar vertex");
    o->ax = std::fabs(o->norm[1]) > std::fabs(o->norm[0]);
    if (std::fabs(o->norm[2]) > std::fabs(o->norm[o->ax])) o->ax = 2;
}

// getcone(): radii made positive (turning a cone into a cup, a cylinder into a tube, and a cone
// of equal radii into a cylinder, as the octree then stores them), ends ordered by radius, and
// the axis. False where RADIANCE leaves the object out of the tree.
bool OctreeMaker::PrepareCone(Object *o) const {
    Primitive &p = o->p;
    std::vector<double> &ca = p.fargs;
    const auto retype = [&](const char *name) {
        p.info = FindPrimitiveType(name);
        p.type = name;
    };
    if (p.type == "cylinder" || p.type == "tube") {
        if (ca[6] < -kFtiny) {
            Warn(p, "negative radius");
            retype(p.type == "cylinder" ? "tube" : "cylinder");
            ca[6] = -ca[6];
        } else if (ca[6] <= kFtiny) {
            Warn(p, "illegal radii");
            return false;
        }
        o->p0 = 0, o->p1 = 3, o->r0 = o->r1 = 6;
    } else {
        const auto sign = [](double r) { return r < -kFtiny ? -1 : r > kFtiny ? 1 : 0; };
        const int sgn0 = sign(ca[6]), sgn1 = sign(ca[7]);
        const bool ring = p.type == "ring";
        if (sgn0 + sgn1 == 0 || (ring && (sgn0 < 0 || sgn1 < 0))) {
            Warn(p, "illegal radii");
            return false;
        }
        if (sgn0 < 0 || sgn1 < 0) {
            Warn(p, "negative radii");
            retype(p.type == "cone" ? "cup" : "cone");
        }
        ca[6] *= sgn0;
        ca[7] *= sgn1;
        if (ca[7] - ca[6] > kFtiny) {
            o->p0 = 0, o->p1 = ring ? 0 : 3, o->r0 = 6, o->r1 = 7;
        } else if (ca[6] - ca[7] > kFtiny) {
            o->p0 = ring ? 0 : 3, o->p1 = 0, o->r0 = 7, o->r1 = 6;
        } else {
            if (ring) {
                Warn(p, "illegal radii");
                return false;
            }
            retype(p.type == "cone" ? "cylinder" : "tube");
            ca.resize(7);
            o->p0 = 0, o->p1 = 3, o->r0 = o->r1 = 6;
        }
    }
    if (p.type == "ring") {
        o->ad = {ca[3], ca[4], ca[5]};
    } else {
        for (int k = 0; k < 3; ++k) o->ad[k] = ca[o->p1 + k] - ca[o->p0 + k];
    }
    if (Normalize(o->ad.data()) == 0.0) {
        Warn(p, "unknown orientation");
        return false;
    }
    return true;
}

void OctreeMaker::PrepareInstance(Object *o) const {
    const Primitive &p = o->p;
    const std::string path = FindOnRaypath(p.sargs[0]);
    if (o->shape == Object::kOctreeInstance) {
        const OctreeInfo in = ReadOctreeBounds(path);
        for (int k = 0; k < 3; ++k) o->cube_org[k] = in.cube_origin[k];
        o->cube_size = in.cube_size;
    } else {
        const MeshCube m = ReadMeshBounds(path);
        for (int k = 0; k < 3; ++k) o->cube_org[k] = m.origin[k];
        o->cube_size = m.size;
    }
    for (size_t i = 1; i < p.sargs.size(); ++i)
        if (!ApplyTransformOption(p.sargs, &i, p.loc, p.type + " '" + p.name + "'", &o->forward))
            ErrorExit(&p.loc,
                      p.type + " '" + p.name + "': unknown transform option '" + p.sargs[i] + "'");
    o->backward = InverseOf(p.sargs, 1);
}

// add2bbox()
void OctreeMaker::AddToBox(const Object &o, V3 *min, V3 *max) const {
    const auto point = [&](const double *v) {
        for (int i = 0; i < 3; ++i) {
            if (v[i] < (*min)[i]) (*min)[i] = v[i];
            if (v[i] > (*max)[i]) (*max)[i] = v[i];
        }
    };
    const auto circle = [&](const double *cent, double rad) {
        for (int i = 0; i < 3; ++i) {
            const double r = std::sqrt(1. - o.ad[i] * o.ad[i]);
            double d = cent[i] + r * rad;
            if (d > (*max)[i]) (*max)[i] = d;
            d = cent[i] - r * rad;
            if (d < (*min)[i]) (*min)[i] = d;
        }
    };
    const std::vector<double> &f = o.p.fargs;
    switch (o.shape) {
        case Object::kSphere:
            for (int i = 0; i < 3; ++i) {
                V3 v{f[0], f[1], f[2]};
                v[i] -= f[3];
                point(v.data());
                v[i] += 2.0 * f[3];
                point(v.data());
            }
            break;
        case Object::kFace:
            for (int j = o.nv; j--;) point(o.Vertex(j));
            break;
        case Object::kCone:
            if (!o.cone_ok) break;
            if (o.p.type != "ring") circle(&f[o.p0], f[o.r0]);
            circle(&f[o.p1], f[o.r1]);
            break;
        case Object::kOctreeInstance:
        case Object::kMeshInstance:
            for (int j = 0; j < 8; ++j) {
                V3 v;
                for (int i = 0; i < 3; ++i)
                    v[i] = o.cube_org[i] + ((j & 1 << i) ? o.cube_size : 0.0);
                point(Apply(o.forward, v.data()).data());
            }
            break;
        case Object::kNone:
            break;
    }
}

int OctreeMaker::Test(Object &o, const Cube &cu) {
    switch (o.shape) {
        case Object::kFace:
            return TestFace(o, cu);
        case Object::kSphere:
            return TestSphere(o, cu);
        case Object::kCone:
            return o.cone_ok ? TestCone(o, cu) : kMiss;
        case Object::kOctreeInstance:
        case Object::kMeshInstance:
            return TestCube(o, cu);
        case Object::kNone:
            break;
    }
    return kMiss;  // sources and modifiers are not in the tree (o_default)
}

// inface(): the crossing test in the plane of the dominant axis, edges counting as inside.
bool InFace(const double *p, const Object &o) {
    int xi = o.ax + 1, yi;
    if (xi >= 3) xi -= 3;
    if ((yi = xi + 1) >= 3) yi -= 3;
    const double x = p[xi], y = p[yi];
    const double *p0 = o.Vertex(o.nv - 1), *p1 = o.Vertex(0);
    int crossings = 0;
    for (int n = o.nv; n--; p0 = p1, p1 += 3) {
        if ((p0[yi] > y) ^ (p1[yi] > y)) {
            const int tst = (p0[xi] > x) + (p1[xi] > x);
            if (tst == 2) {
                ++crossings;
            } else if (tst) {
                const double a = (p0[yi] - y) * (p1[xi] - x), b = (p0[xi] - x) * (p1[yi] - y);
                if (RelativelyEqual(a, b)) return true;
                crossings += (p1[yi] > p0[yi]) ^ (a > b);
            } else if (RelativelyEqual(p0[xi], x) && RelativelyEqual(p1[xi], x)) {
                return true;
            }
        } else if (RelativelyEqual(p0[yi], y) && RelativelyEqual(p1[yi], y) &&
                   ((p0[xi] > x) ^ (p1[xi] > x))) {
            return true;
        }
    }
    return crossings & 1;
}

// o_face(): a vertex inside, all to one side, an edge through, or the cube's diagonal across
// the face.
int OctreeMaker::TestFace(const Object &o, const Cube &cu) const {
    if (o.area == 0.0) return kMiss;
    V3 cumin, cumax;
    for (int j = 0; j < 3; ++j) cumax[j] = (cumin[j] = cu.org[j] - kFtiny) + cu.size + 2.0 * kFtiny;
    int vloc = kAbove | kBelow;
    for (int i = 0; i < o.nv; ++i) {
        const int j = Locate(o.Vertex(i), cumin, cumax);
        if (!j) return kHit;
        vloc &= j;
    }
    if (vloc) return kMiss;
    for (int i = 0; i < o.nv; ++i) {
        const int j = i + 1 < o.nv ? i + 1 : 0;
        const double *a = o.Vertex(i), *b = o.Vertex(j);
        if (Clip({a[0], a[1], a[2]}, {b[0], b[1], b[2]}, cumin, cumax)) return kHit;
    }
    V3 v1, v2;
    for (int j = 0; j < 3; ++j) {
        if (o.norm[j] > 0.0) {
            v1[j] = cumin[j];
            v2[j] = cumax[j];
        } else {
            v1[j] = cumax[j];
            v2[j] = cumin[j];
        }
    }
    const double d1 = Dot(v1.data(), o.norm.data()) - o.offset;
    if (d1 > kFtiny) return kMiss;
    const double d2 = Dot(v2.data(), o.norm.data()) - o.offset;
    if (d2 < -kFtiny) return kMiss;
    for (int j = 0; j < 3; ++j) v1[j] = (v1[j] * d2 - v2[j] * d1) / (d2 - d1);
    return InFace(v1.data(), o) ? kHit : kMiss;
}

// o_sphere(): a negative radius turns the sphere inside out (and is stored so).
int OctreeMaker::TestSphere(Object &o, const Cube &cu) {
    std::vector<double> &fa = o.p.fargs;
    double &rad = fa[3];
    if (rad < -kFtiny) {
        Warn(o.p, "negative radius");
        const char *name = o.p.type == "sphere" ? "bubble" : "sphere";
        o.p.info = FindPrimitiveType(name);
        o.p.type = name;
        rad = -rad;
    } else if (rad <= kFtiny) {
        Warn(o.p, "zero radius");
        o.shape = Object::kNone;  // RADIANCE says so at every cube; once is enough
        return kMiss;
    }
    const double d1 = kRoot3 / 2.0 * cu.size;
    double d2 = cu.size * 0.5;
    V3 v;
    for (int i = 0; i < 3; ++i) v[i] = cu.org[i] + d2 - fa[i];
    d2 = Dot(v.data(), v.data());
    if (d2 > (rad + d1 + kFtiny) * (rad + d1 + kFtiny)) return kMiss;
    if (d1 < rad) {
        if (d2 < (rad - d1 - kFtiny) * (rad - d1 - kFtiny)) return kMiss;
        if (d2 < (rad + kFtiny) * (rad + kFtiny)) return kHit;
    }
    for (int i = 0; i < 3; ++i) {
        if (fa[i] < cu.org[i])
            v[i] = cu.org[i] - fa[i];
        else if (fa[i] > cu.org[i] + cu.size)
            v[i] = fa[i] - (cu.org[i] + cu.size);
        else
            v[i] = 0;
    }
    return Dot(v.data(), v.data()) <= (rad + kFtiny) * (rad + kFtiny) ? kHit : kMiss;
}

// o_cone() (STRICT): the cone's segment nearest the cube's centre against the cube's bounding
// sphere, then clipped to the cube, then the cube's eight children down to the resolution.
int OctreeMaker::TestCone(const Object &o, const Cube &cu) const {
    const std::vector<double> &ca = o.p.fargs;
    double r = cu.size * 0.5;
    V3 p;
    for (int i = 0; i < 3; ++i) p[i] = cu.org[i] + r;
    r *= kRoot3;
    // findcseg(): the direction from the axis to p, and the segment of the cone along it.
    V3 v;
    for (int i = 0; i < 3; ++i) v[i] = p[i] - ca[o.p0 + i];
    const double d = Dot(v.data(), o.ad.data());
    for (int i = 0; i < 3; ++i) v[i] -= d * o.ad[i];
    if (Normalize(v.data()) != 0.0) {
        V3 ep0, ep1;
        for (int i = 0; i < 3; ++i) {
            ep0[i] = ca[o.r0] * v[i] + ca[o.p0 + i];
            ep1[i] = ca[o.r1] * v[i] + ca[o.p1 + i];
        }
        if (Dist2Segment(p.data(), ep0.data(), ep1.data()) > (r + kFtiny) * (r + kFtiny))
            return kMiss;
        V3 cumin, cumax;
        for (int i = 0; i < 3; ++i) cumax[i] = (cumin[i] = cu.org[i]) + cu.size;
        if (Clip(ep0, ep1, cumin, cumax)) return kHit;
    }
    Cube kid;
    kid.size = cu.size * 0.5;
    if (kid.size < min_cube_size_) return kHit;
    for (int j = 0; j < 8; ++j) {
        for (int i = 0; i < 3; ++i) kid.org[i] = cu.org[i] + ((1 << i & j) ? kid.size : 0.0);
        if (TestCone(o, kid)) return kHit;
    }
    return kMiss;
}

// o_cube(): an instance's (or mesh's) cube, placed, against ours; inside whole gives kIn.
int OctreeMaker::TestCube(const Object &o, const Cube &cu) const {
    static const int kStart[4] = {0, 3, 5, 6};
    V3 cumin, cumax;
    for (int j = 0; j < 3; ++j) cumax[j] = (cumin[j] = o.cube_org[j]) + o.cube_size;
    int vloc = kAbove | kBelow, out = 0;
    for (int i = 0; i < 8; ++i) {
        V3 v;
        for (int j = 0; j < 3; ++j) v[j] = cu.org[j] + ((i & 1 << j) ? cu.size : 0.0);
        const int loc = Locate(Apply(o.backward, v.data()).data(), cumin, cumax);
        if (loc) ++out;
        vloc &= loc;
    }
    if (out == 0) return kIn;
    if (out < 8) return kHit;
    if (vloc) return kMiss;
    for (int j = 0; j < 3; ++j) cumax[j] = (cumin[j] = cu.org[j]) + cu.size;
    vloc = kAbove | kBelow;
    V3 vert[8];
    for (int i = 0; i < 8; ++i) {
        V3 v;
        for (int j = 0; j < 3; ++j) v[j] = o.cube_org[j] + ((i & 1 << j) ? o.cube_size : 0.0);
        vert[i] = Apply(o.forward, v.data());
        const int loc = Locate(vert[i].data(), cumin, cumax);
        if (!loc) return kHit;
        vloc &= loc;
    }
    if (vloc) return kMiss;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 3; ++j)
            if (Clip(vert[kStart[i]], vert[kStart[i] ^ 1 << j], cumin, cumax)) return kHit;
    return kMiss;
}

// oconv's addobject()
void OctreeMaker::AddObject(Cube *cu, int obj) {
    const int inc = Test(objects_[obj], *cu);
    if (inc == kMiss) return;
    if (cu->tree >= 0) {
        Cube kid;
        kid.size = cu->size * 0.5;
        for (int i = 0; i < 8; ++i) {
            kid.tree = nodes_.branches[cu->tree][i];
            for (int j = 0; j < 3; ++j) kid.org[j] = cu->org[j] + (((1 << j) & i) ? kid.size : 0.0);
            AddObject(&kid, obj);
            nodes_.branches[cu->tree][i] = kid.tree;
        }
        return;
    }
    if (cu->tree == -1) {
        cu->tree = FullNode({&obj, 1});
        return;
    }
    AddToFull(cu, obj, inc);
}

// add2full(): a set grows until it holds set_limit objects (or the cube reaches the resolution,
// or the object fills the cube); then the cube splits, its objects re-added to the children in
// RADIANCE's order: surfaces, the new object, volumes partly in, volumes wholly in.
void OctreeMaker::AddToFull(Cube *cu, int obj, int inc) {
    std::array<int, kMaxSet + 1> set;  // a copy: the table grows as the children are filled
    const std::span<const int> old = sets_.Get(-cu->tree - 2);
    const int n = static_cast<int>(old.size());
    std::copy(old.begin(), old.end(), set.begin());
    const double kid_size = cu->size * 0.5;
    if (inc == kIn || n < options_.set_limit ||
        kid_size < (n < kMaxSet ? min_cube_size_ : min_cube_size_ / 256.0)) {
        if (n >= kMaxSet)
            ErrorExit(&objects_[obj].p.loc, "set overflow in addobject (" + objects_[obj].p.name +
                                                "): too many objects in one place");
        int *end = set.begin() + n, *at = std::upper_bound(set.begin(), end, obj);
        std::copy_backward(at, end, end + 1);
        *at = obj;
        cu->tree = FullNode({set.data(), static_cast<size_t>(n + 1)});
        return;
    }
    std::array<bool, kMaxSet> volume, inside{};
    for (int j = 0; j < n; ++j) {
        const Object &o = objects_[set[j]];
        volume[j] = o.shape == Object::kOctreeInstance || o.shape == Object::kMeshInstance;
        if (volume[j]) inside[j] = Test(objects_[set[j]], *cu) == kIn;
    }
    const int node = static_cast<int>(nodes_.branches.size());
    nodes_.branches.emplace_back();
    for (int i = 0; i < 8; ++i) {
        Cube kid;
        kid.size = kid_size;
        for (int j = 0; j < 3; ++j) kid.org[j] = cu->org[j] + (((1 << j) & i) ? kid_size : 0.0);
        for (int j = 0; j < n; ++j)
            if (!volume[j]) AddObject(&kid, set[j]);
        AddObject(&kid, obj);
        for (int j = 0; j < n; ++j)
            if (volume[j] && !inside[j]) AddObject(&kid, set[j]);
        for (int j = 0; j < n; ++j)
            if (inside[j]) AddObject(&kid, set[j]);
        nodes_.branches[node][i] = kid.tree;
    }
    cu->tree = node;
}

// combine(): a branch whose eight children are the same leaf becomes that leaf.
int OctreeMaker::Combine(int node) {
    if (node < 0) return node;
    int result = nodes_.branches[node][0] = Combine(nodes_.branches[node][0]);
    for (int i = 1; i < 8; ++i)
        if ((nodes_.branches[node][i] = Combine(nodes_.branches[node][i])) != result) result = node;
    return result;
}

void OctreeMaker::WriteTree(int node, RadianceBinaryOutput *out) const {
    if (node >= 0) {
        out->Byte(2);
        for (int kid : nodes_.branches[node]) WriteTree(kid, out);
    } else if (node < -1) {
        out->Byte(1);
        const std::span<const int> set = sets_.Get(-node - 2);
        out->Int(static_cast<long>(set.size()), kObjectSize);
        for (int o : set) out->Int(o, kObjectSize);
    } else {
        out->Byte(0);
    }
}

// writescene(): the type table, then each object.
void OctreeMaker::WriteObjects(RadianceBinaryOutput *out) const {
    for (const PrimitiveType &t : PrimitiveTypes()) out->String(t.name);
    out->String("");
    for (const Object &o : objects_) {
        out->Int(PrimitiveTypeIndex(o.p.info), 1);
        out->Int(o.modifier, kObjectSize);
        out->String(o.p.name);
        out->Int(static_cast<long>(o.p.sargs.size()), 2);
        for (const std::string &s : o.p.sargs) out->String(s);
        out->Int(static_cast<long>(o.p.fargs.size()), 2);
        for (double f : o.p.fargs) out->Real(f);
    }
    out->Int(-1, 1);
}

}  // namespace

void MakeOctree(const std::vector<std::string> &files, const OconvOptions &options,
                const std::string &command_line,
                const std::function<void(std::string_view)> &write) {
    OctreeMaker(options).Make(files, command_line, write);
}

std::string MakeOctree(const std::vector<std::string> &files, const OconvOptions &options,
                       const std::string &command_line) {
    std::string octree;
    MakeOctree(files, options, command_line, [&](std::string_view s) { octree += s; });
    return octree;
}

}  // namespace dayflux
