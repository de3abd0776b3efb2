#include "sky/solar.h"

#include <array>
#include <cmath>

namespace dayflux {

int DayOfYear(int month, int day) {
    static constexpr int start[12] = {0, 31, 59, 90, 120, 151, 181, 212, 243, 273, 304, 334};
    return start[month - 1] + day;
}

double SolarDeclination(int jd) { return 0.4093 * std::sin((2. * M_PI / 365.) * (jd - 81)); }

double SolarTimeOffset(int jd, const Site &site) {
    return 0.170 * std::sin((4. * M_PI / 373.) * (jd - 80)) -
           0.129 * std::sin((2. * M_PI / 355.) * (jd - 8)) +
           (12. / M_PI) * (site.meridian - site.longitude);
}

double SolarAltitude(const Site &site, double sd, double st) {
    return std::asin(std::sin(site.latitude) * std::sin(sd) -
                     std::cos(site.latitude) * std::cos(sd) * std::cos(st * (M_PI / 12.)));
}

SunTrack::Position SunTrack::Next(int month, int day, double hour) {
    Position p;
    if (month == 2 && day == 29) {
        p.day_of_year = 60;
        leap_day_ = 1;
    } else {
        p.day_of_year = DayOfYear(month, day) + leap_day_;
    }
    const double sd = SolarDeclination(p.day_of_year);
    const double st = hour + SolarTimeOffset(p.day_of_year, site_);
    p.altitude = SolarAltitude(site_, sd, st);
    p.azimuth = SolarAzimuth(site_, sd, st);
    p.in_sky = p.altitude > -(kSunAngleDeg / 2.) * (M_PI / 180.);
    return p;
}

double SolarAzimuth(const Site &site, double sd, double st) {
    return -std::atan2(std::cos(sd) * std::sin(st * (M_PI / 12.)),
                       -std::cos(site.latitude) * std::sin(sd) -
                           std::sin(site.latitude) * std::cos(sd) * std::cos(st * (M_PI / 12.)));
}

namespace {
// An angle brought into [0, period).
double Circle(double r, double period) {
    while (r < 0) r += period;
    while (r >= period) r -= period;
    return r;
}
}  // namespace

double AlmanacDate(const Site &site, int year, int month, int day, double hour) {
    int jd = DayOfYear(month, day);
    jd += (month > 2) & !(year & 3);
    jd += (year - 1949) * 365 + (year - 1949) / 4;
    hour += site.meridian * (12. / M_PI);
    return jd + hour * (1. / 24.) + (2432916.5 - 2451545.);
}

double AlmanacDeclination(const Site &site, double mjd, double *solar_time) {
    constexpr double kDeg = M_PI / 180.;
    const double mean_longitude = Circle(280.460 * kDeg + 0.9856474 * kDeg * mjd, 2. * M_PI);
    const double anomaly = Circle(357.528 * kDeg + 0.9856003 * kDeg * mjd, 2. * M_PI);
    const double ecliptic =
        mean_longitude + 1.915 * kDeg * std::sin(anomaly) + 0.020 * kDeg * std::sin(2. * anomaly);
    const double obliquity = 23.439 * kDeg - 4e-7 * kDeg * mjd;
    const double sin_l = std::sin(ecliptic);
    if (solar_time) {
        const double ra = std::atan2(sin_l * std::cos(obliquity), std::cos(ecliptic));
        const double utime = 24. * (mjd - std::floor(mjd)) + 12.;
        const double gmst = 6.697375 + 0.0657098242 * mjd + utime;
        const double lmst = gmst - site.longitude * (12. / M_PI);
        *solar_time = Circle(lmst - ra * (12. / M_PI) + 12., 24.);
    }
    return std::asin(std::sin(obliquity) * sin_l);
}

double TableCos(double x) {
    constexpr int kEntries = 1024;
    static const std::array<double, kEntries + 1> table = [] {
        std::array<double, kEntries + 1> t{};
        for (int i = 0; i <= kEntries; ++i) t[i] = std::cos((M_PI / 2. / kEntries) * i);
        return t;
    }();
    if (x < 0.) x = -x;
    int i = static_cast<int>((kEntries * 2. / M_PI) * x + 0.5);
    while (i >= 4 * kEntries) i -= 4 * kEntries;
    switch (i / kEntries) {
        case 0:
            return table[i];
        case 1:
            return -table[2 * kEntries - i];
        case 2:
            return -table[i - 2 * kEntries];
        case 3:
            return table[4 * kEntries - i];
    }
    return 0.;
}

}  // namespace dayflux
