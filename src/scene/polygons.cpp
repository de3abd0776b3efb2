#include "scene/polygons.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

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

namespace {

// Ear clipping of one counter-clockwise polygon given as indices into p (holes already bridged
// in). Zero-area corners (collinear points, the two sides of a bridge) are dropped without a
// triangle; points at the same place as an ear's corners do not block it.
void EarClip(const std::vector<P2> &p, std::vector<int> ring,
             std::vector<std::array<int, 3>> *tris) {
    auto corner = [&](size_t k) {
        const size_t m = ring.size();
        return std::array<int, 3>{ring[(k + m - 1) % m], ring[k], ring[(k + 1) % m]};
    };
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
        if (chosen == m) {  // rounding left no clean ear: take the largest convex corner
            double best = 0;
            for (size_t k = 0; k < m; ++k) {
                const auto [a, b, c] = corner(k);
                const double area = Cross(p[a], p[b], p[c]);
                if (area > best) best = area, chosen = k;
            }
            if (chosen == m) return;
            emit = true;
        }
        if (emit) tris->push_back(corner(chosen));
        ring.erase(ring.begin() + static_cast<long>(chosen));
    }
    if (ring.size() == 3 && Cross(p[ring[0]], p[ring[1]], p[ring[2]]) > 0)
        tris->push_back({ring[0], ring[1], ring[2]});
}

double SignedArea(const std::vector<P2> &p, const std::vector<int> &ring) {
    double a = 0;
    for (size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++)
        a += (p[ring[j]].x - p[ring[i]].x) * (p[ring[j]].y + p[ring[i]].y);
    return 0.5 * a;
}

bool InsideRing(const std::vector<P2> &p, const std::vector<int> &ring, const P2 &q) {
    bool inside = false;
    for (size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++) {
        const P2 &a = p[ring[i]], &b = p[ring[j]];
        if ((a.y > q.y) != (b.y > q.y) && q.x < (b.x - a.x) * (q.y - a.y) / (b.y - a.y) + a.x)
            inside = !inside;
    }
    return inside;
}

// Whether ring a lies inside ring b (rings of one polygon do not cross): tested at a vertex of a
// that is not also a vertex of b.
bool RingInside(const std::vector<P2> &p, const std::vector<int> &a, const std::vector<int> &b) {
    for (int k : a) {
        bool shared = false;
        for (int m : b) shared |= Same(p[k], p[m]);
        if (!shared) return InsideRing(p, b, p[k]);
    }
    return false;
}

// Splits a polygon that visits some points twice (seams joining holes to outlines) into rings.
std::vector<std::vector<int>> SplitRings(const std::vector<P2> &p) {
    std::vector<std::vector<int>> rings;
    std::vector<int> path;
    for (int i = 0; i < static_cast<int>(p.size()); ++i) {
        size_t k = 0;
        while (k < path.size() && !Same(p[path[k]], p[i])) ++k;
        if (k < path.size()) {  // back at a point already on the path: the loop since is a ring
            rings.emplace_back(path.begin() + static_cast<long>(k), path.end());
            path.resize(k);
        }
        path.push_back(i);
    }
    // Closing back to the start is not repeated in the list; what remains is a ring too.
    rings.push_back(path);
    std::vector<std::vector<int>> kept;
    for (auto &r : rings)
        if (r.size() >= 3 && SignedArea(p, r) != 0) kept.push_back(std::move(r));
    return kept;
}

