// The Perez 1990 luminous efficacy and 1993 all-weather sky models as gendaymtx applies them to
// sky patches, with RADIANCE's clamps and special cases. A time step is computed in two parts:
// Prepare() finds everything that does not depend on the patch (and the normalisation, which
// needs every patch once), PatchValue() gives one patch's RGB radiance. gendaymtx can then
// write patch-major output without holding the whole matrix.
#pragma once

#include <array>
#include <vector>

#include "sky/patches.h"
#include "sky/solar.h"

namespace dayflux {

struct SkyOptions {
    int mf = 1;
    float sky_color[3] = {.960f, 1.004f, 1.118f};
    float sun_color[3] = {1.f, 1.f, 1.f};
    float ground_reflectance[3] = {.2f, .2f, .2f};
    int sun_patches = 4;                // patches the sun is spread over (gendaymtx: 4; -5: 1)
    double fixed_sun_solid_angle = -1;  // -5: divide by this instead of the patch's solid angle
    bool solar_radiance = false;        // -O1: luminous quantities replaced by irradiance x 179
    double rotation_deg = 0;            // -r: sky rotated counter-clockwise
};

// Weather input quantities as gendaymtx classifies them.
enum class WeatherUnits { kRadiometric = 1, kDirectHorizontal = 2, kPhotometric = 3 };

struct SunPatch {
    int patch;
    float value;  // radiance added, before the sun colour
};

// Everything about one time step except per-patch values.
struct SkyStep {
    bool sky_in_use = false;  // sky patches non-zero (sky colour not black, not a dark step)
    bool uniform = false;     // zero Perez sky replaced by a uniform one
    double perez[5] = {};
    double cos_sun_zenith = 0, sin_sun_zenith = 0;
    double azimuth = 0;  // sun azimuth in gendaymtx's frame (from north, east positive)
    double cos_azimuth = 0, sin_azimuth = 0;
    double scale = 0;  // luminance normalisation x 1/179
    float ground[3] = {};
    std::vector<SunPatch> sun;
    double dir_illum = 0;  // direct illuminance (for sun descriptions)
    // Units 2: the direct normal value derived from the horizontal one (a sun at the horizon)
    // made the sky NaN, as it does RADIANCE's, and was taken as kMostIrradiance.
    bool direct_capped = false;
};

class SkyModel {
  public:
    explicit SkyModel(const SkyOptions &options);
    const SkyPatchBasis &Patches() const { return patches_; }
    const SkyOptions &Options() const { return options_; }

    // Computes a daytime step (dir + dif > 1e-4). altitude/azimuth: the sun (azimuth already in
    // gendaymtx's frame). julian_date counts Feb 29 as 60 in leap years.
    SkyStep Prepare(double dir, double dif, WeatherUnits units, double altitude, double azimuth,
                    int julian_date, bool add_sun) const;
    // RGB radiance of sky patch p (1 .. Size()-1) from the sky alone, as RADIANCE's float values.
    void SkyValue(const SkyStep &s, int p, float rgb[3]) const {
        SkyValue(s, p, RowFactor(s, p), rgb);
    }
    // The same with the factor shared by a row of patches (RowFactor) computed once per row.
    void SkyValue(const SkyStep &s, int p, double row_factor, float rgb[3]) const;
    double RowFactor(const SkyStep &s, int p) const;
    int RowOf(int p) const { return row_of_[p]; }

    // The time steps of a run as arrays, for computing one patch at every step in one loop.
    struct StepArrays {
        std::vector<double> cos_sz, sin_sz, cos_az, sin_az, c, d, e, scale;
        std::vector<unsigned char> mode;  // 0: black, 1: Perez sky, 2: uniform sky
    };
    StepArrays Arrays(const std::vector<const SkyStep *> &steps) const;
    // Buffers for one thread's patch rows: the row factors of every step (shared by the patches
    // of a sky row), and PatchValues' scratch.
    struct RowWork {
        std::vector<double> row_factor, x;
        std::vector<float> l;
    };
    // Sky values of patch p at every step (3 floats each), given w.row_factor for p's row.
    void PatchValues(const StepArrays &a, int p, RowWork *w, float *rgb) const;
    // Fills w->row_factor for the row of patch p.
    void RowFactors(const std::vector<const SkyStep *> &steps, const StepArrays &a, int p,
                    RowWork *w) const;

  private:
    // Prepare() as RADIANCE computes it; *finite: whether the sky and sun came out finite.
    SkyStep PrepareAsRadiance(double dir, double dif, WeatherUnits units, double altitude,
                              double azimuth, int julian_date, bool add_sun, bool *finite) const;

    double CosToSun(const SkyStep &s, int p) const;
    float RelativeLuminance(const SkyStep &s, int p, double row_factor) const;

    SkyOptions options_;
    SkyPatchBasis patches_;
    // Per patch: quantities of the patch centre used for every step.
    std::vector<double> cos_zenith_, sin_zenith_, inv_cos_zenith_, cos_azi_, sin_azi_,
        horizontal_weight_;
    std::vector<std::array<double, 3>> direction_;  // patch centres, as gendaymtx computes them
    std::vector<int> row_of_;
    bool sky_black_;
};

}  // namespace dayflux
