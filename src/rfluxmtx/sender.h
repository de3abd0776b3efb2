// rfluxmtx's sampling mode: rays leaving the back of a sender's surfaces, for each bin of its
// hemisphere a fixed number of them, stratified over the bin and over the surfaces (by their
// projected area along the ray) as RADIANCE's rfluxmtx samples them: a point along a Hilbert
// curve through the unit square or cube (SDmultiSamp()) for each stratum.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include "rfluxmtx/annotations.h"

namespace dayflux {

// The coordinates (nbits each) of point `index` of an n-dimensional Hilbert curve (Skilling's
// transpose, "Programming the Hilbert curve", 2004). Neighbouring indices are neighbours.
void HilbertCoordinates(int n, int nbits, uint64_t index, uint64_t coords[]);

class SenderSampler {
  public:
    // samples: rays per bin (rfluxmtx's -c).
    SenderSampler(const FluxGroup &sender, int samples, uint64_t seed);

    int Bins() const { return bins_; }
    // The next ray (origin, direction): bins in order, `samples` rays each; false after the last.
    bool Next(double ray[6]);

    // Where the sender's hemisphere is (its normal faces away from the rays).
    const double *Normal() const { return nrm_; }

  private:
    struct Triangle {
        int v[3];
        double area_fraction;
    };
    struct Element {
        const FluxSurface *surface;
        std::vector<Triangle> triangles;  // polygons
        double axes[2][3];                // rings: the tangent plane
    };

    double Uniform() { return static_cast<double>(rng_() >> 11) * 0x1p-53; }
    // SDmultiSamp(): n coordinates in [0, 1) for the stratum position x in [0, 1).
    void MultiSample(double t[], int n, double x);
    // The direction in the hemisphere's frame (z along the normal) for bin b.
    void Direction(int bin, double s1, double s2, double local[3]);
    void Origin(const Element &e, double x, double origin[3]);
    // sample_origin(): an element by projected area along dir, then a point on it.
    void SampleOrigin(const double dir[3], double x, double origin[3]);

    const FluxGroup &sender_;
    FluxBasis basis_;
    int samples_;
    int bins_ = 0;
    double nrm_[3], udir_[3], vdir_[3];
    std::vector<Element> elements_;
    std::vector<double> projected_;
    std::vector<int> reinhart_row_bins_;  // Reinhart: bins per row
    int klems_ = -1;                      // Klems: the basis among KlemsBases()
    std::mt19937_64 rng_;
    int bin_ = 0, left_ = 0;
};

}  // namespace dayflux