// Joins a hole (clockwise) into an outline (counter-clockwise) by a bridge from the hole's
// rightmost point to a point of the outline it can see (Eberly's method).
std::vector<int> Bridge(const std::vector<P2> &p, const std::vector<int> &outer,
                        const std::vector<int> &hole) {
    size_t hm = 0;
    for (size_t k = 1; k < hole.size(); ++k)
        if (p[hole[k]].x > p[hole[hm]].x) hm = k;
    const P2 m = p[hole[hm]];
    // Nearest crossing of the ray from m toward +x with an outline edge.
    double best_x = 1e300;
    size_t best = outer.size();
    for (size_t i = 0, j = outer.size() - 1; i < outer.size(); j = i++) {
        const P2 &a = p[outer[j]], &b = p[outer[i]];
        if ((a.y > m.y) == (b.y > m.y) && a.y != m.y && b.y != m.y) continue;
        if (a.y == b.y) continue;
        const double t = (m.y - a.y) / (b.y - a.y);
        if (t < 0 || t > 1) continue;
        const double x = a.x + t * (b.x - a.x);
        if (x < m.x || x >= best_x) continue;
        best_x = x;
        best = a.x > b.x ? j : i;
    }
    if (best == outer.size()) best = 0;
    // A reflex outline point inside the triangle (m, crossing, candidate) would block the view:
    // take the one closest in angle to the ray instead.
    const P2 hit{best_x, m.y}, cand = p[outer[best]];
    double best_angle = 1e300;
    for (size_t k = 0; k < outer.size(); ++k) {
        const P2 &q = p[outer[k]];
        const P2 &prev = p[outer[(k + outer.size() - 1) % outer.size()]],
                 &next = p[outer[(k + 1) % outer.size()]];
        if (Cross(prev, q, next) >= 0) continue;  // convex
        if (!InTriangle(q, m, hit, cand) && !(q.x == cand.x && q.y == cand.y)) continue;
        const double angle = std::atan2(std::fabs(q.y - m.y), q.x - m.x);
        if (angle < best_angle) best_angle = angle, best = k;
    }
    std::vector<int> joined(outer.begin(), outer.begin() + static_cast<long>(best) + 1);
    for (size_t k = 0; k <= hole.size(); ++k) joined.push_back(hole[(hm + k) % hole.size()]);
    joined.push_back(outer[best]);
    joined.insert(joined.end(), outer.begin() + static_cast<long>(best) + 1, outer.end());
    return joined;
}

}  // namespace

std::vector<std::array<int, 3>> TriangulatePolygon(const std::vector<Vec3> &v) {
    std::vector<std::array<int, 3>> tris;
    const int n = static_cast<int>(v.size());
    if (n < 3) return tris;
    const Vec3 normal = PolygonNormal(v);
    if (normal[0] == 0 && normal[1] == 0 && normal[2] == 0) return tris;
    if (n == 3) return {{0, 1, 2}};
    const std::vector<P2> p = Project(v, normal);
    std::vector<std::vector<int>> rings = SplitRings(p);
    if (rings.size() <= 1) {
        std::vector<int> ring(n);
        std::iota(ring.begin(), ring.end(), 0);
        if (rings.size() == 1) ring = rings[0];
        if (SignedArea(p, ring) < 0) std::reverse(ring.begin(), ring.end());
        EarClip(p, ring, &tris);
    } else {
        // RADIANCE's inside test is even-odd: a ring inside an odd number of others is a hole.
        std::vector<int> depth(rings.size(), 0);
        for (size_t a = 0; a < rings.size(); ++a)
            for (size_t b = 0; b < rings.size(); ++b)
                if (a != b && RingInside(p, rings[a], rings[b])) ++depth[a];
        for (size_t a = 0; a < rings.size(); ++a) {
            if (depth[a] % 2) continue;
            std::vector<int> outer = rings[a];
            if (SignedArea(p, outer) < 0) std::reverse(outer.begin(), outer.end());
            std::vector<std::vector<int>> holes;
            for (size_t b = 0; b < rings.size(); ++b)
                if (depth[b] == depth[a] + 1 && RingInside(p, rings[b], rings[a])) {
                    std::vector<int> h = rings[b];
                    if (SignedArea(p, h) > 0) std::reverse(h.begin(), h.end());
                    holes.push_back(std::move(h));
                }
            // Rightmost holes first, so later bridges see the earlier ones as part of the outline.
            std::sort(holes.begin(), holes.end(), [&](const auto &x, const auto &y) {
                double mx = -1e300, my = -1e300;
                for (int k : x) mx = std::max(mx, p[k].x);
                for (int k : y) my = std::max(my, p[k].x);
                return mx > my;
            });
            for (const auto &h : holes) outer = Bridge(p, outer, h);
            EarClip(p, outer, &tris);
        }
    }
    return tris;  // counter-clockwise in the projection: the polygon's own normal
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
