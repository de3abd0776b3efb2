#include "sky/perez.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "sky/perez_kernel.h"
#include "sky/perez_tables.h"
#include "sky/weather.h"

namespace dayflux {

namespace {

constexpr double kEfficacy = 179.;          // RADIANCE's WHTEFFICACY, lm/W
constexpr double kSolarConstantE = 1367.0;  // W/m2
constexpr double kSolarConstantL = 127.5;   // klx
constexpr double kDewPoint = 11.0;          // deg C, gendaymtx's fixed surface dew point
constexpr double kTiny = 1e-6;              // RADIANCE's FTINY

double Rad(double deg) { return deg * (M_PI / 180.); }

// The Perez quantities of one step, named as in the papers.
struct Atmosphere {
    double sun_zenith = 0, precipitable_water = 0, eccentricity = 1;
    double diff_irrad = 0, dir_irrad = 0, diff_illum = 0, dir_illum = 0;
    double brightness = 0, clearness = 0;

    double AirMass() const {
        return 1.0 / (std::cos(sun_zenith) +
                      0.15 * std::pow(93.885 - sun_zenith * (180. / M_PI), -1.253));
    }
    double Brightness() const { return diff_irrad * AirMass() / (kSolarConstantE * eccentricity); }
    double Clearness() const {
        const double z3 = sun_zenith * sun_zenith * sun_zenith;
        return ((diff_irrad + dir_irrad) / diff_irrad + 1.041 * z3) / (1.0 + 1.041 * z3);
    }
    int Category() const {
        int i = 0;
        for (; i < 8; ++i)
            if (clearness >= kClearnessBounds[i] && clearness < kClearnessBounds[i + 1]) break;
        return i;
    }
    double DiffuseEfficacy(int i) const {
        const Efficacy &e = kDiffuseEfficacy[i];
        return e.a + e.b * precipitable_water + e.c * std::cos(sun_zenith) +
               e.d * std::log(brightness);
    }
    double DirectEfficacy(int i) const {
        const Efficacy &e = kDirectEfficacy[i];
        return std::max(e.a + e.b * precipitable_water + e.c * std::exp(5.73 * sun_zenith - 5.0) +
                            e.d * brightness,
                        0.0);
    }
    // Photometric input: iterate to the irradiances that give the measured illuminances.
    int FromIlluminance() {
        double test1 = 0.1, test2 = 0.1;
        int counter = 0;
        diff_irrad = diff_illum * kSolarConstantE / (kSolarConstantL * 1000.0);
        dir_irrad = dir_illum * kSolarConstantE / (kSolarConstantL * 1000.0);
        brightness = std::max(Brightness(), 0.01);
        clearness = std::min(Clearness(), 12.0);
        while ((std::fabs(diff_irrad - test1) > 10.0 || std::fabs(dir_irrad - test2) > 10.0) &&
               counter != 5) {
            test1 = diff_irrad;
            test2 = dir_irrad;
            ++counter;
            const int i = Category();
            diff_irrad = diff_illum / DiffuseEfficacy(i);
            dir_irrad = DirectEfficacy(i);
            if (dir_irrad > 0.1) dir_irrad = dir_illum / dir_irrad;
            brightness = Brightness();
            clearness = Clearness();
            if (clearness > 12.0) clearness = 12.0;
            if (brightness < 0.01) brightness = 0.01;
        }
        return Category();
    }
};

void PerezParameters(double sz, double epsilon, double delta, int index, double out[5]) {
    if (epsilon > 1.065 && epsilon < 2.8 && delta < 0.2) delta = 0.2;
    double x[5][4];
    for (int i = 0; i < 5; ++i)
        for (int j = 0; j < 4; ++j) x[i][j] = kPerezCoefficients[index][4 * i + j];
    for (int i = 0; i < 5; ++i) out[i] = x[i][0] + x[i][1] * sz + delta * (x[i][2] + x[i][3] * sz);
    if (index == 0) {  // overcast: c and d from Eqns. 7 and 8
        out[2] = std::exp(std::pow(delta * (x[2][0] + x[2][1] * sz), x[2][2])) - x[2][3];
        out[3] = -std::exp(delta * (x[3][0] + x[3][1] * sz)) + x[3][2] + delta * x[3][3];
    }
}

// CIE luminance weights of RADIANCE's standard primaries (bright()).
double Brightness(const float c[3]) {
    const double xr = 0.640, yr = 0.330, xg = 0.290, yg = 0.600, xb = 0.150, yb = 0.060,
                 xw = 1. / 3., yw = 1. / 3.;
    const double D = xr * (yg - yb) + xg * (yb - yr) + xb * (yr - yg);
    const double CrD = (1. / yw) * (xw * (yg - yb) - yw * (xg - xb) + xg * yb - xb * yg);
    const double CgD = (1. / yw) * (xw * (yb - yr) - yw * (xb - xr) - xr * yb + xb * yr);
    const double CbD = (1. / yw) * (xw * (yr - yg) - yw * (xr - xg) + xr * yg - xg * yr);
    return yr * CrD / D * c[0] + yg * CgD / D * c[1] + yb * CbD / D * c[2];
}

}  // namespace

SkyModel::SkyModel(const SkyOptions &options) : options_(options), patches_(options.mf) {
    const int n = patches_.Size();
    cos_zenith_.resize(n);
    sin_zenith_.resize(n);
    inv_cos_zenith_.resize(n);
    cos_azi_.resize(n);
    sin_azi_.resize(n);
    horizontal_weight_.resize(n);
    row_of_.resize(n);
    direction_.resize(n);
    for (int p = 1; p < n; ++p) {
        patches_.Direction(p, direction_[p].data());
        const double zsa = M_PI * 0.5 - patches_.Altitude(p);
        cos_zenith_[p] = std::cos(zsa);
        sin_zenith_[p] = std::sin(zsa);
        inv_cos_zenith_[p] = 1.0 / std::cos(zsa);
        cos_azi_[p] = std::cos(static_cast<double>(patches_.Azimuth(p)));
        sin_azi_[p] = std::sin(static_cast<double>(patches_.Azimuth(p)));
        // The normalisation weight uses RADIANCE's table sine of the patch altitude.
        horizontal_weight_[p] = TableSin(patches_.Altitude(p));
    }
    int p = 1;
    for (int r = 0; r < patches_.Rows(); ++r)
        for (int j = 0; j < patches_.PatchesInRow(r); ++j) row_of_[p++] = r;
    sky_black_ = Brightness(options_.sky_color) <= 1e-4;
}

double SkyModel::RowFactor(const SkyStep &s, int p) const {
    if (!s.sky_in_use || s.uniform) return 0;
    return 1.0 + s.perez[0] * std::exp(s.perez[1] * inv_cos_zenith_[p]);
}

double SkyModel::CosToSun(const SkyStep &s, int p) const {
    // Cosine of the angle between the sun and the patch centre (RADIANCE's Eqn. 8-20), kept
    // inside acos's domain.
    const double cos_azi_diff = cos_azi_[p] * s.cos_azimuth + sin_azi_[p] * s.sin_azimuth;
    const double cg =
        s.cos_sun_zenith * cos_zenith_[p] + s.sin_sun_zenith * sin_zenith_[p] * cos_azi_diff;
    return std::clamp(cg, -1.0, 1.0);
}

float SkyModel::RelativeLuminance(const SkyStep &s, int p, double row_factor) const {
    const double x = CosToSun(s, p);
    float l;
    PerezRelativeLuminance(1, &x, &row_factor, &s.perez[2], &s.perez[3], &s.perez[4], &l);
    return l;
}

SkyStep SkyModel::Prepare(double dir, double dif, WeatherUnits units, double altitude,
                          double azimuth, int julian_date, bool add_sun) const {
    bool finite;
    SkyStep s =
        PrepareAsRadiance(dir, dif, units, altitude, azimuth, julian_date, add_sun, &finite);
    // Units 2: divided by the sine of a sun at the horizon, a few W/m2 on the horizontal become
    // more than the sun gives normal to it, and the Perez sky can overflow to NaN (RADIANCE's
    // too). Only then is the derived value capped at that (the horizontal value stays within a
    // few percent), so that every finite sky stays RADIANCE's.
    if (!finite && units == WeatherUnits::kDirectHorizontal && altitude > kTiny &&
        dir / std::sin(altitude) > kMostIrradiance) {
        s = PrepareAsRadiance(kMostIrradiance * std::sin(altitude), dif, units, altitude, azimuth,
                              julian_date, add_sun, &finite);
        s.direct_capped = true;
    }
    return s;
}

SkyStep SkyModel::PrepareAsRadiance(double dir, double dif, WeatherUnits units, double altitude,
                                    double azimuth, int julian_date, bool add_sun,
                                    bool *finite) const {
    *finite = true;
    SkyStep s;
    s.azimuth = azimuth;
    s.cos_azimuth = std::cos(azimuth);
    s.sin_azimuth = std::sin(azimuth);
    Atmosphere a;
    a.precipitable_water = std::exp(0.07 * kDewPoint - 0.075);
    if (altitude <= 0.0)
        a.sun_zenith = Rad(90.0);
    else if (altitude >= Rad(87.0))
        a.sun_zenith = Rad(3.0);  // keeps the circumsolar region off the zenith
    else
        a.sun_zenith = Rad(90.0) - altitude;
    const double day_angle = (julian_date - 1.0) * (2.0 * M_PI / 365.0);
    a.eccentricity = 1.00011 + 0.034221 * std::cos(day_angle) + 0.00128 * std::sin(day_angle) +
                     0.000719 * std::cos(2.0 * day_angle) + 0.000077 * std::sin(2.0 * day_angle);
    if (units == WeatherUnits::kDirectHorizontal && altitude > kTiny) dir /= std::sin(altitude);
    int index;
    if (units != WeatherUnits::kPhotometric) {
        a.dir_irrad = dir;
        a.diff_irrad = dif;
        a.brightness = a.Brightness();
        a.clearness = a.Clearness();
        if (a.clearness > 11.9) a.clearness = 11.9;
        if (a.brightness < 0.01) a.brightness = 0.01;
        index = a.Category();
        a.diff_illum = a.diff_irrad * a.DiffuseEfficacy(index);
        a.dir_illum = a.dir_irrad * a.DirectEfficacy(index);
    } else {
        a.dir_illum = dir;
        a.diff_illum = dif;
        index = a.FromIlluminance();
    }
    if (options_.solar_radiance) {
        a.diff_illum = a.diff_irrad * kEfficacy;
        a.dir_illum = a.dir_irrad * kEfficacy;
    }
    s.dir_illum = a.dir_illum;
    // Ground: diffuse plus direct on the horizontal, reflected.
    float g = static_cast<float>(a.diff_illum);
    if (altitude > 0) g = static_cast<float>(g + a.dir_illum * std::sin(altitude));
    g = static_cast<float>(g * (1. / M_PI / kEfficacy));
    for (int k = 0; k < 3; ++k) s.ground[k] = g * options_.ground_reflectance[k];

    if (!sky_black_) {
        s.sky_in_use = true;
        PerezParameters(a.sun_zenith, a.clearness, a.brightness, index, s.perez);
        s.cos_sun_zenith = std::cos(a.sun_zenith);
        s.sin_sun_zenith = std::sin(a.sun_zenith);
        double norm = 0;  // relative horizontal illuminance of the sky patches
        // Row by row: the luminances of a row at once, then summed in patch order as RADIANCE does.
        std::vector<double> x, rf, c, d, e;
        std::vector<float> l;
        for (int r = 0; r < patches_.Rows(); ++r) {
            const int p0 = patches_.FirstPatchOfRow(r), m = patches_.PatchesInRow(r);
            x.resize(m);
            l.resize(m);
            rf.assign(m, RowFactor(s, p0));
            c.assign(m, s.perez[2]);
            d.assign(m, s.perez[3]);
            e.assign(m, s.perez[4]);
            for (int k = 0; k < m; ++k) x[k] = CosToSun(s, p0 + k);
            PerezRelativeLuminance(m, x.data(), rf.data(), c.data(), d.data(), e.data(), l.data());
            for (int k = 0; k < m; ++k)
                norm += static_cast<double>(l[k]) * horizontal_weight_[p0 + k] *
                        patches_.SolidAngle(p0 + k);
        }
        if (norm <= kTiny) {  // zero sky: make it uniform
            s.uniform = true;
            norm = M_PI;
        }
        s.scale = (a.diff_illum / norm) * (1. / kEfficacy);
        *finite = std::isfinite(norm) && std::isfinite(s.scale);
    }
    *finite = *finite && std::isfinite(a.dir_illum);

    // The sun, spread over the nearest patches with weights 1 / (1.002 - cos(angle)).
    const float *sc = options_.sun_color;
    if (add_sun && a.dir_illum > 1e-4 && Brightness(sc) > 1e-4) {
        const int nsuns = std::clamp(options_.sun_patches, 1, 4);
        double near_dot[4];
        int near_patch[4] = {0, 0, 0, 0};
        for (int i = 0; i < nsuns; ++i) near_dot[i] = -1.;
        double sv[3];
        sv[1] = std::cos(altitude);
        sv[0] = sv[1] * std::sin(azimuth);
        sv[1] *= std::cos(azimuth);
        sv[2] = std::sin(altitude);
        for (int p = 1; p < patches_.Size(); ++p) {
            const double *pv = direction_[p].data();
            const double d = pv[0] * sv[0] + pv[1] * sv[1] + pv[2] * sv[2];
            for (int i = 0; i < nsuns; ++i)
                if (d > near_dot[i]) {
                    for (int j = nsuns; --j > i;)
                        near_dot[j] = near_dot[j - 1], near_patch[j] = near_patch[j - 1];
                    near_dot[i] = d;
                    near_patch[i] = p;
                    break;
                }
        }
        double wt[4], wtot = 0;
        for (int i = nsuns; i--;) wtot += wt[i] = 1. / (1.002 - near_dot[i]);
        for (int i = nsuns; i--;) {
            float v = static_cast<float>(wt[i] * a.dir_illum / (kEfficacy * wtot));
            const double omega = options_.fixed_sun_solid_angle > 0
                                     ? options_.fixed_sun_solid_angle
                                     : static_cast<double>(patches_.SolidAngle(near_patch[i]));
            v = static_cast<float>(v / omega);
            s.sun.push_back({near_patch[i], v});
        }
    }
    return s;
}

void SkyModel::SkyValue(const SkyStep &s, int p, double row_factor, float rgb[3]) const {
    if (!s.sky_in_use) {
        rgb[0] = rgb[1] = rgb[2] = 0.f;
        return;
    }
    const float l = s.uniform ? 1.f : RelativeLuminance(s, p, row_factor);
    for (int k = 0; k < 3; ++k) rgb[k] = static_cast<float>(l * s.scale) * options_.sky_color[k];
}

SkyModel::StepArrays SkyModel::Arrays(const std::vector<const SkyStep *> &steps) const {
    StepArrays a;
    const size_t n = steps.size();
    for (auto *v : {&a.cos_sz, &a.sin_sz, &a.cos_az, &a.sin_az, &a.c, &a.d, &a.e, &a.scale})
        v->assign(n, 0.0);
    a.mode.assign(n, 0);
    for (size_t i = 0; i < n; ++i) {
        const SkyStep *s = steps[i];
        if (!s || !s->sky_in_use) continue;
        a.mode[i] = s->uniform ? 2 : 1;
        a.cos_sz[i] = s->cos_sun_zenith, a.sin_sz[i] = s->sin_sun_zenith;
        a.cos_az[i] = s->cos_azimuth, a.sin_az[i] = s->sin_azimuth;
        a.c[i] = s->perez[2], a.d[i] = s->perez[3], a.e[i] = s->perez[4];
        a.scale[i] = s->scale;
    }
    return a;
}

void SkyModel::RowFactors(const std::vector<const SkyStep *> &steps, const StepArrays &a, int p,
                          RowWork *w) const {
    w->row_factor.resize(steps.size());
    for (size_t i = 0; i < steps.size(); ++i)
        w->row_factor[i] = a.mode[i] == 1 ? RowFactor(*steps[i], p) : 0;
}

void SkyModel::PatchValues(const StepArrays &a, int p, RowWork *w, float *rgb) const {
    const size_t n = a.mode.size();
    std::vector<double> &x = w->x;
    std::vector<float> &l = w->l;
    x.resize(n);
    l.resize(n);
    const double czp = cos_zenith_[p], szp = sin_zenith_[p], cap = cos_azi_[p], sap = sin_azi_[p];
    for (size_t i = 0; i < n; ++i) {
        const double cg =
            a.cos_sz[i] * czp + a.sin_sz[i] * szp * (cap * a.cos_az[i] + sap * a.sin_az[i]);
        x[i] = std::clamp(cg, -1.0, 1.0);
    }
    PerezRelativeLuminance(n, x.data(), w->row_factor.data(), a.c.data(), a.d.data(), a.e.data(),
                           l.data());
    const float *col = options_.sky_color;
    for (size_t i = 0; i < n; ++i) {
        const float li = a.mode[i] == 2 ? 1.f : l[i];
        const float v = a.mode[i] == 0 ? 0.f : static_cast<float>(li * a.scale[i]);
        rgb[3 * i] = v * col[0];
        rgb[3 * i + 1] = v * col[1];
        rgb[3 * i + 2] = v * col[2];
    }
}

}  // namespace dayflux
