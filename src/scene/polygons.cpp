#include "scene/polygons.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace dayflux {

namespace {

struct P2 {
    double x, y;
};

// Projects onto the coordinate plane most nearly parallel to the polygon, keeping its winding
// counter-clockwise when seen along the normal.
std::vector<P2> Project(const std::vector<Vec3> &v, const Vec3 &n) {
    int ax = 0;
    for (int k = 1; k < 3; ++k)
        if (std::fabs(n[k]) > std::fabs(n[ax])) ax = k;
    const int u = (ax + 1) % 3, w = (ax + 2) % 3;
    std::vector<P2> p(v.size());
    for (size_t i = 0; i < v.size(); ++i) p[i] = {v[i][u], v[i][w]};
    if (n[ax] < 0)
        for (P2 &q : p) q.x = -q.x;
    return p;
}

double Cross(const P2 &a, const P2 &b, const P2 &c) {
    return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

bool Same(const P2 &a, const P2 &b) { return a.x == b.x && a.y == b.y; }

// Strictly inside triangle abc (counter-clockwise), or on an edge but not at a corner.
bool InTriangle(const P2 &p, const P2 &a, const P2 &b, const P2 &c) {
    if (Same(p, a) || Same(p, b) || Same(p, c)) return false;
    return Cross(a, b, p) >= 0 && Cross(b, c, p) >= 0 && Cross(c, a, p) >= 0;
}

}  // namespace

Vec3 PolygonNormal(const std::vector<Vec3> &v) {
    Vec3 n{0, 0, 0};
    for (size_t i = 0; i < v.size(); ++i) {
        const Vec3 &a = v[i], &b = v[(i + 1) % v.size()];
        n[0] += (a[1] - b[1]) * (a[2] + b[2]);
        n[1] += (a[2] - b[2]) * (a[0] + b[0]);
        n[2] += (a[0] - b[0]) * (a[1] + b[1]);
    }
    return n;
}

std::vector<std::array<int, 3>> TriangulatePolygon(const std::vector<Vec3> &v) {
    std::vector<std::array<int, 3>> tris;
    const int n = static_cast<int>(v.size());
    if (n < 3) return tris;
    const Vec3 normal = PolygonNormal(v);
    if (normal[0] == 0 && normal[1] == 0 && normal[2] == 0) return tris;
    if (n == 3) return {{0, 1, 2}};
    const std::vector<P2> p = Project(v, normal);
    std::vector<int> ring(n);
    std::iota(ring.begin(), ring.end(), 0);
    auto corner = [&](size_t k) {
        const size_t m = ring.size();
        return std::array<int, 3>{ring[(k + m - 1) % m], ring[k], ring[(k + 1) % m]};
    };
    // Ear clipping. Zero-area corners (collinear points, the tips of seams) are dropped without a
    // triangle; vertices at the same place as an ear's corners (the two sides of a seam) do not
    // block it.
    while (ring.size() > 3) {
        const size_t m = ring.size();
        size_t chosen = m;
        bool emit = false;
        for (size_t k = 0; k < m && chosen == m; ++k) {
            const auto [a, b, c] = corner(k);
            const double area = Cross(p[a], p[b], p[c]);
            if (area == 0) {
                chosen = k;
                continue;
            }
            if (area < 0) continue;
            bool clear = true;
            for (size_t q = 0; clear && q < m; ++q) {
                const int o = ring[q];
                if (o != a && o != b && o != c && InTriangle(p[o], p[a], p[b], p[c])) clear = false;
            }
            if (clear) chosen = k, emit = true;
        }
        if (chosen == m) {
            // Rounding left no clean ear: take the largest convex corner.
            double best = 0;
            for (size_t k = 0; k < m; ++k) {
                const auto [a, b, c] = corner(k);
                const double area = Cross(p[a], p[b], p[c]);
                if (area > best) best = area, chosen = k;
            }
            if (chosen == m) break;
            emit = true;
        }
        if (emit) tris.push_back(corner(chosen));
        ring.erase(ring.begin() + static_cast<long>(chosen));
    }
    if (ring.size() == 3 && Cross(p[ring[0]], p[ring[1]], p[ring[2]]) > 0)
        tris.push_back({ring[0], ring[1], ring[2]});
    return tris;
}

bool InsidePolygon(const std::vector<Vec3> &v, const Vec3 &pt) {
    const Vec3 normal = PolygonNormal(v);
    std::vector<Vec3> withp = v;
    withp.push_back(pt);
    const std::vector<P2> p = Project(withp, normal);
    const P2 q = p.back();
    bool inside = false;
    const size_t n = v.size();
    for (size_t i = 0, j = n - 1; i < n; j = i++) {
        if ((p[i].y > q.y) != (p[j].y > q.y) &&
            q.x < (p[j].x - p[i].x) * (q.y - p[i].y) / (p[j].y - p[i].y) + p[i].x)
            inside = !inside;
    }
    return inside;
}

}  // namespace dayflux
