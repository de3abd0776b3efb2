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
