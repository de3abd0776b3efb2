// Virtual light sources: the images of light sources in planar mirrors, which RADIANCE's direct
// calculation samples through the mirror (its -dr relays; virtuals.c, m_mirror.c). A shadow ray
// aimed at an image must meet the mirror, which turns it toward the source imaged.
#pragma once

#include <vector>

#include "raytrace/materials.h"
#include "scene/flatten.h"

namespace dayflux {

// A mirror polygon or ring that relays sources: its plane (normal . x = offset, the normal on
// the reflecting side), a disc about it (RADIANCE's getdisk()) and its outline.
struct MirrorRelay {
    int object = -1;
    double normal[3]{}, offset = 0;
    // The disc: the vertices' centre (a ring's), and the farthest vertex's distance squared.
    double centre[3]{}, radius2 = 0;
    std::vector<double> polygon;  // vertices, 3 numbers each (empty for a ring)
    double inner2 = 0;            // a ring's inner radius squared (its outer one is radius2)
    // Whether the ray from org along dir meets the mirror: RADIANCE's srcvalue() asks the relay
    // alone, before any shadow ray is traced.
    bool Meets(const double org[3], const double dir[3]) const;
};

// The relays among a scene's own objects (mirrors on polygons and rings; a mirror on another
// surface gets RADIANCE's warning when warn is set) and the images of sources in them, and of
// images in other mirrors, up to `depth` mirrors deep (-dr), appended to sources as RADIANCE's
// markvirtuals() appends them.
std::vector<MirrorRelay> AddMirrorImages(const FlatScene &scene, const SceneMaterials &table,
                                         int depth, bool warn, std::vector<Source> *sources);

}  // namespace dayflux
