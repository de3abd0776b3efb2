#include "daysim/ds_illum.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <cstdio>
#include <memory>

#include "daysim/patches.h"
#include "daysim/suns.h"
#include "sky/perez_tables.h"
#include "sky/solar.h"
#include "sky/weather.h"
#include "util/errors.h"
#include "util/files.h"
#include "util/strings.h"

namespace dayflux {

namespace {

double Rad(double deg) { return deg * (M_PI / 180.0); }
double Deg(double rad) { return rad * (180.0 / M_PI); }

// The sun's disc (0.533 degrees) as a solid angle.
const double kSunSolidAngle = 2 * M_PI * (1 - std::cos(Rad(0.2665)));
constexpr double kMinSunAngle = 0.0093026;  // radians: the disc's diameter
constexpr double kPrecipitableWater = 2;    // cm, fixed by DAYSIM
// DAYSIM's clearness bins for the efficacies end at 12.1, where its clamp puts the clearest
// skies: they fall in no bin and take bin 0's (overcast) efficacies (kept: docs/compat.md).
constexpr double kEfficacyBounds[9] = {1, 1.065, 1.230, 1.500, 1.950, 2.800, 4.500, 6.200, 12.1};
constexpr double kLuminanceBounds[9] = {1, 1.065, 1.230, 1.500, 1.950, 2.800, 4.500, 6.200, 14};

int Bin(const double (&bounds)[9], double clearness) {
    for (int i = 0; i < 8; ++i)
        if (clearness >= bounds[i] && clearness < bounds[i + 1]) return i;
    return 0;
}

// DAYSIM's sun.c: solar time minus standard time (hours), declination, altitude, azimuth (from
// south, west positive).
struct SunFormulas {
    double latitude, longitude, meridian;  // radians, west positive
    double TimeOffset(int jd) const {
        return 0.170 * std::sin((4 * M_PI / 373) * (jd - 80)) -
               0.129 * std::sin((2 * M_PI / 355) * (jd - 8)) + 12 * (meridian - longitude) / M_PI;
    }
    double Altitude(double sd, double st) const {
        return std::asin(std::sin(latitude) * std::sin(sd) -
                         std::cos(latitude) * std::cos(sd) * std::cos(st * (M_PI / 12)));
    }
    double Azimuth(double sd, double st) const {
        return -std::atan2(std::cos(sd) * std::sin(st * (M_PI / 12)),
                           -std::cos(latitude) * std::sin(sd) -
                               std::sin(latitude) * std::cos(sd) * std::cos(st * (M_PI / 12)));
    }
    // Solar time of sunset (hours), NaN where the sun does not set or rise.
    double Sunset(int jd) const {
        const double w = -std::tan(latitude) * std::tan(DaysimDeclination(jd));
        return Deg(M_PI / 2 - std::atan2(w, std::sqrt(1 - w * w))) / 15 + 12;
    }
};

struct Perez {
    double a, b, c, d, e;
    double Relative(double zeta, double gamma) const {
        return (1 + a * std::exp(b / std::cos(zeta))) *
               (1 + c * std::exp(d * gamma) + e * std::cos(gamma) * std::cos(gamma));
    }
};

// DAYSIM's table has a few of Perez's coefficients as they print from float (24.721901 for
// 24.7219), which moves its skies by about 1e-7.
struct DaysimCoefficients {
    double x[8][20];
    DaysimCoefficients() {
        for (int k = 0; k < 8; ++k)
            for (int i = 0; i < 20; ++i) x[k][i] = kPerezCoefficients[k][i];
        for (auto &c : x)
            for (double &v : c) {
                if (v == 24.7219) v = 24.721901;
                if (v == -37.7) v = -37.700001;
                if (v == 33.3389) v = 33.338902;
                if (v == -18.3) v = -18.299999;
                if (v == 52.0781) v = 52.078098;
                if (v == -21.5906) v = -21.590599;
                if (v == -46.1148) v = -46.114799;
            }
    }
};

Perez LuminanceCoefficients(double zenith, double clearness, double brightness) {
    static const DaysimCoefficients kDaysim;
    if (clearness > 1.065 && clearness < 2.8 && brightness < 0.2) brightness = 0.2;
    const int k = Bin(kLuminanceBounds, clearness);
    const double *x = kDaysim.x[k];
    double c[5];
    for (int i = 0; i < 5; ++i)
        c[i] =
            x[4 * i] + x[4 * i + 1] * zenith + brightness * (x[4 * i + 2] + x[4 * i + 3] * zenith);
    if (k == 0) {
        c[2] = std::exp(std::pow(brightness * (x[8] + x[9] * zenith), x[10])) - x[11];
        c[3] = -std::exp(brightness * (x[12] + x[13] * zenith)) + x[14] + brightness * x[15];
    }
    return {c[0], c[1], c[2], c[3], c[4]};
}

struct Direction {
    double x, y, z;
};
std::vector<Direction> PatchDirections() {
    std::vector<Direction> d(kDaysimDiffusePatches);
    for (int j = 0; j < kDaysimDiffusePatches; ++j) DaysimPatchDirection(j, &d[j].x);
    return d;
}

// The irradiances (W/m2) and Perez parameters of one step, and the illuminances (lux).
struct Atmosphere {
    double zenith = 0;  // of the sun, radians
    double dir_irrad = 0, dif_irrad = 0, dir_illum = 0, dif_illum = 0;
    double brightness = 0, clearness = 0, eccentricity = 1;

