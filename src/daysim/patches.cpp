#include "daysim/patches.h"

#include <algorithm>
#include <cmath>

#include "util/errors.h"

namespace dayflux {

namespace {

constexpr int kRowStart[8] = {0, 30, 60, 84, 108, 126, 138, 144};
constexpr int kRowCount[8] = {30, 30, 24, 24, 18, 12, 6, 1};

}  // namespace

int DaysimPatch(double dx, double dy, double dz) {
    if (dz > 0) {
        // Rows are 12 degrees tall and the zenith cap 6: 7.5 rows from horizon to zenith.
        const int row = std::min(7, static_cast<int>(std::asin(std::min(dz, 1.0)) * 15 / M_PI));
        if (row == 7) return kRowStart[7];
        double turn = std::atan2(dy, dx) / (2 * M_PI);
        if (turn < 0) turn += 1;
        const int k = static_cast<int>(kRowCount[row] * turn);
        return kRowStart[row] + std::min(k, kRowCount[row] - 1);
    }
    if (dz >= -0.17365) return 145;
    if (dz >= -0.5) return 146;
    return 147;
}

void DaysimPatchDirection(int patch, double dir[3]) {
    CHECK(patch >= 0 && patch < kDaysimDiffusePatches);
    // ds_illum's own numbers (the sky's rounded to float as it stores them)
    static constexpr double kGround[3][3] = {
        {0.9961946, 0, -0.087156}, {0.9397, 0, -0.342}, {0, 0, -1}};
    if (patch >= kDaysimSkyPatches) {
        std::copy(kGround[patch - kDaysimSkyPatches], kGround[patch - kDaysimSkyPatches] + 3, dir);
        return;
    }
    int row = 0;
    while (row < 7 && patch >= kRowStart[row + 1]) ++row;
    if (row == 7) {  // the zenith, as ds_illum writes it
        dir[0] = static_cast<float>(std::cos(M_PI / 2)), dir[1] = 0, dir[2] = 1;
        return;
    }
    const double theta = (84.0 - 12.0 * row) * (M_PI / 180);
    const double az =
        static_cast<float>(360.0 / kRowCount[row] * (patch - kRowStart[row] + 0.5)) * (M_PI / 180);
    dir[0] = static_cast<float>(std::cos(az) * std::sin(theta));
    dir[1] = static_cast<float>(std::sin(az) * std::sin(theta));
    dir[2] = static_cast<float>(std::cos(theta));
}

// The same arithmetic as DaysimPatch (a turn of exactly 1 kept in its row; a negative turn of
// -0 taken as 0, where DAYSIM would index before the row).
const char kDaysimPatchCal[] =
    "dspi : 3.14159265358979323846;\n"
    "dsrow = floor(asin(if(Dz - 1, 1, Dz)) * 15 / dspi);\n"
    "dsturn0 = atan2(Dy, Dx) / (2 * dspi);\n"
    "dsturn = if(-dsturn0, dsturn0 + 1, dsturn0);\n"
    "dsstart = select(dsrow + 1, 0, 30, 60, 84, 108, 126, 138, 144);\n"
    "dscount = select(dsrow + 1, 30, 30, 24, 24, 18, 12, 6, 1);\n"
    "dsk = floor(dscount * dsturn);\n"
    "dssky = if(dsrow - 6.5, 144, dsstart + if(dsk - dscount + .5, dscount - 1, dsk));\n"
    "dspatch = if(Dz, dssky, if(-0.17365 - Dz, if(-0.5 - Dz, 147, 146), 145));\n";

}  // namespace dayflux
