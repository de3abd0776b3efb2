// What a scene's modifiers mean to the integrators: each surface's material (RADIANCE's plastic,
// metal, trans, glass, mirror, glow, light, mixfunc, BSDF, with brightfunc/colorfunc patterns), the
// modifier tracked by -m that it counts for, and the distant sources. Both backends' integrators
// read this one table, so they model the same materials and refuse the same things.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "raytrace/contrib.h"
#include "raytrace/core/sampling.h"
#include "raytrace/klems.h"
#include "scene/flatten.h"
#include "scene/patterns.h"

namespace dayflux {

constexpr double kTiny = core::kTiny;  // RADIANCE's FTINY

using RGB = std::array<double, 3>;

inline double Max3(const RGB &c) { return std::max({c[0], c[1], c[2]}); }

// Two unit vectors perpendicular to n and to each other (the core's, for the host's set-up of
// sources).
inline void Tangents(const double n[3], double u[3], double v[3]) {
    core::real3 a, b;
    core::Tangents(core::real3(n[0], n[1], n[2]), a, b);
    for (int k = 0; k < 3; ++k) u[k] = a[k], v[k] = b[k];
}

struct MixInfo;
struct BsdfInfo;

// How many modifiers antimatter with a material for its inside may clip in all: a ray carries
// a count of penetrations for each.
constexpr int kInsideCounters = 16;

struct Material {
    enum Kind {
        kBlack,
        kDiffuse,
        kGlass,
        kDielectric,
        kMirror,
        kGlow,
        kLight,
        kMix,
        kBsdf,
        kIllum,
        kAntimatter
    } kind = kBlack;
    RGB color{0, 0, 0};
    double spec = 0;              // plastic/metal/trans specularity
    double trans = 0, tspec = 0;  // trans: transmissivity and its specular fraction
    double alpha2 = 0;            // roughness squared (0: pure specular)
    bool metal = false;
    bool transparent = false;  // trans and glass: -i passes through them (RADIANCE's istransp)
    double rindex = 1.52;      // glass; dielectric: n + Hartmann constant / 500 nm
    const PatternFunction *pattern = nullptr;  // brightfunc/colorfunc modifying the colour
    const MixInfo *mix = nullptr;              // mixfunc: the two materials and the coefficient
    const BsdfInfo *bsdf = nullptr;            // BSDF: its data and arguments
    // illum: what rays not aimed at it see (null: void); mirror: its substitute; antimatter: what
    // the inside of the cut looks like (m_clip()'s first modifier; null: void)
    const Material *alternate = nullptr;
    bool mirror_alternate = false;  // mirror: it names one (m_mirror()'s substitute)
    uint64_t clip_mask = 0;  // antimatter: the modifiers it clips (SceneMaterials::ClipMaskOf*)
    uint32_t inside_counters = 0;  // antimatter with an inside: the counters of those modifiers
    // spotlight (a light): the cone's solid angle (0: not a spot), its axis, the focus distance.
    double spot_size = 0;
    std::array<double, 3> spot_aim{0, 0, 0};
    double spot_flen = 0;
    // RADIANCE's spotout() for a local spot: a direction toward the source outside the cone
    // (about aim: the spot's axis, or its mirror image's).
    bool SpotOut(const double dir[3], const double *aim) const {
        return spot_size > 0 &&
               spot_size < 2. * M_PI * (1. + aim[0] * dir[0] + aim[1] * dir[1] + aim[2] * dir[2]);
    }
    bool SpotOut(const double dir[3]) const { return SpotOut(dir, spot_aim.data()); }
};

// A mixfunc: foreground and background (void: transparent) and the function mixing them.
struct MixInfo {
    Material fore, back;
    bool is_void[2] = {false, false};
    std::unique_ptr<PatternFunction> coef;
};

// A BSDF material (RADIANCE's MAT_BSDF with Klems data): the scattering data, shared by the
// materials that name the same file; the thickness and up vector, expressions evaluated per hit
// (as a brightfunc and a colorfunc would be); the diffuse colours its real arguments add.
struct BsdfInfo {
    std::shared_ptr<const KlemsScattering> klems;
    std::unique_ptr<PatternFunction> thickness, up;
    RGB front_reflection{0, 0, 0}, back_reflection{0, 0, 0}, transmission{0, 0, 0};
    bool proxy = false;     // a thickness other than "0" (RADIANCE's isBSDFproxy)
    bool aperture = false;  // aBSDF: a peak about the straight-through direction passes unscattered
    std::string name;
};

// A light source direct() samples: distant (`source` with light, or glow: skipped), or local, a
// polygon, ring or sphere with a light or illum material (RADIANCE's SRCREC).
struct Source {
    enum Shape { kDistant, kFlat, kSphere, kCylinder } shape = kDistant;
    double dir[3];       // distant: toward the source
    double solid_angle;  // distant: RADIANCE's ss2 = 2 pi (1 - cos(half angle))
    int object;
    bool skip;  // glow: reached only by rays that find nothing else
    bool weak;  // illum or glow (RADIANCE's weaksrcmat(): an illum in front passes its rays)
    RGB colour;
    double u[3], v[3];  // half-sides of the square of area ss2 that -dj jitters over (setflatss)
    // Local sources: centre, normal (flat), half-size vectors ss[SU], ss[SV], ss[SW], area
    // (flat) or pi r^2 (sphere), and whether the shape is round (RADIANCE's SCIR).
    double loc[3], norm[3], ss[3][3];
    double area = 0;
    bool circular = false;
    bool turned = false;  // ss is setflatss()'s square (a cylinder's SW and SV), turned at random
    double axis[3] = {0, 0, 0};  // a cylinder's unit axis
    double radius = 0;           // and its radius
    // An image of a source in a mirror (RADIANCE's virtual source, -dr): object is the mirror,
    // relay its index among the relays (else -1), next the source the image is of, emitter the
    // object whose material gives the light, spot_aim a spotlight's axis mirrored likewise.
    int relay = -1, next = -1, emitter = -1;
    double spot_aim[3] = {0, 0, 0};
};

class SceneMaterials {
  public:
    // Resolves every surface's modifier (errors, with file and line, for what is not traced).
    SceneMaterials(const FlatScene &scene, const std::vector<TrackedModifier> &tracked);