    double AirMass() const {
        return 1 / (std::cos(zenith) + 0.15 * std::pow(93.885 - Deg(zenith), -1.253));
    }
    void Parametrise() {
        brightness = dif_irrad * AirMass() / (1367 * eccentricity);
        const double z3 = 1.041 * zenith * zenith * zenith;
        clearness = dif_irrad > 0 ? ((dif_irrad + dir_irrad) / dif_irrad + z3) / (1 + z3) : 0;
    }
    void Clamp() {
        if (clearness < 1) clearness = 1;
        if (clearness > 12.1) clearness = 12.1;
        if (brightness < 0.01) brightness = 0.01;
        if (brightness > 0.6) brightness = 0.6;
    }
    double DiffuseEfficacy() const {
        const Efficacy &e = kDiffuseEfficacy[Bin(kEfficacyBounds, clearness)];
        return e.a + e.b * kPrecipitableWater + e.c * std::cos(zenith) + e.d * std::log(brightness);
    }
    double DirectEfficacy() const {
        const Efficacy &e = kDirectEfficacy[Bin(kEfficacyBounds, clearness)];
        return std::max(0.0, e.a + e.b * kPrecipitableWater + e.c * std::exp(5.73 * zenith - 5) +
                                 e.d * brightness);
    }
    void CheckIlluminances() {
        if (dir_illum >= 0 && dir_illum <= 127500 && dif_illum > 0) return;
        if (dir_illum > 127500)
            dir_illum = 127500;
        else
            dir_illum = dif_illum = 0;
    }
    // Units 3: the irradiances from the illuminances, by DAYSIM's five passes.
    void IrradiancesFromIlluminances() {
        const auto clamp = [this] {
            if (clearness > 12) clearness = 12;
            if (brightness < 0.05) brightness = 0.01;
        };
        dif_irrad = dif_illum * 1367 / 127500;
        dir_irrad = dir_illum * 1367 / 127500;
        Parametrise();
        clamp();
        for (int pass = 0; pass < 5; ++pass) {
            dif_irrad = dif_illum / DiffuseEfficacy();
            dir_irrad = dir_illum / DirectEfficacy();
            Parametrise();
            clamp();
        }
    }
};

// normsc(): the ground's share of the zenith luminance (Perez), by a polynomial in the sun's
// altitude.
double NormFactor(double clearness, double altitude) {
    static constexpr double kClear[5] = {2.766521, 0.547665, -0.369832, 0.009237, 0.059229};
    static constexpr double kIntermediate[5] = {3.5556, -2.7152, -1.3081, 1.0660, 0.60227};
    const auto poly = [altitude](const double(&n)[5]) {
        const double x = (altitude - M_PI / 4) / (M_PI / 4);
        double v = n[4];
        for (int i = 3; i >= 0; --i) v = v * x + n[i];
        return v;
    };
    if (clearness == 1) return 0.777778;
    if (clearness >= 6) {
        const double f2 = 0.274 * (0.91 + 10 * std::exp(-3 * (M_PI / 2 - altitude)) +
                                   0.45 * std::sin(altitude) * std::sin(altitude));
        return poly(kClear) / f2 / M_PI;
    }
    if (clearness > 1) {
        const double f2 = (2.739 + 0.9891 * std::sin(0.3119 + 2.6 * altitude)) *
                          std::exp(-(M_PI / 2 - altitude) * (0.4441 + 1.48 * altitude));
        return poly(kIntermediate) / f2 / M_PI;
    }
    // A clearness that is not a number (lux data with no direct light where the direct efficacy
    // is 0: DAYSIM divides 0 by 0) gives the ground no light, as in DAYSIM.
    return 0;
}

}  // namespace

struct DaysimSkyModel::Impl {
    const DaysimProject &p;
    SunFormulas sun;
    DaysimSunTable calendar;
    int columns;
    double half_step;  // hours
    std::vector<Direction> patches = PatchDirections();
    std::vector<std::pair<int, int>> column_of_entry;  // (month, hour) -> column, by j1

