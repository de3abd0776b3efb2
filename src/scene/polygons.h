// Triangulation of RADIANCE polygons: convex, concave, and polygons with holes joined to the
// outline by a seam (an edge walked out and back), covering exactly the region RADIANCE's
// crossing-number inside test gives.
#pragma once

#include <array>
#include <vector>

namespace dayflux {

using Vec3 = std::array<double, 3>;

// Newell's normal of a polygon (not normalised; its length is twice the area).
Vec3 PolygonNormal(const std::vector<Vec3> &v);
// Triangles as index triples into v, each wound like the polygon. Degenerate polygons give none.
std::vector<std::array<int, 3>> TriangulatePolygon(const std::vector<Vec3> &v);
// RADIANCE's notion of inside for a point in the polygon's plane (even-odd crossings).
bool InsidePolygon(const std::vector<Vec3> &v, const Vec3 &p);

}  // namespace dayflux
