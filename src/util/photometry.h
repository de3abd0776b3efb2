// RADIANCE's photometric constants, so every program converts the same way.
#pragma once

namespace dayflux {

// White-light luminous efficacy (lm/W): lux = 179 x equal-energy irradiance.
inline constexpr double kLuminousEfficacy = 179;
// gensky's: skylight's (RADIANCE's SKYEFFICACY, D65's 203) and the sun's (SUNEFFICACY,
// illuminant B's 208).
inline constexpr double kSkyEfficacy = 203;
inline constexpr double kSunEfficacy = 208;

// Illuminance (lux) of RGB irradiance (W/m2), as rmtxop -c 47.4 119.9 11.6 computes it.
inline double IlluminanceFromRgb(const double *rgb) {
    return 47.4 * rgb[0] + 119.9 * rgb[1] + 11.6 * rgb[2];
}

}  // namespace dayflux