    Impl(const DaysimProject &project, int cols)
        : p(project),
          sun{Rad(*project.latitude), Rad(*project.longitude), Rad(*project.time_zone)},
          calendar(DaysimDirectSuns(Rad(*project.latitude), false)),
          columns(cols),
          half_step(0.5 * project.time_step / 60.0) {}

    // The hour moved into the sunlit part of a step that holds sunrise or sunset.
    double Shifted(int jd, double hour) const {
        const double set = sun.Sunset(jd);
        const double sunrise = 24 - sun.TimeOffset(jd) - set, sunset = set - sun.TimeOffset(jd);
        if (hour - half_step <= sunrise && hour + half_step > sunrise)
            return 0.5 * (hour + half_step) + 0.5 * sunrise;
        if (hour - half_step <= sunset && hour + half_step > sunset)
            return 0.5 * (hour - half_step) + 0.5 * sunset;
        return hour;
    }

    DaysimStepSky Step(int month, int day, double hour, double dir, double dif) const;
    void Sky(int jd, double hour, double dir, double dif, DaysimStepSky *s, double *sun_lum,
             double *sun_rad) const;
    void Direct(int jd, double hour, double sun_lum, double sun_rad, DaysimStepSky *s) const;
};

DaysimStepSky DaysimSkyModel::Impl::Step(int month, int day, double hour, double dir,
                                         double dif) const {
    DaysimStepSky s;
    const int jd = DayOfYear(month, day);
    const double altitude = sun.Altitude(DaysimDeclination(jd), hour + sun.TimeOffset(jd));
    if (dif < p.diffuse_threshold || altitude < 0) return s;
    s.dark = false;
    s.luminance.assign(columns, 0.f);
    s.radiance.assign(columns, 0.f);
    const double shifted = Shifted(jd, hour);
    double sun_lum = 0, sun_rad = 0;
    Sky(jd, shifted, dir, dif, &s, &sun_lum, &sun_rad);
    s.direct = dir > p.direct_threshold && p.coupling_mode == 0;
    if (s.direct) Direct(jd, shifted, sun_lum, sun_rad, &s);
    return s;
}

void DaysimSkyModel::Impl::Sky(int jd, double hour, double dir, double dif, DaysimStepSky *s,
                               double *sun_lum, double *sun_rad) const {
    const double sd = DaysimDeclination(jd), st = hour + sun.TimeOffset(jd);
    const double alpha = sun.Altitude(sd, st), azimuth = sun.Azimuth(sd, st);
    const Direction to_sun{-std::sin(azimuth) * std::cos(alpha),
                           -std::cos(azimuth) * std::cos(alpha), std::sin(alpha)};
    Atmosphere at;
    at.zenith = Rad(90 - Deg(alpha));
    const double g = 2 * M_PI * (jd - 1) / 365;
    at.eccentricity = 1.00011 + 0.034221 * std::cos(g) + 0.00128 * std::sin(g) +
                      0.000719 * std::cos(2 * g) + 0.000077 * std::sin(2 * g);
    if (p.weather_units == 3) {
        at.dir_illum = dir, at.dif_illum = dif;
        at.CheckIlluminances();
        at.IrradiancesFromIlluminances();
        at.Clamp();
    } else {
        at.dir_irrad = dir, at.dif_irrad = dif;
        if (p.weather_units == 2) {
            if (Deg(alpha) < 1)
                at.dir_irrad = at.dif_irrad = 0;
            else if (at.dir_irrad > 0)
                at.dir_irrad = dir / std::sin(alpha);
        }
        at.Parametrise();
        at.Clamp();
        at.dif_illum = at.dif_irrad * at.DiffuseEfficacy();
        at.dir_illum = at.dir_irrad * at.DirectEfficacy();
        at.CheckIlluminances();
    }
    const Perez perez = LuminanceCoefficients(at.zenith, at.clearness, at.brightness);
    // Normalised over a grid of 145 points around the sun, each weighing 2 pi / 144.
    static constexpr int kGrid[8][2] = {{84, 30}, {72, 30}, {60, 24}, {48, 24},
                                        {36, 18}, {24, 12}, {12, 6},  {0, 1}};
    double integral = 0;
    for (const auto &row : kGrid) {
        const double theta = Rad(row[0]);
        for (int j = 0; j < row[1]; ++j) {
            const double phi = Rad(360.0 / row[1] * j);
            double c = std::cos(at.zenith) * std::cos(theta) +
                       std::sin(at.zenith) * std::sin(theta) * std::cos(phi);
            const double gamma = c > 1 && c < 1.1 ? 0 : std::acos(c);
            integral += static_cast<float>(perez.Relative(theta, gamma)) * std::cos(theta);
        }
    }
    integral *= 2 * M_PI / 144;
    const double scale_lum = at.dif_illum / integral, scale_rad = at.dif_irrad / integral;
    *sun_lum = at.dir_illum / kSunSolidAngle;
    *sun_rad = at.dir_irrad / kSunSolidAngle;
    const double zenith_rel = perez.Relative(0, at.zenith);
    const double nf = NormFactor(at.clearness, alpha);
    // (DAYSIM's sun term takes 6.8e-5 sr for the disc.)
    const auto ground = [&](double scale, double sun_value) {
        return p.ground_reflectance *
               (zenith_rel * scale * nf +
                (at.clearness > 1 ? 6.8e-5 / M_PI * sun_value * std::sin(alpha) : 0));
    };
    const double ground_lum = ground(scale_lum, *sun_lum), ground_rad = ground(scale_rad, *sun_rad);
    if (at.clearness == 1) *sun_lum = *sun_rad = 0;
    for (int j = 0; j < kDaysimDiffusePatches; ++j) {
        const Direction &d = patches[j];
        const double cos_sun = d.x * to_sun.x + d.y * to_sun.y + d.z * to_sun.z;
        const double gamma =
            std::max(cos_sun < 1 ? std::acos(cos_sun) : kMinSunAngle, kMinSunAngle);
        const double z = d.z > 0.01 ? d.z : 0.01;
        // The sky fades into the ground below the horizon.
        const double up = std::pow(d.z + 1.01, 10), down = std::pow(d.z + 1.01, -10);
        const auto blend = [&](double scale, double ground) {
            const double sky = scale * (1 + perez.a * std::exp(perez.b / z)) *
                               (1 + perez.c * std::exp(perez.d * gamma) +
                                perez.e * std::cos(gamma) * std::cos(gamma));
            return std::max(0.0, (up * sky + down * ground) / (up + down));
        };
        float l = static_cast<float>(blend(scale_lum, ground_lum));
        float r = static_cast<float>(blend(scale_rad, ground_rad));
        s->luminance[j] = l > 180000 ? 0 : l;  // DAYSIM zeroes unreal values
        s->radiance[j] = r > 1700 ? 0 : r;
    }
}

void DaysimSkyModel::Impl::Direct(int jd, double hour, double sun_lum, double sun_rad,
                                  DaysimStepSky *s) const {
    // The design days around the date: the second half of the year uses the first half's
    // coefficients at the dates of equal declination.
    struct Span {
        int from, to, month0, month1, jd0, jd1;
    };
    static constexpr Span kSpans[] = {
        {355, 366, 12, 2, 355, 52}, {1, 52, 12, 2, 355, 52},    {52, 80, 2, 3, 52, 80},
        {80, 111, 3, 4, 80, 111},   {111, 172, 4, 6, 111, 172}, {172, 233, 4, 6, 233, 172},
        {233, 264, 3, 4, 264, 233}, {264, 294, 2, 3, 294, 264}, {294, 355, 12, 2, 355, 294}};
    const Span *span = nullptr;
    for (const Span &sp : kSpans)
        if (jd >= sp.from && jd < sp.to) span = &sp;
    CHECK(span != nullptr);
    const double st = hour + sun.TimeOffset(jd);
    const double alt = Deg(sun.Altitude(DaysimDeclination(jd), st));
    const double alt0 = Deg(sun.Altitude(DaysimDeclination(span->jd0), st));
    const double alt1 = Deg(sun.Altitude(DaysimDeclination(span->jd1), st));
    const auto bracket = [&](int month) {
        const double t = hour + sun.TimeOffset(DayOfYear(month, 21));
        for (int j = 1; j < 23; ++j)
            if (calendar.calendar[month][j].solar_time < t &&
                t < calendar.calendar[month][j + 1].solar_time)
                return std::make_pair(j, t);
        ErrorExit("no design-day hours around solar time " + FormatNumber(t) + " on day " +
                  std::to_string(jd) + " (the sun does not set at this latitude)");
    };
    const auto [h0, t0] = bracket(span->month0);
    const auto [h1, t1] = bracket(span->month1);
    const auto &c0 = calendar.calendar[span->month0], &c1 = calendar.calendar[span->month1];
    const double a0 = (alt1 - alt) / (alt1 - alt0), a1 = (alt - alt0) / (alt1 - alt0);
    struct Part {
        int month, hour;
        double w;
    };
    Part parts[4] = {{span->month0, h0,
                      (c0[h0].altitude >= 0) * a0 * (c0[h0 + 1].solar_time - t0) /
                          (c0[h0 + 1].solar_time - c0[h0].solar_time)},
                     {span->month0, h0 + 1,
                      (c0[h0 + 1].altitude >= 0) * a0 * (t0 - c0[h0].solar_time) /
                          (c0[h0 + 1].solar_time - c0[h0].solar_time)},
                     {span->month1, h1,
                      (c1[h1].altitude >= 0) * a1 * (c1[h1 + 1].solar_time - t1) /
                          (c1[h1 + 1].solar_time - c1[h1].solar_time)},
                     {span->month1, h1 + 1,
                      (c1[h1 + 1].altitude >= 0) * a1 * (t1 - c1[h1].solar_time) /
                          (c1[h1 + 1].solar_time - c1[h1].solar_time)}};
    double sum = 0;
    for (const Part &part : parts) sum += part.w;
    for (const Part &part : parts) {
        const double w = sum > 0 ? part.w / sum : 0;
        // DAYSIM numbers the calendar's entries with the sun above the horizon (months from
        // December, hours from 1) to find the coefficient's column.
        int column = kDaysimDiffusePatches - 1;
        for (const auto &[month, h] : column_of_entry) {
            ++column;
            if (month == part.month && h == part.hour) {
                if (column < columns) {
                    s->luminance[column] = static_cast<float>(sun_lum * w);
                    s->radiance[column] = static_cast<float>(sun_rad * w);
                }
                break;
            }
        }
    }
}

DaysimSkyModel::DaysimSkyModel(const DaysimProject &project, int columns) {
    auto impl = std::make_shared<Impl>(project, columns);
    for (int m : {12, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11})
        for (int h = 1; h < 24; ++h)
            if (impl->calendar.calendar[m][h].altitude > 0) impl->column_of_entry.push_back({m, h});
    impl_ = impl;
}

DaysimStepSky DaysimSkyModel::Step(int month, int day, double hour, double dir, double dif) const {
    return impl_->Step(month, day, hour, dir, dif);
}

namespace {

}  // namespace

std::vector<std::vector<float>> ReadDaysimDc(const std::string &file, size_t sensors,
                                             int columns) {
    const std::unique_ptr<InputSource> in = InputSource::Open(file);
    std::vector<std::vector<float>> rows;
    std::string line;
    while (true) {
        const FileLoc loc = in->Loc();
        if (!in->ReadLine(&line)) break;
        if (line.empty() || line[0] == '#') continue;
        const std::vector<std::string> words = SplitWords(line);
        if (words.size() != static_cast<size_t>(columns))
            ErrorExit(&loc, std::to_string(words.size()) +
                                " coefficients where the latitude gives " +
                                std::to_string(columns) + " (148 diffuse and " +
                                std::to_string(columns - 148) + " suns)");
        if (rows.size() == sensors)
            ErrorExit(&loc,
                      "more rows of coefficients than the " + std::to_string(sensors) + " sensors");
        rows.emplace_back(columns);
        for (int k = 0; k < columns; ++k)
            if (!ParseNumber(words[k], &rows.back()[k]))
                ErrorExit(&loc, "'" + words[k] + "' is not a number");
    }
    if (rows.size() != sensors)
        ErrorExit(file + ": " + std::to_string(rows.size()) + " rows of coefficients for " +
                  std::to_string(sensors) + " sensors (run gen_dc again?)");
    return rows;
}

namespace {

// One sensor's value at a step: the products rounded to float, summed in double, in DAYSIM's
// order and with its choices (negative diffuse coefficients after the first left out; suns
// where the luminance is above zero).
double Sum(const std::vector<float> &dc, const std::vector<float> &sky,
           const std::vector<float> &luminance, bool direct) {
    double sum = static_cast<float>(dc[0] * sky[0]);
    for (int i = 1; i < kDaysimDiffusePatches; ++i)
        if (dc[i] > 0) sum += static_cast<float>(dc[i] * sky[i]);
    if (!direct || dc.size() <= static_cast<size_t>(kDaysimDiffusePatches)) return sum;
    sum += static_cast<float>(dc[148] * sky[148]);
    for (size_t i = 149; i < dc.size(); ++i)
        if (luminance[i] > 0 && dc[i] != 0) sum += static_cast<float>(dc[i] * sky[i]);
    return sum;
}

// The reader checks the values against the file's own units; DAYSIM takes the project's, so
// check them against those too.
void CheckUnits(const DaysimProject &p, const std::string &name, const WeatherRecord &rec) {
    if (p.weather_units == 3 || (rec.dir <= 1500 && rec.dif <= 1500)) return;
    const FileLoc loc{name, rec.line};
    ErrorExit(&loc, "direct " + FormatNumber(rec.dir) + ", diffuse " + FormatNumber(rec.dif) +
                        ": more than the sun gives in W/m2 (lux? the project says "
                        "wea_data_short_file_units " +
                        std::to_string(p.weather_units) + ")");
}

// A step's line of the .ill (and of the blinds-down file, with down).
void Lines(const DaysimStepSky &s, const WeatherRecord &r,
           const std::vector<std::vector<float>> &dc, const std::vector<int> &units, bool down,
           std::string *line, std::string *line_down) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%d %d %.3f ", r.month, r.day, r.hour);
    *line = *line_down = buf;
    for (size_t j = 0; j < dc.size(); ++j) {
        const bool watts = units[j] >= 2;
        if (s.dark) {
            *line += " 0", *line_down += " 0";
            continue;
        }
        const std::vector<float> &values = watts ? s.radiance : s.luminance;
        const char *format = watts ? " %.2f" : " %.0f";
        std::snprintf(buf, sizeof buf, format, Sum(dc[j], values, s.luminance, s.direct));
        *line += buf;
        if (!down) continue;
        std::snprintf(buf, sizeof buf, format, 0.25 * Sum(dc[j], values, s.luminance, false));
        *line_down += buf;
    }
    *line += '\n', *line_down += '\n';
}

}  // namespace

