// RADIANCE scene primitives: "modifier type identifier / strings / integers / reals", the type
// table with each type's kind and argument rules, and a scene as an ordered list of primitives
// whose modifiers are resolved to the definitions in force where they were used.
#pragma once

#include <array>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "util/errors.h"

namespace dayflux {

enum class PrimitiveKind {
    kSurface,
    kMaterial,
    kLight,
    kPattern,
    kTexture,
    kMixture,
    kVolume,
    kAlias
};

struct PrimitiveType {
    const char *name;
    PrimitiveKind kind;
};

// Every type RADIANCE knows (otypes.h), with our classification; nullptr if name is unknown.
const PrimitiveType *FindPrimitiveType(const std::string &name);
// All of them, in RADIANCE's order (otypes.h's INIT_OTYPE), whose indices octrees store.
std::span<const PrimitiveType> PrimitiveTypes();
int PrimitiveTypeIndex(const PrimitiveType *type);

// A 4x4 affine transform (row vectors, as RADIANCE's xf: p' = p M) with its uniform scale.
struct Transform {
    std::array<double, 16> m{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    double scale = 1;
    bool identity = true;
    // The options that made it, as given ("-rz" "90" ...), for the text xform writes into a
    // function's or instance's string arguments.
    std::vector<std::string> words;
    Transform Then(const Transform &next) const;  // this, followed by next
    void Apply(const double p[3], double out[3]) const;
    void ApplyDirection(const double d[3], double out[3]) const;  // no translation
    // A mirror image (negative determinant): xform turns surfaces over to keep their front side.
    bool Mirrors() const;
};

// If args[*i] is one of xform's transform options (-t x y z, -rx/-ry/-rz deg, -s f, -mx/-my/-mz,
// and "-i 1", the group marker xform writes), applies it after xf, moves *i past its numbers and
// returns true; else returns false. who
// names the primitive or command for the error a missing or bad number gives at loc.
bool ApplyTransformOption(const std::vector<std::string> &args, size_t *i, const FileLoc &loc,
                          const std::string &who, Transform *xf);

struct Primitive {
    int modifier = -1;  // index of the modifier primitive, -1 for void
    std::string modifier_name;
    std::string type;
    const PrimitiveType *info = nullptr;
    std::string name;
    std::vector<std::string> sargs;
    std::vector<double> fargs;
    Transform xf;  // from xform commands the primitive came through
    // Those commands one by one, innermost first: each "!xform" (identity or not) rewrote the
    // primitive's numbers in its own precision (scene/xform_text.h). Shared by all it read.
    std::shared_ptr<const std::vector<Transform>> xforms;
    FileLoc loc;
};

struct Scene {
    std::vector<Primitive> objects;
    // The latest definition named `name` (as a modifier is looked up), -1 if none.
    int FindModifier(const std::string &name) const;
};

}  // namespace dayflux
