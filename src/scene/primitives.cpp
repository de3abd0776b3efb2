#include "scene/primitives.h"

#include <cmath>
#include <cstring>

#include "util/strings.h"

namespace dayflux {

namespace {
using K = PrimitiveKind;
constexpr PrimitiveType kTypes[] = {
    {"polygon", K::kSurface},     {"cone", K::kSurface},        {"sphere", K::kSurface},
    {"texfunc", K::kTexture},     {"ring", K::kSurface},        {"cylinder", K::kSurface},
    {"instance", K::kVolume},     {"cup", K::kSurface},         {"bubble", K::kSurface},
    {"tube", K::kSurface},        {"mesh", K::kVolume},         {"alias", K::kAlias},
    {"plastic", K::kMaterial},    {"metal", K::kMaterial},      {"glass", K::kMaterial},
    {"trans", K::kMaterial},      {"dielectric", K::kMaterial}, {"plastic2", K::kMaterial},
    {"metal2", K::kMaterial},     {"trans2", K::kMaterial},     {"interface", K::kMaterial},
    {"plasfunc", K::kMaterial},   {"metfunc", K::kMaterial},    {"brightfunc", K::kPattern},
    {"brightdata", K::kPattern},  {"brighttext", K::kPattern},  {"colorpict", K::kPattern},
    {"glow", K::kLight},          {"source", K::kSurface},      {"light", K::kLight},
    {"illum", K::kLight},         {"spotlight", K::kLight},     {"mist", K::kMaterial},
    {"mirror", K::kMaterial},     {"transfunc", K::kMaterial},  {"BRTDfunc", K::kMaterial},
    {"BSDF", K::kMaterial},       {"aBSDF", K::kMaterial},      {"plasdata", K::kMaterial},
    {"metdata", K::kMaterial},    {"transdata", K::kMaterial},  {"colorfunc", K::kPattern},
    {"antimatter", K::kMaterial}, {"colordata", K::kPattern},   {"colortext", K::kPattern},
    {"texdata", K::kTexture},     {"mixfunc", K::kMixture},     {"mixdata", K::kMixture},
    {"mixtext", K::kMixture},     {"mixpict", K::kMixture},     {"prism1", K::kMaterial},
    {"prism2", K::kMaterial},     {"ashik2", K::kMaterial},
};
}  // namespace

std::span<const PrimitiveType> PrimitiveTypes() { return kTypes; }

int PrimitiveTypeIndex(const PrimitiveType *type) {
    CHECK(type >= std::begin(kTypes) && type < std::end(kTypes));
    return static_cast<int>(type - std::begin(kTypes));
}

const PrimitiveType *FindPrimitiveType(const std::string &name) {
    for (const PrimitiveType &t : kTypes)
        if (name == t.name) return &t;
    return nullptr;
}

Transform Transform::Then(const Transform &n) const {
    Transform r = identity ? n : *this;
    if (!identity && !n.identity) {
        for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j) {
                double s = 0;
                for (int k = 0; k < 4; ++k) s += m[4 * i + k] * n.m[4 * k + j];
                r.m[4 * i + j] = s;
            }
        r.scale = scale * n.scale;
    }
    r.words = words;
    r.words.insert(r.words.end(), n.words.begin(), n.words.end());
    return r;
}

bool Transform::Mirrors() const {
    if (identity) return false;
    const double det = m[0] * (m[5] * m[10] - m[6] * m[9]) - m[1] * (m[4] * m[10] - m[6] * m[8]) +
                       m[2] * (m[4] * m[9] - m[5] * m[8]);
    return det < 0;
}

void Transform::Apply(const double p[3], double out[3]) const {
    for (int j = 0; j < 3; ++j)
        out[j] = p[0] * m[j] + p[1] * m[4 + j] + p[2] * m[8 + j] + m[12 + j];
}

void Transform::ApplyDirection(const double d[3], double out[3]) const {
    for (int j = 0; j < 3; ++j) out[j] = d[0] * m[j] + d[1] * m[4 + j] + d[2] * m[8 + j];
}

int Scene::FindModifier(const std::string &name) const {
    for (int i = static_cast<int>(objects.size()); i--;)
        if (objects[i].name == name && objects[i].info->kind != PrimitiveKind::kSurface &&
            objects[i].info->kind != PrimitiveKind::kVolume)
            return i;
    return -1;
}

bool ApplyTransformOption(const std::vector<std::string> &args, size_t *i, const FileLoc &loc,
                          const std::string &who, Transform *xf) {
    const std::string &a = args[*i];
    auto number = [&]() {
        double v;
        if (*i + 1 >= args.size() || !ParseNumber(args[*i + 1], &v))
            ErrorExit(&loc, who + ": option " + a + " needs a number");
        // The geometry would vanish or fill space: refused where the scene reader refuses a
        // NaN among a primitive's own arguments.
        if (!(std::fabs(v) <= 1e12))
            ErrorExit(&loc, who + ": option " + a + ": '" + args[*i + 1] + "' is " +
                                (std::isfinite(v) ? "out of range" : "not a number"));
        ++*i;
        return v;
    };
    Transform t;
    t.identity = false;
    const size_t first = *i;
    if (a == "-i") {
        // xform's iteration count: "-i 1" only closes a group (xform writes it before the
        // options it adds to an instance); more repetitions are arrays, not supported here.
        if (*i + 1 >= args.size() || args[*i + 1] != "1")
            ErrorExit(&loc, who + ": -i with a count other than 1 (arrays) is not supported");
        ++*i;
        xf->words.insert(xf->words.end(), {"-i", "1"});
        return true;
    }
    if (a == "-t") {
        for (int k = 0; k < 3; ++k) t.m[12 + k] = number();
    } else if (a == "-rx" || a == "-ry" || a == "-rz") {
        const double ang = number() * (M_PI / 180.), c = std::cos(ang), s = std::sin(ang);
        const int ax = a[2] - 'x', u = (ax + 1) % 3, w = (ax + 2) % 3;  // x->y for z, ...
        t.m[4 * u + u] = c, t.m[4 * u + w] = s, t.m[4 * w + u] = -s, t.m[4 * w + w] = c;
    } else if (a == "-s") {
        const double s = number();
        if (s == 0) Warning(&loc, who + ": -s 0 shrinks everything after it to a point");
        for (int k = 0; k < 3; ++k) t.m[5 * k] = s;
        t.scale = s;
    } else if (a == "-mx" || a == "-my" || a == "-mz") {
        t.m[5 * (a[2] - 'x')] = -1;
    } else {
        return false;
    }
    t.words.assign(args.begin() + static_cast<long>(first),
                   args.begin() + static_cast<long>(*i) + 1);
    *xf = xf->Then(t);
    return true;
}

}  // namespace dayflux