void RunDsIllum(const DaysimProject &p, const DsIllumOptions &options) {
    for (const char *key : {"latitude", "longitude", "time_zone"})
        p.Require(key, p.where.count(key) > 0);
    p.Require("wea_data_short_file", !p.weather.empty());
    p.Require("sensor_file", !p.sensor_file.empty());
    p.Require("shading", !p.variants.empty());
    if (std::fabs(*p.time_zone - *p.longitude) > 30)
        ErrorExit(&p.where.at("time_zone"), "the time zone's meridian (" +
                                                FormatNumber(*p.time_zone) +
                                                ") lies over 30 "
                                                "degrees from the longitude (" +
                                                FormatNumber(*p.longitude) + ")");
    const std::string sensors_file = p.Path(p.sensor_file) + options.extension;
    const size_t sensors = CountSensors(sensors_file);
    std::vector<int> units = p.sensor_units;
    if (units.empty()) units.assign(sensors, p.output_units == 1 ? 2 : 0);
    if (units.size() != sensors)
        ErrorExit(&p.sensor_units_loc, "sensor_file_unit gives " + std::to_string(units.size()) +
                                           " units for the " + std::to_string(sensors) +
                                           " sensors of " + sensors_file);
    const int columns = kDaysimDiffusePatches +
                        static_cast<int>(DaysimDirectSuns(Rad(*p.latitude), false).suns.size());
    const DaysimSkyModel sky(p, columns);

    for (const DaysimVariant &v : p.variants) {
        const auto dc = ReadDaysimDc(p.Path(v.dc) + options.extension, sensors, columns);
        WeatherReader weather(p.Path(p.weather));
        if (weather.Header().units != p.weather_units)
            Warning(weather.Name() + ": weather_data_file_units " +
                    std::to_string(weather.Header().units) + " where the project says " +
                    std::to_string(p.weather_units) + " (the project's taken, as DAYSIM does)");
        OutputFile out(p.Path(v.ill) + options.extension);
        std::unique_ptr<OutputFile> down;
        if (!v.ill_blinds_down.empty())
            down = std::make_unique<OutputFile>(p.Path(v.ill_blinds_down) + options.extension);
        // Steps are read in blocks, their lines made in parallel and written in order.
        constexpr size_t kBlock = 256;
        std::vector<WeatherRecord> block;
        std::vector<std::string> lines(kBlock), lines_down(kBlock);
        WeatherRecord rec;
        bool more = true;
        while (more) {
            block.clear();
            while (block.size() < kBlock && (more = weather.Next(&rec))) {
                CheckUnits(p, weather.Name(), rec);
                block.push_back(rec);
            }
            tbb::parallel_for(size_t(0), block.size(), [&](size_t k) {
                const WeatherRecord &r = block[k];
                const DaysimStepSky s = sky.Step(r.month, r.day, r.hour, r.dir, r.dif);
                Lines(s, r, dc, units, down != nullptr, &lines[k], &lines_down[k]);
            });
            for (size_t k = 0; k < block.size(); ++k) {
                out.Write(lines[k]);
                if (down) down->Write(lines_down[k]);
            }
        }
        out.Commit();
        if (down) down->Commit();
    }
}

}  // namespace dayflux
