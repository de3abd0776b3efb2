// DAYSIM's sky division: Tregenza's 145 sky patches and three ground patches, numbered as DAYSIM
// numbers its 148 diffuse daylight coefficients. Not tregenza.cal's order: rows from the horizon
// up, each starting east (+X) and going counter-clockwise (toward north, +Y), patch edges (not
// centres) at multiples of 360/n, the zenith patch 144, then the ground 0-10, 10-30 and 30-90
// degrees below the horizon (145, 146, 147).
#pragma once

namespace dayflux {

constexpr int kDaysimSkyPatches = 145;
constexpr int kDaysimDiffusePatches = 148;  // with the three ground patches

// The patch a direction (unit vector, x east, y north, z up) falls into, as rtrace_dc's -Dd sorts
// the light it finds (DAYSIM's daysimComputePatch).
int DaysimPatch(double dx, double dy, double dz);

// The direction ds_illum evaluates a patch's luminance at: a sky patch's centre (rounded to
// float, as ds_illum stores it), or the ground patches' (0.9961946 0 -0.087156),
// (0.9397 0 -0.342), (0 0 -1).
void DaysimPatchDirection(int patch, double dir[3]);

// DaysimPatch as a calcomp bin expression (`dspatch`, of Dx Dy Dz), for the engines.
extern const char kDaysimPatchCal[];

}  // namespace dayflux
