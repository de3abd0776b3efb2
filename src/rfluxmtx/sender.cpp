#include "rfluxmtx/sender.h"

#include <algorithm>
#include <cmath>

#include "matrix/bsdf_xml.h"
#include "raytrace/core/sampling.h"
#include "scene/polygons.h"
#include "util/errors.h"

namespace dayflux {

namespace {

constexpr double kTiny = 1e-6;  // RADIANCE's FTINY

void Cross(const double a[3], const double b[3], double c[3]) {
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}
double Dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double Normalise(double v[3]) {
    const double l = std::sqrt(Dot(v, v));
    if (l > 0)
        for (int k = 0; k < 3; ++k) v[k] /= l;
    return l;
}

// Tregenza's azimuth divisions per band, which Reinhart's bases subdivide.
constexpr int kTregenzaBands[7] = {30, 30, 24, 24, 18, 12, 6};

}  // namespace

void HilbertCoordinates(int n, int nbits, uint64_t index, uint64_t x[]) {
    // The index's bits dealt out to the coordinates, most significant first (the transpose).
    for (int i = 0; i < n; ++i) x[i] = 0;
    for (int b = 0; b < nbits; ++b)
        for (int i = 0; i < n; ++i)
            if ((index >> (b * n + (n - 1 - i))) & 1u) x[i] |= uint64_t{1} << b;
    // Gray decoding, then undoing the rotations and reflections of each level.
    uint64_t t = x[n - 1] >> 1;
    for (int i = n - 1; i > 0; --i) x[i] ^= x[i - 1];
    x[0] ^= t;
    const uint64_t top = uint64_t{1} << nbits;
    for (uint64_t q = 2; q != top; q <<= 1) {
        const uint64_t p = q - 1;
        for (int i = n - 1; i >= 0; --i) {
            if (x[i] & q) {
                x[0] ^= p;
            } else {
                t = (x[0] ^ x[i]) & p;
                x[0] ^= t;
                x[i] ^= t;
            }
        }
    }
}

SenderSampler::SenderSampler(const FluxGroup &sender, int samples, uint64_t seed)
    : sender_(sender), basis_(sender.basis), samples_(samples), rng_(seed) {
    // prepare_sampler(): the frame (u = up x normal, v = normal x u; u reversed for h=-...).
    double up[3];
    sender.Normal(nrm_);
    sender.Up(up);
    Cross(up, nrm_, udir_);
    CHECK(Normalise(udir_) > 0);  // FluxGroup::Up() refuses an up vector along the normal
    Cross(nrm_, udir_, vdir_);
    if (basis_.left_handed)
        for (double &c : udir_) c = -c;
    switch (basis_.kind) {
        case FluxBasis::kUniform:
            bins_ = 1;
            break;
        case FluxBasis::kShirleyChiu:
            if (basis_.size <= 1)
                ErrorExit(&sender.loc, "missing size for Shirley-Chiu sampling (h=sc" +
                                           std::to_string(basis_.size) + ")");
            bins_ = basis_.size * basis_.size;
            break;
        case FluxBasis::kReinhart: {
            const int rows = 7 * basis_.size + 1;
            for (int r = 0; r < rows; ++r)
                reinhart_row_bins_.push_back(
                    r == rows - 1 ? 1 : basis_.size * kTregenzaBands[r / basis_.size]);
            for (int n : reinhart_row_bins_) bins_ += n;
            break;
        }
        default: {
            const int size = basis_.kind == FluxBasis::kKlemsFull   ? 145
                             : basis_.kind == FluxBasis::kKlemsHalf ? 73
                                                                    : 41;
            const std::vector<AngleBasis> &bases = KlemsBases();
            for (size_t i = 0; i < bases.size(); ++i)
                if (bases[i].Size() == size) klems_ = static_cast<int>(i);
            CHECK(klems_ >= 0);
            bins_ = size;
        }
    }
    for (const FluxSurface &s : sender.surfaces) {
        Element e{&s, {}, {}};
        if (s.type == FluxSurface::kPolygon) {
            std::vector<Vec3> v;
            for (size_t i = 0; i + 2 < s.args.size(); i += 3)
                v.push_back({s.args[i], s.args[i + 1], s.args[i + 2]});
            double total = 0;
            for (const auto &t : TriangulatePolygon(v)) {
                const Vec3 n = PolygonNormal({v[t[0]], v[t[1]], v[t[2]]});
                const double area = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
                e.triangles.push_back({{t[0], t[1], t[2]}, area});
                total += area;
            }
            if (e.triangles.empty() || total <= 0)
                ErrorExit(&s.loc, "cannot triangulate polygon '" + s.name + "'");
            for (Triangle &t : e.triangles) t.area_fraction /= total;
        } else {
            // make_axes(): any two axes of the ring's plane.
            const double *n = s.normal;
            double other[3] = {0, 0, 0};
            other[std::fabs(n[0]) < .6 ? 0 : std::fabs(n[1]) < .6 ? 1 : 2] = 1;
            Cross(other, n, e.axes[0]);
            Normalise(e.axes[0]);
            Cross(n, e.axes[0], e.axes[1]);
        }
        elements_.push_back(std::move(e));
    }
    projected_.resize(elements_.size());
    left_ = samples_;
}

void SenderSampler::MultiSample(double t[], int n, double x) {
    x = std::clamp(x, 0.0, 0.999999999999999);
    if (n == 1) {
        t[0] = x;
        return;
    }
    const int nbits = 63 / n;
    uint64_t coords[3];
    HilbertCoordinates(n, nbits, static_cast<uint64_t>(x * std::ldexp(1.0, nbits * n)), coords);
    const double scale = std::ldexp(1.0, -nbits);
    for (int k = 0; k < n; ++k) t[k] = scale * (static_cast<double>(coords[k]) + Uniform());
}

void SenderSampler::Direction(int bin, double s1, double s2, double d[3]) {
    switch (basis_.kind) {
        case FluxBasis::kUniform: {  // the whole hemisphere, cosine-weighted
            const core::real2 disk = core::SquareToDisk(s1, s2);
            d[0] = -disk.x, d[1] = -disk.y;
            break;
        }
        case FluxBasis::kShirleyChiu: {
            const int n = basis_.size;
            const core::real2 disk = core::SquareToDisk((bin / n + s1) / n, (bin % n + s2) / n);
            d[0] = disk.x, d[1] = disk.y;
            break;
        }
        case FluxBasis::kReinhart: {
            const int rows = static_cast<int>(reinhart_row_bins_.size());
            int row = 0, col = bin;
            while (col >= reinhart_row_bins_[row]) col -= reinhart_row_bins_[row++];
            if (row == rows - 1) s1 *= s1;  // the zenith cap: avoid crowding
            const double alt = (row + s1) * (M_PI / 2) / (rows - .5);
            const double azi = 2 * M_PI * (col + s2 - .5) / reinhart_row_bins_[row];
            d[0] = std::sin(azi) * std::cos(alt);
            d[1] = -std::cos(azi) * std::cos(alt);
            break;
        }
        default: {  // fo_getvec(): uniform in projected solid angle over the patch
            const AngleBasis &ab = KlemsBases()[klems_];
            int ring = 0, k = bin;
            while (k >= ab.nphis[ring]) k -= ab.nphis[ring++];
            double rx[2];
            MultiSample(rx, 2, s1);
            const double c0 = std::cos(ab.theta[ring] * M_PI / 180);
            const double c1 = std::cos(ab.theta[ring + 1] * M_PI / 180);
            const double cos_theta = std::sqrt((1 - rx[0]) * c0 * c0 + rx[0] * c1 * c1);
            const double sin_theta = std::sqrt(1 - cos_theta * cos_theta);
            const double azi = 2 * M_PI * (k + rx[1] - .5) / ab.nphis[ring];
            d[0] = std::cos(azi) * sin_theta, d[1] = std::sin(azi) * sin_theta;
        }
    }
    d[2] = std::sqrt(std::max(0.0, 1 - d[0] * d[0] - d[1] * d[1]));
}

void SenderSampler::Origin(const Element &e, double x, double origin[3]) {
    const std::vector<double> &a = e.surface->args;
    double s[2];
    if (e.surface->type == FluxSurface::kRing) {
        MultiSample(s, 2, x);
        const double r = std::sqrt(s[0] * e.surface->area / M_PI + a[6] * a[6]);
        const double phi = 2 * M_PI * s[1];
        for (int k = 0; k < 3; ++k)
            origin[k] = a[k] + r * std::cos(phi) * e.axes[0][k] + r * std::sin(phi) * e.axes[1][k];
        return;
    }
    size_t i = 0;  // a triangle by its share of the area
    for (; i + 1 < e.triangles.size() && x > e.triangles[i].area_fraction; ++i)
        x -= e.triangles[i].area_fraction;
    const Triangle &t = e.triangles[i];
    MultiSample(s, 2, x / t.area_fraction);
    const double root = std::sqrt(s[1]);
    const double b1 = s[0] * root, b2 = 1 - root;
    const double *v0 = &a[3 * t.v[0]], *v1 = &a[3 * t.v[1]], *v2 = &a[3 * t.v[2]];
    for (int k = 0; k < 3; ++k) origin[k] = v0[k] + b1 * (v1[k] - v0[k]) + b2 * (v2[k] - v0[k]);
}

void SenderSampler::SampleOrigin(const double dir[3], double x, double origin[3]) {
    if (elements_.size() == 1) {
        if (Dot(elements_[0].surface->normal, dir) >= kTiny)
            ErrorExit(&elements_[0].surface->loc,
                      "sample behind sender '" + elements_[0].surface->name + "'");
        Origin(elements_[0], x, origin);
        return;
    }
    double total = 0;
    for (size_t i = 0; i < elements_.size(); ++i) {
        const FluxSurface &s = *elements_[i].surface;
        projected_[i] = std::max(0.0, -Dot(s.normal, dir) * s.area);
        total += projected_[i];
    }
    if (total < kTiny * kTiny)
        ErrorExit(&sender_.loc, "sample behind all sender elements ('" + sender_.modifier + "')");
    double left = total * x;
    size_t i = 0;
    while (i + 1 < elements_.size() && (projected_[i] == 0 || left > projected_[i]))
        left -= projected_[i++];
    Origin(elements_[i], std::min(1.0, left / projected_[i]), origin);
}

bool SenderSampler::Next(double ray[6]) {
    if (bin_ >= bins_) return false;
    // Stratum left_ - 1 of the bin's `samples_`, counting down as rfluxmtx does.
    --left_;
    double s[3];
    const bool klems = klems_ >= 0;
    MultiSample(s, klems ? 2 : 3, (left_ + Uniform()) / samples_);
    double local[3];
    Direction(bin_, s[1], klems ? 0 : s[2], local);
    for (int k = 0; k < 3; ++k)
        ray[3 + k] = -(local[0] * udir_[k] + local[1] * vdir_[k] + local[2] * nrm_[k]);
    SampleOrigin(ray + 3, s[0], ray);
    if (left_ == 0) ++bin_, left_ = samples_;
    return true;
}

}  // namespace dayflux
