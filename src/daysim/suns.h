// The suns of DAYSIM's direct run (gen_dc): on December 21, February 21, March 21, April 21 and
// June 21, each whole solar hour with the sun more than 2 degrees up, the hours of sunrise and
// sunset moved to where the sun stands 2 degrees high. About 65 suns, depending on latitude.
// Computed in DAYSIM's float arithmetic so that the suns' directions print as DAYSIM's do.
#pragma once

#include <string>
#include <vector>

namespace dayflux {

// DAYSIM's design days: month of each (day 21), in the order gen_dc visits them.
inline constexpr int kDaysimDesignMonths[5] = {12, 2, 3, 4, 6};

struct DaysimSun {
    float solar_time = 0;  // hours
    float altitude = 0;    // degrees
    float azimuth = 0;     // degrees from south, west positive
    int month = 0, hour = 0;
};

struct DaysimSunTable {
    std::vector<DaysimSun> suns;  // the direct coefficients, in order (solar1 is suns[0])
    // For each design month (1..12, only the five used) and hour 0..23: the position at that
    // hour (the adjusted time at sunrise and sunset), and its coefficient, or -1 below 2 degrees.
    struct Entry {
        float solar_time = 0, altitude = 0, azimuth = 0;
        int coefficient = -1;
    };
    Entry calendar[13][24];
};

// latitude in radians north. as_gen_dc: gen_dc's float declination and solar times (the suns'
// files); else ds_illum's double ones (its calendar, which numbers the same suns).
DaysimSunTable DaysimDirectSuns(double latitude, bool as_gen_dc = true);

// DAYSIM's solar declination (radians): an older form of RADIANCE's, with a 368-day period.
double DaysimDeclination(int day_of_year);

// The direction gen_dc writes for a sun (x east, y north, z up).
void DaysimSunDirection(const DaysimSun &sun, double dir[3]);

// The direct run's light sources: `solarK` (K from 1) of luminance 1000 and 0.533 degrees.
std::string DaysimSunScene(const DaysimSunTable &table);

}  // namespace dayflux