    const Material &OfObject(int object) const { return materials_[object]; }
    int TrackedOfObject(int object) const { return tracked_of_object_[object]; }
    // A RADIANCE mesh's own material (FlatScene::triangle_material), tracked by its name.
    const Material &OfMeshMaterial(int mat) const { return by_modifier_.at(mat); }
    int TrackedOfMeshMaterial(int mat) const { return tracked_of_mesh_material_.at(mat); }
    const std::vector<Source> &Sources() const { return sources_; }
    // The antimatter bit of an object's own modifier (or a mesh material), 0 if none clips it.
    uint64_t ClipMaskOfObject(int object) const { return clip_of_object_[object]; }
    uint64_t ClipMaskOfMeshMaterial(int mat) const {
        auto it = clip_bits_.find(mat);
        return it == clip_bits_.end() ? 0 : uint64_t{1} << it->second;
    }

    // The penetration counter (< kInsideCounters) of a clip bit that an antimatter with a
    // material for its inside names, or -1.
    int InsideCounterOfClipMask(uint64_t mask) const {
        return mask ? inside_counter_of_bit_[__builtin_ctzll(mask)] : -1;
    }

  private:
    int TrackedIndex(const std::string &modifier) const;
    void CheckSourceEmits(int object) const;
    void WarnOfUnusedModifiers() const;
    const Material &Resolved(int mod, std::vector<int> &pattern_of);
    void AddLocalSource(int object);
    // RADIANCE's lastmod(): the modifier named name defined before object `before`, or -1;
    // FindModifier() makes -1 an error.
    int LastModifier(int before, const std::string &name) const;
    int FindModifier(int before, const std::string &name, const FileLoc &loc) const;
    Material Resolve(int mod, std::vector<int> &pattern_of);

    const FlatScene &scene_;
    std::vector<TrackedModifier> tracked_;
    std::vector<Material> materials_;      // per scene object (surfaces: their material)
    std::vector<int> tracked_of_object_;   // tracked modifier whose name is the object's modifier
    std::map<int, Material> by_modifier_;  // each modifier resolved once (stable references)
    std::map<int, int> tracked_of_mesh_material_;
    std::vector<std::unique_ptr<PatternFunction>> patterns_;
    std::vector<std::unique_ptr<MixInfo>> mixes_;
    std::vector<std::unique_ptr<BsdfInfo>> bsdfs_;
    std::map<std::string, std::shared_ptr<const KlemsScattering>> klems_by_path_;
    std::vector<Source> sources_;
    std::map<int, int> clip_bits_;          // modifier clipped by some antimatter -> its bit
    std::vector<uint64_t> clip_of_object_;  // per object: its modifier's bit (or 0)
    std::array<int8_t, 64> inside_counter_of_bit_;  // filled with -1 first
    int inside_counters_ = 0;
};

}  // namespace dayflux
