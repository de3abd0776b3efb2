// Solar position with the formulas RADIANCE uses (src/gen/sun.c: the old IES equations), so that
// hours, sun positions and everything derived from them agree with RADIANCE's.
#pragma once

#include <cmath>

namespace dayflux {

struct Site {
    double latitude = 0;   // radians north
    double longitude = 0;  // radians west of Greenwich (RADIANCE's convention)
    double meridian = 0;   // standard meridian, radians west
};

// Day of the year for a month (1-12) and day, without leap days (RADIANCE's jdate()).
int DayOfYear(int month, int day);
// Solar declination (radians) for a day of the year.
double SolarDeclination(int day_of_year);
// Solar time minus local standard time, hours.
double SolarTimeOffset(int day_of_year, const Site &site);
// Altitude (radians) for a declination and a solar time in hours.
double SolarAltitude(const Site &site, double declination, double solar_time);
// Azimuth (radians) measured from south, west positive, as RADIANCE's sazi().
double SolarAzimuth(const Site &site, double declination, double solar_time);

// RADIANCE's table cosine (tcos.c): 1024 entries per quarter turn, nearest entry, no interpolation.
// gendaymtx normalises its skies with it, so we must too.
double TableCos(double x);
inline double TableSin(double x) { return TableCos(x - M_PI / 2.); }

}  // namespace dayflux
