// gendaylit: RADIANCE's Perez all-weather sky for one time (or sun position), from the Perez
// parameters (-P), direct and diffuse irradiance (-W, -G), illuminance (-L) or global irradiance
// (Erbs, -E): the sun as a light source and the sky as perezlum.cal's brightfunc (or, -C,
// perezlum_c.cal's colorfunc), with its options, warnings and output byte for byte as RADIANCE
// 5.4a's gendaylit (version 2.6). Its arithmetic follows gendaylit's, floats where it has floats.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "sky/perez_tables.h"
#include "sky/solar.h"
#include "util/errors.h"
#include "util/photometry.h"

namespace dayflux {
namespace {

constexpr double kSolarConstantE = 1367;    // W/m2
constexpr double kSolarConstantL = 127500;  // lux
constexpr double kHalfSunAngle = 0.2665;    // degrees
constexpr double kClearInf = 1.0, kClearSup = 12.01, kBrightInf = 0.01, kBrightSup = 0.6;
constexpr int kPatches = 145;

// The 145 patch centres gendaylit integrates the sky over (theta from the zenith, phi, degrees):
// rings at 84 to 12 degrees of 30, 30, 24, 24, 18, 12 and 6 patches, and the zenith.
struct Patches {
    float theta[kPatches], phi[kPatches];
    Patches() {
        static const int rings[7][2] = {{84, 30}, {72, 30}, {60, 24}, {48, 24},
                                        {36, 18}, {24, 12}, {12, 6}};
        int k = 0;
        for (const auto &r : rings)
            for (int j = 0; j < r[1]; ++j, ++k) {
                theta[k] = static_cast<float>(r[0]);
                phi[k] = static_cast<float>(j * (360 / r[1]));
            }
        theta[k] = phi[k] = 0;
    }
};

double Radians(double degrees) { return degrees * (M_PI / 180.); }

class Gendaylit {
  public:
    int Run(int argc, char **argv);

  private:
    [[noreturn]] void UsageError(const char *msg) const;
    void ComputeSky();
    void PrintSky();
    [[noreturn]] void ErrorSky();
    void CheckParametrization();
    void CheckIrradiances();
    void CheckIlluminances();
    void IlluminanceToIrradiance();
    double DiffuseEfficacy();
    double DirectEfficacy();
    double SkyBrightness() { return diffuse_irr_ * AirMass() / (kSolarConstantE * Eccentricity()); }
    double SkyClearness() const;
    double DiffuseFromBrightness() {
        return brightness_ / AirMass() * (kSolarConstantE * Eccentricity());
    }
    double DirectFromClearness();
    double Eccentricity() const;
    double AirMass();
    double Sunrise() const;
    double Sunset() const;
    double NormSc() const;
    double RelativeLuminance(double dzeta, double gamma, double z, double epsilon,
                             double delta) const;
    void PerezCoefficients(double z, double epsilon, double delta);

