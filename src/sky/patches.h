// Sky patch geometry: Reinhart's subdivision of Tregenza's 145 patches (MF = 1 is Tregenza), with
// the ground as patch 0, as gendaymtx orders its rows and reinhart.cal numbers its bins.
#pragma once

#include <vector>

namespace dayflux {

class SkyPatchBasis {
  public:
    explicit SkyPatchBasis(int mf);

    // Patches including the ground (patch 0): 144 MF^2 + 2.
    int Size() const { return static_cast<int>(altitude_.size()); }
    // Sky rows 0 .. 7 MF - 1 are regular; row 7 MF is the zenith cap.
    int Rows() const { return 7 * mf_ + 1; }
    int PatchesInRow(int row) const;
    int FirstPatchOfRow(int row) const;  // patch index (counting the ground as 0)
    // Row height in radians: (pi/2) / (7 MF + 0.5); the zenith cap is half as tall.
    double RowHeight() const { return alpha_; }

    // Patch centres and solid angles exactly as gendaymtx stores them (in float). Azimuth is
    // measured from north toward east (+Y toward +X); the ground has altitude -pi/2.
    float Altitude(int p) const { return altitude_[p]; }
    float Azimuth(int p) const { return azimuth_[p]; }
    float SolidAngle(int p) const { return solid_angle_[p]; }
    // Unit vector of a patch centre (x east, y north, z up).
    void Direction(int p, double v[3]) const;

    // Patch of a direction, as reinhart.cal's rbin: 0 below the horizon, patches centred on
    // their azimuths (patch 1 straddles north).
    int Bin(double dx, double dy, double dz) const;

  private:
    int mf_;
    double alpha_;
    std::vector<int> row_start_;
    std::vector<float> altitude_, azimuth_, solid_angle_;
};

}  // namespace dayflux
