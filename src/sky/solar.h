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

// Michalsky's algorithm (RADIANCE's mjdate() and msdec(), for gensky and gendaylit with a year):
// the Almanac's Julian date from noon UT on 2000-01-01 (fractional days) of a local standard time,
// and the solar declination (radians) then, with the solar time in *solar_time where asked.
double AlmanacDate(const Site &site, int year, int month, int day, double hour);
double AlmanacDeclination(const Site &site, double date, double *solar_time);

// The full angle of the solar disc, degrees (gendaymtx's and gensky's).
constexpr double kSunAngleDeg = 0.533;

// The sun over a weather file's records, taken in order as gendaymtx takes them: February 29
// is day 60, and once it has been seen the days after it move on by one.
class SunTrack {
  public:
    struct Position {
        int day_of_year = 0;
        double altitude = 0;  // radians
        double azimuth = 0;   // radians from south, west positive
        bool in_sky = false;  // any part of the disc above the horizon (gendaymtx -u keeps these)
    };
    explicit SunTrack(const Site &site) : site_(site) {}
    Position Next(int month, int day, double hour);

  private:
    Site site_;
    int leap_day_ = 0;
};

// RADIANCE's table cosine (tcos.c): 1024 entries per quarter turn, nearest entry, no interpolation.
// gendaymtx normalises its skies with it, so we must too.
double TableCos(double x);
inline double TableSin(double x) { return TableCos(x - M_PI / 2.); }

}  // namespace dayflux
