// A scene as the estimator core reads it (raytrace/core/tables.h): its surfaces, sources,
// analytic shapes, triangles' surfaces, mirrors and BSDF data, packed once from the flattened
// scene and its materials (raytrace/materials.h). Both drivers trace these tables: the CPU's
// from memory, the GPU's uploaded into storage buffers. Coordinates are recentred on the
// scene's centre (its bounding box's), so that a scene far from the origin keeps its precision
// in float; the core adds the centre back where bins and patterns see positions.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "raytrace/contrib.h"
#include "raytrace/core/parameters.h"
#include "raytrace/core/tables.h"
#include "raytrace/klems.h"
#include "raytrace/materials.h"
#include "scene/flatten.h"
#include "scene/patterns.h"

namespace dayflux {

struct PackedScene {
    double centre[3] = {0, 0, 0};
    double extent = 0;                            // the bounding box's largest side
    std::vector<core::PackedTriangle> triangles;  // per FlatScene triangle
    std::vector<core::PackedSurface> surfaces;
    std::vector<core::PackedShape> shapes;    // the analytic surfaces, but for distant sources
    std::vector<int> shape_of;                // FlatScene shape -> index in shapes (-1: a source)
    std::vector<int> flat_shape;              // and back
    std::vector<core::PackedSource> sources;  // the scene's, then their images in mirrors
    std::vector<core::vec4> relays;           // the mirrors those are seen through
    std::vector<float> klems;                 // BSDF data (tables.h's kKlems* layout)
    std::vector<core::ivec4> tracked;   // per tracked modifier: column, bins, bin function (0)
    std::vector<core::vec4> receivers;  // what -asub samples directly (tables.h), with -asub only
    // The patterns (brightfunc, colorfunc, mixfunc coefficients, variable BSDF frames) the
    // tables name by index.
    std::vector<const PatternFunction *> patterns;
    int ndirect = 0;  // sources sampled with shadow rays (not glow)
    int columns = 0;  // of a record: all tracked modifiers' bins
    // What the scene needs of the core (its DAYFLUX_* features), and how deep its mixfuncs nest.
    bool bsdf = false, dielectric = false, local_sources = false, mirror_images = false;
    bool inside = false;      // antimatter with a material for its inside
    bool aperture = false;    // an aBSDF (a BSDF too)
    int mix_depth = 0;        // mixfuncs of mixfuncs, as many levels deep
    std::string mix_deepest;  // the object whose material nests them so
};

// A Klems BSDF's scattering in the core's layout (tables.h's kKlems*), appended to klems;
// returns its offset. The material's own fields (thickness, up vector, diffuse colours) are 0,
// its frame's patterns -1.
int PackKlemsData(const KlemsScattering &k, std::vector<float> *klems);

// Packs scene (whose materials table resolved `tracked`); mirrors relay sources up to -dr
// deep. Reports bad input (a BSDF whose data outgrows float offsets) as errors.
PackedScene PackScene(const FlatScene &scene, const SceneMaterials &table,
                      const std::vector<TrackedModifier> &tracked, const ContribOptions &options);

// The run's parameters as the core reads them (core/parameters.h), in a driver's precision:
// CpuParameters or GpuParameters.
template <typename Parameters>
Parameters MakeParameters(const PackedScene &packed, const ContribOptions &o) {
    using Real = decltype(Parameters::lw);
    Parameters p{};
    p.centre_x = static_cast<Real>(packed.centre[0]);
    p.centre_y = static_cast<Real>(packed.centre[1]);
    p.centre_z = static_cast<Real>(packed.centre[2]);
    p.centre_rest_x = static_cast<Real>(packed.centre[0] - p.centre_x);
    p.centre_rest_y = static_cast<Real>(packed.centre[1] - p.centre_y);
    p.centre_rest_z = static_cast<Real>(packed.centre[2] - p.centre_z);
    p.lw = static_cast<Real>(o.limit_weight);
    p.dj = static_cast<Real>(o.source_jitter);
    p.st = static_cast<Real>(o.specular_threshold);
    p.ss = static_cast<Real>(o.specular_jitter);
    p.ds = static_cast<Real>(o.source_size_ratio);
    p.ab = o.ambient_bounces;
    p.ad = o.ambient_divisions;
    p.lr = o.limit_reflections;
    p.asub = o.ambient_subsamples;
    p.irradiance = o.irradiance ? 1 : 0;
    p.first_hit = o.first_hit_irradiance ? 1 : 0;
    p.contributions = o.contributions ? 1 : 0;
    p.nsources = static_cast<int>(packed.sources.size());
    p.ndirect = packed.ndirect;
    p.seed = static_cast<uint32_t>(o.seed ^ (o.seed >> 32));
    return p;
}

// The GPU core's stack of mixfunc sides waiting to be shaded (MIX_STACK; trees nested n deep
// need n + 1), and the most specular samples per hit its ray stack holds (-ss).
constexpr int kGpuMixStack = 8;
constexpr double kGpuMaxSpecularSamples = 16;

// What the GPU's core cannot trace in this run ("" if nothing): -ss above 16 (its ray stack),
// mixfuncs nested deeper than its stack of waiting sides. Decided before anything is compiled.
std::string UnsupportedOnGpu(const PackedScene &packed, const ContribOptions &options);

}  // namespace dayflux
