// gensky: RADIANCE's CIE sky descriptions (clear with or without sun, intermediate, overcast,
// uniform) for a date and time or a solar altitude and azimuth, with its options, warnings and
// output byte for byte (RADIANCE 5.4a): the sun as a light source, the sky as skybright.cal's
// brightfunc skyfunc.
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "matrix/header.h"
#include "sky/solar.h"
#include "util/errors.h"
#include "util/photometry.h"

namespace dayflux {
namespace {

enum SkyType { kClear = 1, kOvercast = 2, kUniform = 3, kIntermediate = 4 };

struct Sky {
    Site site{0.66, 2.13, 120. * M_PI / 180.};  // RADIANCE's default site (sun.c)
    int year = 0, month = 0, day = 0;
    double hour = 0;
    bool solar_time = false;  // the hour given as solar time (+)
    double altitude = 0, azimuth = 0;
    SkyType type = kClear;
    bool sun = true;
    double zenith = 0;    // zenith brightness given (-b radiance, -B irradiance)
    int zenith_unit = 0;  // 1: -b, -1: -B, 0: computed
    double turbidity = 2.45;
    double ground_reflectance = 0.2;
    double solar = 0;    // -r radiance, -R irradiance
    int solar_unit = 0;  // 1: -r, -1: -R, 0: computed
    // computed
    double dir[3] = {0, 0, 0};
    double ground = 0, f2 = 0;
    bool Overcast() const { return type == kOvercast || type == kUniform; }
};

[[noreturn]] void UseError(const char *prog, const std::string &msg) {
    if (!msg.empty()) std::fprintf(stderr, "%s: Use error - %s\n", prog, msg.c_str());
    std::fprintf(stderr, "Usage: %s month day hour [options]\n", prog);
    std::fprintf(stderr, "   Or: %s -ang altitude azimuth [options]\n", prog);
    std::fprintf(stderr, "   Or: %s -defaults\n", prog);
    std::exit(1);
}

// The hour argument: hh[.hh] or hh:mm, + for solar time, or a time zone's name after it (whose
// standard meridian it sets). True where a zone was named.
bool ParseHour(const char *prog, const char *text, Sky &s) {
    static const struct {
        char name[8];     // (eight bytes, as RADIANCE's: its match reads past a name's end)
        double meridian;  // degrees west
    } kZones[] = {{"YST", 135},   {"YDT", 120},  {"PST", 120},  {"PDT", 105},   {"MST", 105},
                  {"MDT", 90},    {"CST", 90},   {"CDT", 75},   {"EST", 75},    {"EDT", 60},
                  {"AST", 60},    {"ADT", 45},   {"NST", 52.5}, {"NDT", 37.5},  {"GMT", 0},
                  {"BST", -15},   {"CET", -15},  {"CEST", -30}, {"EET", -30},   {"EEST", -45},
                  {"AST", -45},   {"ADT", -60},  {"GST", -60},  {"GDT", -75},   {"IST", -82.5},
                  {"IDT", -97.5}, {"JST", -135}, {"NDT", -150}, {"NZST", -180}, {"NZDT", -195}};
    const char *cp = text;
    if ((s.solar_time = *cp == '+')) ++cp;
    while (std::isdigit(static_cast<unsigned char>(*cp))) ++cp;
    if (*cp == ':') {
        s.hour = std::atoi(text) + std::atoi(++cp) / 60.0;
    } else {
        s.hour = std::atof(text);
        if (*cp == '.') ++cp;
    }
    while (std::isdigit(static_cast<unsigned char>(*cp))) ++cp;
    if (!*cp) return false;
    if (s.solar_time || !std::isalpha(static_cast<unsigned char>(*cp))) {
        std::fprintf(stderr, "%s: bad time format: %s\n", prog, text);
        std::exit(1);
    }
    for (const auto &zone : kZones) {  // (RADIANCE's upper-casing: ASCII letters' bit 5 off)
        size_t j = 0;
        while (j < sizeof zone.name && cp[j] && (cp[j] & ~0x20) == zone.name[j]) ++j;
        if (j < sizeof zone.name && !cp[j] && !zone.name[j]) {
            s.site.meridian = zone.meridian * (M_PI / 180);
            return true;
        }
    }
    std::fprintf(stderr, "%s: unknown time zone: %s\nKnown time zones:\n\t%s", prog, cp,
                 kZones[0].name);
    for (size_t i = 1; i < sizeof kZones / sizeof kZones[0]; ++i)
        std::fprintf(stderr, " %s", kZones[i].name);
    std::fputc('\n', stderr);
    std::exit(1);
}

// E0 F2 / L0 for the clear and intermediate skies (a polynomial in the sun's altitude).
double NormalisedSky(const Sky &s) {
    static const double kCoefficients[2][5] = {
        {2.766521, 0.547665, -0.369832, 0.009237, 0.059229},  // clear
        {3.5556, -2.7152, -1.3081, 1.0660, 0.60227}};         // intermediate
    const double *c = kCoefficients[s.type == kIntermediate];
    const double x = (s.altitude - M_PI / 4.0) / (M_PI / 4.0);
    double value = c[4];
    for (int i = 3; i >= 0; --i) value = value * x + c[i];
    return value;
}

// The sun's direction, the sky's normalisation, zenith, ground and sun brightness.
void Compute(const char *prog, Sky &s) {
    if (s.month) {
        double declination, st = s.hour;
        if (s.year) {
            const double mjd = AlmanacDate(s.site, s.year, s.month, s.day, s.hour);
            declination = AlmanacDeclination(s.site, mjd, s.solar_time ? nullptr : &st);
        } else {
            const int jd = DayOfYear(s.month, s.day);
            declination = SolarDeclination(jd);
            if (!s.solar_time) st = s.hour + SolarTimeOffset(jd, s.site);
        }
        s.altitude = SolarAltitude(s.site, declination, st);
        s.azimuth = SolarAzimuth(s.site, declination, st);
        std::printf("# Local solar time: %.2f\n", st);
        std::printf("# Solar altitude and azimuth: %.1f %.1f\n", 180. / M_PI * s.altitude,
                    180. / M_PI * s.azimuth);
    }
    if (!s.Overcast() && s.altitude > 87. * M_PI / 180.) {
        std::fprintf(stderr,
                     "%s: warning - sun too close to zenith, reducing altitude to 87 degrees\n",
                     prog);
        std::printf("# warning - sun too close to zenith, reducing altitude to 87 degrees\n");
        s.altitude = 87. * M_PI / 180.;
    }
    s.dir[0] = -std::sin(s.azimuth) * std::cos(s.altitude);
    s.dir[1] = -std::cos(s.azimuth) * std::cos(s.altitude);
    s.dir[2] = std::sin(s.altitude);
    double norm = 1.0;
    switch (s.type) {
        case kUniform:
            norm = 1.0;
            break;
        case kOvercast:
            norm = 0.777778;
            break;
        case kClear:
            s.f2 = 0.274 * (0.91 + 10.0 * std::exp(-3.0 * (M_PI / 2.0 - s.altitude)) +
                            0.45 * s.dir[2] * s.dir[2]);
            norm = NormalisedSky(s) / s.f2 / M_PI;
            break;
        case kIntermediate:
            s.f2 = (2.739 + .9891 * std::sin(.3119 + 2.6 * s.altitude)) *
                   std::exp(-(M_PI / 2.0 - s.altitude) * (.4441 + 1.48 * s.altitude));
            norm = NormalisedSky(s) / s.f2 / M_PI;
            break;
    }
    if (s.zenith_unit == -1) {
        s.zenith /= norm * M_PI;
    } else if (s.zenith_unit == 0) {
        if (s.Overcast())
            s.zenith = 8.6 * s.dir[2] + .123;
        else
            s.zenith = (1.376 * s.turbidity - 1.81) * std::tan(s.altitude) + 0.38;
        if (s.type == kIntermediate) s.zenith = (s.zenith + 8.6 * s.dir[2] + .123) / 2.0;
        if (s.zenith < 0.0)
            s.zenith = 0.0;
        else
            s.zenith *= 1000.0 / kSkyEfficacy;
    }
    s.ground = s.zenith * norm;
    std::printf("# Ground ambient level: %.1f\n", s.ground);
    if (!s.Overcast() && s.dir[2] > 0.0 && (!s.solar_unit || s.solar > 0.0)) {
        if (s.solar_unit == -1) {
            s.solar /= 6e-5 * s.dir[2];
        } else if (s.solar_unit == 0) {
            s.solar = 1.5e9 / kSunEfficacy * (1.147 - .147 / (s.dir[2] > .16 ? s.dir[2] : .16));
            if (s.type == kIntermediate) s.solar *= 0.15;  // (RADIANCE's fudge factor)
        }
        s.ground += 6e-5 / M_PI * s.solar * s.dir[2];
    } else {
        s.sun = false;
    }
    s.ground *= s.ground_reflectance;
}

void Print(const Sky &s) {
    if (s.sun) {
        std::printf("\nvoid light solar\n0\n0\n3 %.2e %.2e %.2e\n", s.solar, s.solar, s.solar);
        std::printf("\nsolar source sun\n0\n0\n4 %f %f %f 0.5\n", s.dir[0], s.dir[1], s.dir[2]);
    }
    std::printf("\nvoid brightfunc skyfunc\n2 skybr skybright.cal\n0\n");
    if (s.Overcast())
        std::printf("3 %d %.2e %.2e\n", s.type, s.zenith, s.ground);
    else
        std::printf("7 %d %.2e %.2e %.2e %f %f %f\n", s.type, s.zenith, s.ground, s.f2, s.dir[0],
                    s.dir[1], s.dir[2]);
}

void PrintDefaults(const Sky &s) {
    std::printf("+s\t\t\t\t# Sunny sky with sun\n");
    std::printf("-g %f\t\t\t# Ground plane reflectance\n", s.ground_reflectance);
    std::printf("-t %f\t\t\t# Atmospheric turbidity\n", s.turbidity);
    std::printf("-a %f\t\t\t# Site latitude (degrees)\n", s.site.latitude * (180 / M_PI));
    std::printf("-o %f\t\t\t# Site longitude (degrees)\n", s.site.longitude * (180 / M_PI));
    std::printf("-m %f\t\t\t# Standard meridian (degrees)\n", s.site.meridian * (180 / M_PI));
}

int Main(int argc, char **argv) {
    const char *prog = argv[0];
    Sky s;
    if (argc == 2 && std::strcmp(argv[1], "-defaults") == 0) {
        PrintDefaults(s);
        return 0;
    }
    if (argc < 4) UseError(prog, "arg count");
    bool zone_given = false;
    if (std::strcmp(argv[1], "-ang") == 0) {
        s.altitude = std::atof(argv[2]) * (M_PI / 180);
        s.azimuth = std::atof(argv[3]) * (M_PI / 180);
    } else {
        s.month = std::atoi(argv[1]);
        if (s.month < 1 || s.month > 12) UseError(prog, "bad month");
        s.day = std::atoi(argv[2]);
        if (s.day < 1 || s.day > 31) UseError(prog, "bad day");
        zone_given = ParseHour(prog, argv[3], s);
    }
    // An option's value: the next argument (RADIANCE reads past the end as a null pointer,
    // which crashes it; this refuses).
    const auto next = [&](int *i) -> const char * {
        if (*i + 1 >= argc) UseError(prog, std::string("missing value for ") + argv[*i]);
        return argv[++*i];
    };
    for (int i = 4; i < argc; ++i) {
        if (argv[i][0] != '-' && argv[i][0] != '+') UseError(prog, "bad option");
        switch (argv[i][1]) {
            case 's':
                s.type = kClear;
                s.sun = argv[i][0] == '+';
                break;
            case 'y':
                s.year = std::atoi(next(&i));
                break;
            case 'r':
            case 'R':
                s.solar_unit = argv[i][1] == 'R' ? -1 : 1;
                s.solar = std::atof(next(&i));
                break;
            case 'c':
                s.type = kOvercast;
                break;
            case 'u':
                s.type = kUniform;
                break;
            case 'i':
                s.type = kIntermediate;
                s.sun = argv[i][0] == '+';
                break;
            case 't':
                s.turbidity = std::atof(next(&i));
                break;
            case 'b':
            case 'B':
                s.zenith_unit = argv[i][1] == 'B' ? -1 : 1;
                s.zenith = std::atof(next(&i));
                break;
            case 'g':
                s.ground_reflectance = std::atof(next(&i));
                break;
            case 'a':
                s.site.latitude = std::atof(next(&i)) * (M_PI / 180);
                break;
            case 'o':
                s.site.longitude = std::atof(next(&i)) * (M_PI / 180);
                break;
            case 'm': {
                const char *v = next(&i);
                if (!zone_given) s.site.meridian = std::atof(v) * (M_PI / 180);  // a zone wins
                break;
            }
            default:
                UseError(prog, std::string("unknown option: ") + argv[i]);
        }
    }
    if (s.year && (s.year < 1950 || s.year > 2050))
        std::fprintf(stderr, "%s: warning - year should be in range 1950-2050\n", prog);
    if (s.month && !s.solar_time && std::fabs(s.site.meridian - s.site.longitude) > 45 * M_PI / 180)
        std::fprintf(stderr, "%s: warning - %.1f hours btwn. standard meridian and longitude\n",
                     prog, (s.site.longitude - s.site.meridian) * 12 / M_PI);
    std::printf("# %s", CommandLine(argc, argv).c_str());
    Compute(prog, s);
    Print(s);
    return 0;
}

}  // namespace
}  // namespace dayflux

int main(int argc, char **argv) { return dayflux::RunTool(argc, argv, dayflux::Main); }