    const char *prog_ = "gendaylit";
    Site site_{0.66, 2.13, 120. * M_PI / 180.};  // RADIANCE's default site (sun.c)
    int year_ = 0, month_ = 0, day_ = 0;
    double hour_ = 0;
    bool solar_time_ = false;
    double altitude_ = 0, azimuth_ = 0;
    double clearness_ = 0, brightness_ = 0, solar_radiance_ = 0;
    double diffuse_ill_ = 0, direct_ill_ = 0, diffuse_irr_ = 0, direct_irr_ = 0, global_irr_ = 0;
    double sun_zenith_ = 0, day_number_ = 0, water_ = 0, dew_point_ = 10.97353115;
    double diff_normalization_ = 0;
    double c_perez_[5] = {0, 0, 0, 0, 0};
    int output_ = 0, input_ = 0;
    bool color_ = false, quiet_ = false;
    int cloudy_ = 0;
    bool dosun_ = true;
    double gprefl_ = 0.2;
    int intermediate_ = 0;  // S_INTER
    double sundir_[3] = {0, 0, 0};
    double groundbr_ = 0;
    float time_interval_ = 0;
    double st_ = 0;
    float locus_[11] = {-4.843e9f,  2.5568e6f, 0.24282e3f, 0.23258f, -4.843e9f, 2.5568e6f,
                        0.24282e3f, 0.23258f,  -1.2848f,   1.7519f,  -0.093786f};
};

void Gendaylit::UsageError(const char *msg) const {
    if (msg) std::fprintf(stderr, "%s: Use error - %s\n\n", prog_, msg);
    std::fprintf(stderr, "Usage: %s      month day hour [-y year]\t[...]\n", prog_);
    std::fprintf(stderr, "   or: %s -ang altitude azimuth\t\t[...]\n", prog_);
    std::fprintf(stderr, "\t\tfollowed by:\t  -P          epsilon delta [options]\n");
    std::fprintf(stderr, "\t\t\t or:\t  [-W|-L|-G]  direct_value diffuse_value [options]\n");
    std::fprintf(stderr, "\t\t\t or:\t  -E          global_irradiance [options]\n\n");
    std::fprintf(stderr, "    Description:\n");
    std::fprintf(stderr, "\t-P epsilon delta  (these are the Perez parameters) \n");
    std::fprintf(stderr, "\t-W direct-normal-irradiance diffuse-horizontal-irradiance (W/m^2)\n");
    std::fprintf(stderr, "\t-L direct-normal-illuminance diffuse-horizontal-illuminance (lux)\n");
    std::fprintf(stderr,
                 "\t-G direct-horizontal-irradiance diffuse-horizontal-irradiance (W/m^2)\n");
    std::fprintf(stderr, "\t-E global-horizontal-irradiance (W/m^2)\n\n");
    std::fprintf(stderr, "\tOutput specification with option:\n");
    std::fprintf(stderr,
                 "\t-O [0|1|2]  (0=output in W/m^2/sr visible, 1=output in W/m^2/sr solar, "
                 "2=output in candela/m^2), default is 0 \n");
    std::fprintf(stderr, "\tgendaylit version 2.5 (2018/04/18)  \n\n");
    std::exit(1);
}

void Gendaylit::ErrorSky() {
    sundir_[0] = -std::sin(azimuth_) * std::cos(altitude_);
    sundir_[1] = -std::cos(azimuth_) * std::cos(altitude_);
    sundir_[2] = std::sin(altitude_);
    std::printf("# Local solar time: %.2f\n", st_);
    std::printf("# Solar altitude and azimuth: %.1f %.1f\n", altitude_ * 180 / M_PI,
                azimuth_ * 180 / M_PI);
    std::printf("\nvoid brightfunc skyfunc\n");
    std::printf("2 skybright perezlum.cal\n");
    std::printf("0\n");
    std::printf("10 0.00 0.00  0.000 0.000 0.000 0.000 0.000  %f %f %f \n", sundir_[0], sundir_[1],
                sundir_[2]);
    std::fflush(stdout);
    std::exit(0);
}

// atan2(W, sqrt(1 - W W)) of a float W as C computes it: 1 - W W in float, the rest in double
// (C++'s float overloads would round each step to float).
double SunAngle(float w) {
    const float one_minus = 1 - w * w;
    return std::atan2(static_cast<double>(w), std::sqrt(static_cast<double>(one_minus)));
}

double Gendaylit::Sunset() const {
    const float w = static_cast<float>(
        -1 * (std::tan(site_.latitude) * std::tan(SolarDeclination(DayOfYear(month_, day_)))));
    return 12 + (M_PI / 2 - SunAngle(w)) * 180 / (M_PI * 15);
}

double Gendaylit::Sunrise() const {
    const float w = static_cast<float>(
        -1 * (std::tan(site_.latitude) * std::tan(SolarDeclination(DayOfYear(month_, day_)))));
    return 12 - (M_PI / 2 - SunAngle(w)) * 180 / (M_PI * 15);
}

// normsc(): the polynomial for E0 F2 / L0, clear or intermediate.
double Gendaylit::NormSc() const {
    static const double nfc[2][5] = {{2.766521, 0.547665, -0.369832, 0.009237, 0.059229},
                                     {3.5556, -2.7152, -1.3081, 1.0660, 0.60227}};
    const double *nf = nfc[intermediate_];
    const double x = (altitude_ - M_PI / 4.0) / (M_PI / 4.0);
    int i = 4;
    double nsc = nf[i];
    while (i--) nsc = nsc * x + nf[i];
    return nsc;
}

void Gendaylit::CheckParametrization() {
    if (clearness_ < kClearInf) clearness_ = kClearInf;
    if (clearness_ > kClearSup) clearness_ = kClearSup - 0.001;
    if (brightness_ < kBrightInf) brightness_ = kBrightInf;
    if (brightness_ > kBrightSup) brightness_ = kBrightSup;
}

void Gendaylit::CheckIlluminances() {
    if (direct_ill_ < 0) {
        if (!quiet_) std::fprintf(stderr, "Warning: direct illuminance < 0. Using 0.0\n");
        direct_ill_ = 0.0;
    }
    if (diffuse_ill_ < 0) {
        if (!quiet_) std::fprintf(stderr, "Warning: diffuse illuminance < 0. Using 0.0\n");
        diffuse_ill_ = 0.0;
    }
    if (direct_ill_ + diffuse_ill_ == 0 && altitude_ > 0) {
        if (!quiet_)
            std::fprintf(stderr,
                         "Warning: zero illuminance at sun altitude > 0, printing error sky\n");
        ErrorSky();
    }
    if (direct_ill_ > kSolarConstantL) {
        if (!quiet_) std::fprintf(stderr, "Warning: direct illuminance exceeds solar constant\n");
        ErrorSky();
    }
}

void Gendaylit::CheckIrradiances() {
    if (direct_irr_ < 0) {
        if (!quiet_) std::fprintf(stderr, "Warning: direct irradiance < 0. Using 0.0\n");
        direct_irr_ = 0.0;
    }
    if (diffuse_irr_ < 0) {
        if (!quiet_) std::fprintf(stderr, "Warning: diffuse irradiance < 0. Using 0.0\n");
        diffuse_irr_ = 0.0;
    }
    if (direct_irr_ + diffuse_irr_ == 0 && altitude_ > 0) {
        if (!quiet_)
            std::fprintf(stderr,
                         "Warning: zero irradiance at sun altitude > 0, printing error sky\n");
        ErrorSky();
    }
    if (direct_irr_ > kSolarConstantE) {
        if (!quiet_) std::fprintf(stderr, "Warning: direct irradiance exceeds solar constant\n");
        ErrorSky();
    }
}

// The clearness bin of the efficacy models (bounds 1, 1.065, ..., 6.2, and last): -1 if none.
int Bin(double clearness, double last) {
    int bin = -1;
    for (int i = 0; i < 8; ++i) {
        const double upper = i < 7 ? kClearnessBounds[i + 1] : last;
        if (clearness >= kClearnessBounds[i] && clearness < upper) bin = i;
    }
    return bin;
}

double Gendaylit::DiffuseEfficacy() {
    CheckParametrization();
    const int bin = Bin(clearness_, 12.01);
    if (bin < 0) {
        if (!quiet_)
            std::fprintf(stderr, "Warning: sky clearness (= %.3f) too high, printing error sky\n",
                         clearness_);
        ErrorSky();
    }
    const Efficacy &e = kDiffuseEfficacy[bin];
    return e.a + e.b * water_ + e.c * std::cos(sun_zenith_ * M_PI / 180) +
           e.d * std::log(brightness_);
}

double Gendaylit::DirectEfficacy() {
    const int bin = Bin(clearness_, 12.1);
    const Efficacy &e = kDirectEfficacy[bin < 0 ? 0 : bin];
    const double v = e.a + e.b * water_ + e.c * std::exp(5.73 * sun_zenith_ * M_PI / 180 - 5) +
                     e.d * brightness_;
    return v < 0 ? 0 : v;
}

double Gendaylit::SkyClearness() const {
    const double z = sun_zenith_ * M_PI / 180;
    return ((diffuse_irr_ + direct_irr_) / (diffuse_irr_) + 1.041 * z * z * z) /
           (1 + 1.041 * z * z * z);
}

double Gendaylit::DirectFromClearness() {
    const double z = sun_zenith_ * M_PI / 180;
    return DiffuseFromBrightness() * ((clearness_ - 1) * (1 + 1.041 * z * z * z));
}

double Gendaylit::Eccentricity() const {
    const double a = 2 * M_PI * (day_number_ - 1) / 365;
    return 1.00011 + 0.034221 * std::cos(a) + 0.00128 * std::sin(a) + 0.000719 * std::cos(2 * a) +
           0.000077 * std::sin(2 * a);
}

double Gendaylit::AirMass() {
    if (sun_zenith_ > 90) {
        if (!quiet_) std::fprintf(stderr, "Warning: air mass has reached the maximal value\n");
        sun_zenith_ = 90;
    }
    return 1 / (std::cos(sun_zenith_ * M_PI / 180) +
                0.15 * std::exp(std::log(93.885 - sun_zenith_) * (-1.253)));
}

void Gendaylit::IlluminanceToIrradiance() {
    double test1 = 0.1, test2 = 0.1;
    int counter = 0;
    diffuse_irr_ = diffuse_ill_ * kSolarConstantE / kSolarConstantL;
    direct_irr_ = direct_ill_ * kSolarConstantE / kSolarConstantL;
    clearness_ = SkyClearness();
    brightness_ = SkyBrightness();
    CheckParametrization();
    while ((std::fabs(diffuse_irr_ - test1) > 10 || std::fabs(direct_irr_ - test2) > 10 ||
            !(clearness_ < kClearInf || clearness_ > kClearSup) ||
            !(brightness_ < kBrightInf || brightness_ > kBrightSup)) &&
           counter != 9) {
        test1 = diffuse_irr_;
        test2 = direct_irr_;
        ++counter;
        diffuse_irr_ = diffuse_ill_ / DiffuseEfficacy();
        const double d_eff = DirectEfficacy();
        direct_irr_ = d_eff < 0.1 ? 0 : direct_ill_ / d_eff;
        brightness_ = SkyBrightness();
        clearness_ = SkyClearness();
        CheckParametrization();
    }
}

int ClearnessLine(float epsilon) {  // get_numlin()
    for (int i = 1; i < 8; ++i)
        if (epsilon < kClearnessBounds[i]) return i - 1;
    return 7;
}

// calc_rel_lum_perez() (coeff_lum_perez() keeps the a..e in c_perez_).
double Gendaylit::RelativeLuminance(double dzeta, double gamma, double z, double epsilon,
                                    double delta) const {
    if (epsilon < kClearInf || epsilon >= kClearSup) {
        std::fprintf(stderr, "Error: epsilon out of range in function calc_rel_lum_perez!\n");
        std::exit(1);
    }
    if (epsilon > 1.065 && epsilon < 2.8 && delta < 0.2) delta = 0.2;
    const int line = ClearnessLine(static_cast<float>(epsilon));
    float x[5][4];
    for (int i = 0; i < 5; ++i)
        for (int j = 0; j < 4; ++j)
            x[i][j] = static_cast<float>(kPerezCoefficients[line][4 * i + j]);
    double c[5];
    if (line) {
        for (int i = 0; i < 5; ++i) c[i] = x[i][0] + x[i][1] * z + delta * (x[i][2] + x[i][3] * z);
    } else {
        c[0] = x[0][0] + x[0][1] * z + delta * (x[0][2] + x[0][3] * z);
        c[1] = x[1][0] + x[1][1] * z + delta * (x[1][2] + x[1][3] * z);
        c[4] = x[4][0] + x[4][1] * z + delta * (x[4][2] + x[4][3] * z);
        c[2] = std::exp(std::pow(delta * (x[2][0] + x[2][1] * z), x[2][2])) - x[2][3];
        c[3] = -std::exp(delta * (x[3][0] + x[3][1] * z)) + x[3][2] + delta * x[3][3];
    }
    return (1 + c[0] * std::exp(c[1] / std::cos(dzeta))) *
           (1 + c[2] * std::exp(c[3] * gamma) + c[4] * std::cos(gamma) * std::cos(gamma));
}

void Gendaylit::PerezCoefficients(double z, double epsilon, double delta) {
    if (epsilon < kClearInf || epsilon >= kClearSup) {
        std::fprintf(stderr, "Error: epsilon out of range in function coeff_lum_perez!\n");
        std::exit(1);
    }
    if (epsilon > 1.065 && epsilon < 2.8 && delta < 0.2) delta = 0.2;
    const int line = ClearnessLine(static_cast<float>(epsilon));
    float x[5][4];
    for (int i = 0; i < 5; ++i)
        for (int j = 0; j < 4; ++j)
            x[i][j] = static_cast<float>(kPerezCoefficients[line][4 * i + j]);
    double *c = c_perez_;
    if (line) {
        for (int i = 0; i < 5; ++i) c[i] = x[i][0] + x[i][1] * z + delta * (x[i][2] + x[i][3] * z);
    } else {
        c[0] = x[0][0] + x[0][1] * z + delta * (x[0][2] + x[0][3] * z);
        c[1] = x[1][0] + x[1][1] * z + delta * (x[1][2] + x[1][3] * z);
        c[4] = x[4][0] + x[4][1] * z + delta * (x[4][2] + x[4][3] * z);
        c[2] = std::exp(std::pow(delta * (x[2][0] + x[2][1] * z), x[2][2])) - x[2][3];
        c[3] = -std::exp(delta * (x[3][0] + x[3][1] * z)) + x[3][2] + delta * x[3][3];
    }
}

void ZetaGamma(double theta, double phi, double *dzeta, double *gamma, double z) {
    *dzeta = theta;
    const double cg = std::cos(z) * std::cos(theta) + std::sin(z) * std::sin(theta) * std::cos(phi);
    if (cg > 1 && cg < 1.1) {
        *gamma = 0;
    } else if (cg > 1.1) {
        std::printf("error in calculation of gamma (angle between point and sun");
        std::exit(1);
    } else {
        *gamma = std::acos(cg);
    }
}

void Gendaylit::ComputeSky() {
    if (month_) {  // the sun from the date and time
        double sd;
        st_ = hour_;
        if (year_) {  // Michalsky's algorithm
            const double mjd = AlmanacDate(site_, year_, month_, day_, hour_);
            sd = AlmanacDeclination(site_, mjd, solar_time_ ? nullptr : &st_);
        } else {
            const int jd = DayOfYear(month_, day_);
            sd = SolarDeclination(jd);
            if (!solar_time_) st_ = hour_ + SolarTimeOffset(jd, site_);
        }
        const auto error_sky = [&] {
            altitude_ = SolarAltitude(site_, sd, st_);
            azimuth_ = SolarAzimuth(site_, sd, st_);
            ErrorSky();
        };
        if (time_interval_) {
            if (time_interval_ < 0) {
                std::fprintf(stderr, "time interval negative\n");
                std::exit(1);
            }
            if (std::fabs(Sunrise() - st_) <= time_interval_ / 120) {
                st_ = (st_ + time_interval_ / 120 + Sunrise()) / 2;
                if (!quiet_)
                    std::fprintf(stderr, "Solar position corrected at time step %d %d %.3f\n",
                                 month_, day_, hour_);
            }
            if (std::fabs(Sunset() - st_) < time_interval_ / 120) {
                st_ = (st_ - time_interval_ / 120 + Sunset()) / 2;
                if (!quiet_)
                    std::fprintf(stderr, "Solar position corrected at time step %d %d %.3f\n",
                                 month_, day_, hour_);
            }
            if (st_ < Sunrise() - time_interval_ / 120 || st_ > Sunset() + time_interval_ / 120) {
                if (!quiet_)
                    std::fprintf(stderr,
                                 "Warning: sun position too low, printing error sky at %d %d "
                                 "%.3f\n",
                                 month_, day_, hour_);
                error_sky();
            }
        } else if (st_ < Sunrise() || st_ > Sunset()) {
            if (!quiet_)
                std::fprintf(stderr,
                             "Warning: sun altitude below zero at time step %i %i %.2f, printing "
                             "error sky\n",
                             month_, day_, hour_);
            error_sky();
        }
        altitude_ = SolarAltitude(site_, sd, st_);
        azimuth_ = SolarAzimuth(site_, sd, st_);
        day_number_ = static_cast<double>(DayOfYear(month_, day_));
    }
    if (!cloudy_ && altitude_ > 87. * M_PI / 180.) {
        if (!quiet_)
            std::fprintf(stderr,
                         "%s: warning - sun too close to zenith, reducing altitude to 87 degrees\n",
                         prog_);
        altitude_ = 87. * M_PI / 180.;
    }
    sundir_[0] = -std::sin(azimuth_) * std::cos(altitude_);
    sundir_[1] = -std::cos(azimuth_) * std::cos(altitude_);
    sundir_[2] = std::sin(altitude_);
    sun_zenith_ = 90 - altitude_ * 180 / M_PI;

    const auto illuminances = [&] {
        if (output_ == 0 || output_ == 2) {
            diffuse_ill_ = diffuse_irr_ * DiffuseEfficacy();
            direct_ill_ = direct_irr_ * DirectEfficacy();
            CheckIlluminances();
        }
    };
    const auto from_irradiances = [&] {
        CheckIrradiances();
        brightness_ = SkyBrightness();
        clearness_ = SkyClearness();
        CheckParametrization();
        illuminances();
    };
    if (input_ == 0) {  // -P
        CheckParametrization();
        diffuse_irr_ = DiffuseFromBrightness();
        direct_irr_ = DirectFromClearness();
        CheckIrradiances();
        illuminances();
    } else if (input_ == 1) {  // -W
        from_irradiances();
    } else if (input_ == 2) {  // -L
        CheckIlluminances();
        IlluminanceToIrradiance();
        CheckParametrization();
    } else if (input_ == 3) {  // -G
        if (altitude_ <= 0) {
            if (!quiet_)
                std::fprintf(stderr,
                             "Warning: sun altitude < 0, proceed with irradiance values of zero\n");
            direct_irr_ = diffuse_irr_ = 0;
        } else {
            direct_irr_ = direct_irr_ / std::sin(altitude_);
        }
        from_irradiances();
    } else if (input_ == 4) {  // -E: Erbs
        if (altitude_ <= 0) {
            if (!quiet_ && global_irr_ > 50)
                std::fprintf(stderr,
                             "Warning: global irradiance higher than 50 W/m^2 while the sun "
                             "altitude is lower than zero\n");
            global_irr_ = diffuse_irr_ = direct_irr_ = 0;
        } else {
            const double s0 = kSolarConstantE * Eccentricity() * std::sin(altitude_);
            if (global_irr_ > s0) {
                if (!quiet_)
                    std::fprintf(stderr,
                                 "Warning: global irradiance is higher than the time-dependent "
                                 "solar constant s0\n");
                global_irr_ = s0 * 0.999;
            }
            const double kt = global_irr_ / s0;
            if (kt <= 0.22)
                diffuse_irr_ = global_irr_ * (1 - 0.09 * kt);
            else if (kt <= 0.8)
                diffuse_irr_ = global_irr_ * (0.9511 - 0.1604 * kt + 4.388 * std::pow(kt, 2) -
                                              16.638 * std::pow(kt, 3) + 12.336 * std::pow(kt, 4));
            else if (kt < 1)
                diffuse_irr_ = global_irr_ * (0.165);
            direct_irr_ = global_irr_ - diffuse_irr_;
            std::printf("# erbs_s0, erbs_kt, irr_dir_h, irr_diff: %.3f %.3f %.3f %.3f\n", s0, kt,
                        direct_irr_, diffuse_irr_);
            std::printf("# WARNING: the -E option is only recommended for a rough estimation!\n");
            direct_irr_ = direct_irr_ / std::sin(altitude_);
        }
        from_irradiances();
    } else {
        std::fprintf(stderr, "error at the input arguments");
        std::exit(1);
    }

    // The diffuse sky's normalisation: its luminance integrated over 145 patches.
    static const Patches patches;
    float lv[kPatches];
    const double z = Radians(sun_zenith_);
    PerezCoefficients(z, clearness_, brightness_);
    for (int j = 0; j < kPatches; ++j) {
        double dzeta, gamma;
        ZetaGamma(Radians(patches.theta[j]), Radians(patches.phi[j]), &dzeta, &gamma, z);
        lv[j] = static_cast<float>(RelativeLuminance(dzeta, gamma, z, clearness_, brightness_));
    }
    double integral = 0.0;
    for (int i = 0; i < kPatches; ++i) integral += lv[i] * std::cos(Radians(patches.theta[i]));
    diff_normalization_ = integral * (2. * M_PI / 145.);
    const double sun_solid_angle = 2 * M_PI * (1 - std::cos(kHalfSunAngle * M_PI / 180));
    if (output_ == 0) {
        diff_normalization_ = diffuse_ill_ / diff_normalization_ / kLuminousEfficacy;
        solar_radiance_ = direct_ill_ / sun_solid_angle / kLuminousEfficacy;
    } else if (output_ == 1) {
        diff_normalization_ = diffuse_irr_ / diff_normalization_;
        solar_radiance_ = direct_irr_ / sun_solid_angle;
    } else if (output_ == 2) {
        diff_normalization_ = diffuse_ill_ / diff_normalization_;
        solar_radiance_ = direct_ill_ / sun_solid_angle;
    } else {
        std::fprintf(stderr, "Wrong output specification.\n");
        std::exit(1);
    }

    // The ground's radiance.
    double zenith = RelativeLuminance(0.0, z, z, clearness_, brightness_) * diff_normalization_;
    double norm = 0;
    if (clearness_ == 1) norm = 0.777778;
    if (clearness_ >= 6) {
        const double f2 = 0.274 * (0.91 + 10.0 * std::exp(-3.0 * (M_PI / 2.0 - altitude_)) +
                                   0.45 * sundir_[2] * sundir_[2]);
        norm = NormSc() / f2 / M_PI;
    }
    if (clearness_ > 1 && clearness_ < 6) {
        intermediate_ = 1;
        const double f2 = (2.739 + .9891 * std::sin(.3119 + 2.6 * altitude_)) *
                          std::exp(-(M_PI / 2.0 - altitude_) * (.4441 + 1.48 * altitude_));
        norm = NormSc() / f2 / M_PI;
    }
    groundbr_ = zenith * norm;
    if (dosun_ && clearness_ > 1) groundbr_ += 6.8e-5 / M_PI * solar_radiance_ * sundir_[2];
    groundbr_ *= gprefl_;
    if (c_perez_[1] > 0) {
        if (!quiet_)
            std::fprintf(stderr,
                         "Warning: positive Perez parameter B (= %lf), printing error sky\n",
                         c_perez_[1]);
        ErrorSky();
    }
}

void Gendaylit::PrintSky() {
    std::printf("# Local solar time: %.2f\n", st_);
    std::printf("# Solar altitude and azimuth: %.1f %.1f\n", altitude_ * 180 / M_PI,
                azimuth_ * 180 / M_PI);
    std::printf("# epsilon, delta, atmospheric precipitable water content : %.4f %.4f %.4f \n",
                clearness_, brightness_, water_);
    if (dosun_) {
        const bool bright = clearness_ > 1;
        std::printf("\nvoid light solar\n0\n0\n");
        if (bright)
            std::printf("3 %.3e %.3e %.3e\n", solar_radiance_, solar_radiance_, solar_radiance_);
        else
            std::printf("3 0.0 0.0 0.0\n");
        std::printf("\nsolar source sun\n0\n0\n");
        std::printf("4 %f %f %f %f\n", sundir_[0], sundir_[1], sundir_[2], 2 * kHalfSunAngle);
    }
    if (color_ && clearness_ < 4.5 && clearness_ > 1.065) {
        std::fprintf(stderr, "\twarning: sky clearness(epsilon)= %f \n", clearness_);
        std::fprintf(stderr, "\twarning: intermediate sky!! \n");
        std::fprintf(stderr, "\twarning: color model for intermediate sky pending  \n");
        std::fprintf(stderr, "\twarning: no color output ! \n");
        color_ = false;
    }
    const double *c = c_perez_;
    if (color_) {
        std::printf("\nvoid colorfunc skyfunc\n");
        std::printf("4 skybright_r skybright_g skybright_b perezlum_c.cal\n");
        std::printf("0\n");
        std::printf(
            "22 %.3e %.3e %lf %lf %lf %lf %lf %f %f %f %f %f %f %f %f %f %f %f %f %f %f %f\n",
            diff_normalization_, groundbr_, c[0], c[1], c[2], c[3], c[4], sundir_[0], sundir_[1],
            sundir_[2], clearness_, locus_[0], locus_[1], locus_[2], locus_[3], locus_[4],
            locus_[5], locus_[6], locus_[7], locus_[8], locus_[9], locus_[10]);
    } else {
        std::printf("\nvoid brightfunc skyfunc\n");
        std::printf("2 skybright perezlum.cal\n");
        std::printf("0\n");
        std::printf("10 %.3e %.3e %lf %lf %lf %lf %lf %f %f %f \n", diff_normalization_, groundbr_,
                    c[0], c[1], c[2], c[3], c[4], sundir_[0], sundir_[1], sundir_[2]);
    }
}

int Gendaylit::Run(int argc, char **argv) {
    prog_ = argv[0];
    if (argc == 2 && !std::strcmp(argv[1], "-defaults")) {
        std::printf("-g %f\t\t\t# Ground plane reflectance\n", gprefl_);
        std::printf("-t %f\t\t\t# Atmospheric betaturbidity\n", 0.1);
        std::printf("-a %f\t\t\t# Site latitude (degrees)\n", site_.latitude * (180 / M_PI));
        std::printf("-o %f\t\t\t# Site longitude (degrees)\n", site_.longitude * (180 / M_PI));
        std::printf("-m %f\t\t\t# Standard meridian (degrees)\n", site_.meridian * (180 / M_PI));
        return 0;
    }
    if (argc < 4) UsageError("arg count");
    if (!std::strcmp(argv[1], "-ang")) {
        altitude_ = std::atof(argv[2]) * (M_PI / 180);
        azimuth_ = std::atof(argv[3]) * (M_PI / 180);
        month_ = 0;
    } else {
        month_ = std::atoi(argv[1]);
        if (month_ < 1 || month_ > 12) UsageError("bad month");
        day_ = std::atoi(argv[2]);
        if (day_ < 1 || day_ > 31) UsageError("bad day");
        hour_ = std::atof(argv[3]);
        if (hour_ < 0 || hour_ >= 24) UsageError("bad hour");
        solar_time_ = argv[3][0] == '+';
    }
    for (int i = 4; i < argc; ++i) {
        // (RADIANCE's reads past the arguments where an option's value is missing: a crash)
        const auto value = [&]() -> const char * {
            if (i + 1 >= argc) UsageError((std::string("missing value for ") + argv[i]).c_str());
            return argv[++i];
        };
        if (argv[i][0] != '-' && argv[i][0] != '+') UsageError("bad option");
        switch (argv[i][1]) {
            case 'd':
                dew_point_ = std::atof(value());
                if (dew_point_ < -40 || dew_point_ > 40) dew_point_ = 10.97353115;
                break;
            case 's':
                cloudy_ = 0;
                dosun_ = argv[i][0] == '+';
                break;
            case 'y':
                year_ = std::atoi(value());
                break;
            case 'R':
                std::atof(value());
                break;  // read, and used for nothing (as RADIANCE)
            case 'c':
                cloudy_ = argv[i][0] == '+' ? 2 : 1;
                dosun_ = false;
                break;
            case 'C':
                if (argv[i][2] == 'I' && argv[i][3] == 'E') {
                    const float cie[11] = {-4.607e9f,  2.9678e6f, 0.09911e3f, 0.244063f,
                                           -2.0064e9f, 1.9018e6f, 0.24748e3f, 0.23704f,
                                           -3.0f,      2.87f,     -0.275f};
                    std::copy(cie, cie + 11, locus_);
                } else {
                    color_ = true;
                }
                break;
            case 'l':
                for (int k = 0; k < 4; ++k) locus_[k] = static_cast<float>(std::atof(value()));
                for (int k = 0; k < 4; ++k) locus_[4 + k] = locus_[k];
                for (int k = 8; k < 11; ++k) locus_[k] = static_cast<float>(std::atof(value()));
                break;
            case 't':
                std::atof(value());
                break;  // turbidity: not in the Perez sky
            case 'w':
                quiet_ = true;
                break;
            case 'b':
                std::atof(value());
                break;  // zenith radiance: not in the Perez sky
            case 'g':
                gprefl_ = std::atof(value());
                break;
            case 'a':
                site_.latitude = std::atof(value()) * (M_PI / 180);
                break;
            case 'o':
                site_.longitude = std::atof(value()) * (M_PI / 180);
                break;
            case 'm':
                site_.meridian = std::atof(value()) * (M_PI / 180);
                break;
            case 'O':
                output_ = static_cast<int>(std::atof(value()));
                break;
            case 'P':
                input_ = 0;
                clearness_ = std::atof(value());
                brightness_ = std::atof(value());
                break;
            case 'W':
            case 'G':
                input_ = argv[i][1] == 'W' ? 1 : 3;
                direct_irr_ = std::atof(value());
                diffuse_irr_ = std::atof(value());
                break;
            case 'L':
                input_ = 2;
                direct_ill_ = std::atof(value());
                diffuse_ill_ = std::atof(value());
                break;
            case 'E':
                input_ = 4;
                global_irr_ = std::atof(value());
                break;
            case 'i':
                time_interval_ = static_cast<float>(std::atof(value()));
                break;
            default: {
                const std::string msg = std::string("unknown option: ") + argv[i];
                UsageError(msg.c_str());
            }
        }
    }
    if (month_ && !solar_time_ && std::fabs(site_.meridian - site_.longitude) > 45 * M_PI / 180)
        std::fprintf(stderr, "%s: warning: %.1f hours btwn. standard meridian and longitude\n",
                     prog_, (site_.longitude - site_.meridian) * 12 / M_PI);
    water_ = std::exp(0.07 * dew_point_ - 0.075);
    std::putchar('#');
    for (int a = 0; a < argc; ++a) std::printf(" %s", argv[a]);
    std::putchar('\n');
    ComputeSky();
    PrintSky();
    return 0;
}

int Main(int argc, char **argv) { return Gendaylit().Run(argc, argv); }

}  // namespace
}  // namespace dayflux

int main(int argc, char **argv) { return dayflux::RunTool(argc, argv, dayflux::Main); }
