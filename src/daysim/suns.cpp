#include "daysim/suns.h"

#include <cmath>
#include <cstdio>

#include "sky/solar.h"

namespace dayflux {

namespace {

// DAYSIM's sun.c with RADIANCE's formulas; the latitude is DAYSIM's s_latitude (radians).
double Altitude(double latitude, double sd, double st) {
    return std::asin(std::sin(latitude) * std::sin(sd) -
                     std::cos(latitude) * std::cos(sd) * std::cos(st * (M_PI / 12)));
}
double Azimuth(double latitude, double sd, double st) {
    return -std::atan2(std::cos(sd) * std::sin(st * (M_PI / 12)),
                       -std::cos(latitude) * std::sin(sd) -
                           std::sin(latitude) * std::cos(sd) * std::cos(st * (M_PI / 12)));
}
// The solar time (hours after midnight) when the sun reaches altitude alt in the morning; NaN
// where it never does (polar days and nights: no hour is then moved).
double TimeAtAltitude(double latitude, double sd, double alt) {
    const double e = std::sin(latitude) * std::sin(sd), f = std::cos(latitude) * std::cos(sd);
    return 12.0 / M_PI * std::acos((e - std::sin(alt)) / f);
}
// DAYSIM's declination: an older form of RADIANCE's, with a 368-day period (RADIANCE now has 365).
}  // namespace

double DaysimDeclination(int day_of_year) {
    return 0.4093 * std::sin((2 * M_PI / 368) * (day_of_year - 81));
}

namespace {
double Degrees(double r) { return r * (180.0 / M_PI); }

// gen_dc keeps the declination and solar time in float, ds_illum in double (Real).
template <typename Real>
void AddDesignDay(double latitude, int month, DaysimSunTable *table) {
    const Real sd = static_cast<Real>(DaysimDeclination(DayOfYear(month, 21)));
    const double rise = TimeAtAltitude(latitude, sd, 2.0 * (M_PI / 180.));
    const double set = 24 - rise;
    for (int hour = 0; hour < 24; ++hour) {
        Real st = static_cast<Real>(hour);
        if (hour - 0.5 < rise && hour + 0.5 > rise) st = static_cast<Real>(rise);
        if (hour - 0.5 < set && hour + 0.5 > set) st = static_cast<Real>(set);
        DaysimSunTable::Entry &e = table->calendar[month][hour];
        e.solar_time = static_cast<float>(st);
        e.altitude = static_cast<float>(Degrees(Altitude(latitude, sd, st)));
        e.azimuth = static_cast<float>(Degrees(Azimuth(latitude, sd, st)));
        if (Degrees(Altitude(latitude, sd, st)) > 1.999) {
            if (e.altitude < 2.001f) e.altitude = 2;
            e.coefficient = static_cast<int>(table->suns.size());
            table->suns.push_back({e.solar_time, e.altitude, e.azimuth, month, hour});
        }
    }
}

}  // namespace

DaysimSunTable DaysimDirectSuns(double latitude, bool as_gen_dc) {
    DaysimSunTable table;
    for (int month = 1; month <= 12; ++month)
        for (int hour = 0; hour < 24; ++hour) table.calendar[month][hour].solar_time = hour;
    for (int month : kDaysimDesignMonths) {
        if (as_gen_dc)
            AddDesignDay<float>(latitude, month, &table);
        else
            AddDesignDay<double>(latitude, month, &table);
    }
    return table;
}

void DaysimSunDirection(const DaysimSun &sun, double dir[3]) {
    // gen_dc's degrees-to-radians constant and float angles, kept so the files agree.
    // (Stored in float and taken back to double: C's sin of a float is the double sin.)
    const double zenith = static_cast<float>(0.017453 * (90 - sun.altitude));
    const double azimuth = static_cast<float>(0.017453 * -1 * (sun.azimuth + 90));
    dir[0] = std::sin(zenith) * std::cos(azimuth);
    dir[1] = std::sin(zenith) * std::sin(azimuth);
    dir[2] = std::cos(zenith);
}

std::string DaysimSunScene(const DaysimSunTable &table) {
    std::string s =
        "# the suns of DAYSIM's direct daylight coefficients (gen_dc), written by dayflux\n\n";
    char buf[160];
    for (size_t k = 0; k < table.suns.size(); ++k) {
        double d[3];
        DaysimSunDirection(table.suns[k], d);
        std::snprintf(buf, sizeof buf,
                      "void light solar%zu\n0\n0\n3 1000 1000 1000\n\nsolar%zu source sun\n0\n0\n"
                      "4 %f %f %f 0.533\n\n",
                      k + 1, k + 1, d[0], d[1], d[2]);
        s += buf;
    }
    return s;
}

}  // namespace dayflux
