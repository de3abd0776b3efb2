#include "sky/patches.h"

#include <cmath>

#include "util/errors.h"

namespace dayflux {

namespace {
constexpr int kTregenzaRowPatches[7] = {30, 30, 24, 24, 18, 12, 6};
}

SkyPatchBasis::SkyPatchBasis(int mf) : mf_(mf), alpha_((M_PI / 2.) / (7 * mf + .5)) {
    CHECK(mf >= 1);
    const int n = 144 * mf * mf + 2;
    altitude_.resize(n);
    azimuth_.resize(n);
    solid_angle_.resize(n);
    // gendaymtx's rh_init(): values computed in double, stored in float.
    altitude_[0] = static_cast<float>(-M_PI / 2.);
    azimuth_[0] = 0;
    solid_angle_[0] = static_cast<float>(2. * M_PI);
    altitude_[n - 1] = static_cast<float>(M_PI / 2.);
    azimuth_[n - 1] = 0;
    solid_angle_[n - 1] = static_cast<float>(2. * M_PI * (1. - std::cos(alpha_ * .5)));
    int p = 1;
    for (int i = 0; i < 7 * mf; ++i) {
        row_start_.push_back(p);
        const float alt = static_cast<float>(alpha_ * (i + .5));
        const int in_row = kTregenzaRowPatches[i / mf] * mf;
        const float dom =
            static_cast<float>(2. * M_PI * (std::sin(alpha_ * (i + 1)) - std::sin(alpha_ * i)) /
                               static_cast<double>(in_row));
        for (int j = 0; j < in_row; ++j) {
            altitude_[p] = alt;
            azimuth_[p] = static_cast<float>(2. * M_PI * j / static_cast<double>(in_row));
            solid_angle_[p++] = dom;
        }
    }
    row_start_.push_back(p);  // zenith
    CHECK(p == n - 1);
}

int SkyPatchBasis::PatchesInRow(int row) const {
    if (row == 7 * mf_) return 1;
    return kTregenzaRowPatches[row / mf_] * mf_;
}

int SkyPatchBasis::FirstPatchOfRow(int row) const { return row_start_[row]; }

void SkyPatchBasis::Direction(int p, double v[3]) const {
    const double alt = altitude_[p], azi = azimuth_[p];
    v[1] = std::cos(alt);
    v[0] = v[1] * std::sin(azi);
    v[1] *= std::cos(azi);
    v[2] = std::sin(alt);
}

int SkyPatchBasis::Bin(double dx, double dy, double dz) const {
    const double alt = std::asin(dz) * (180. / M_PI);
    if (alt < 0) return 0;
    double azi = std::atan2(dx, dy) * (180. / M_PI);
    if (azi < 0) azi += 360.;
    const double alpha_deg = 90. / (7 * mf_ + .5);
    int row = static_cast<int>(std::floor(alt / alpha_deg));
    if (row >= 7 * mf_) return Size() - 1;
    const double inc = 360. / PatchesInRow(row);
    int col = static_cast<int>(std::floor((azi + inc / 2.) / inc));
    if (col >= PatchesInRow(row)) col = 0;
    return row_start_[row] + col;
}

}  // namespace dayflux
