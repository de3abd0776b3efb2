// The run's parameters as the estimator core reads them (`params.ab`, ...): rcontrib's options
// and what the packed scene fixes for the whole run. One struct for both drivers, in the common
// subset: the CPU holds it in double (CpuParameters, a member of each thread's estimator), the
// GPU in float, in a storage buffer of its own (GpuParameters, shaders/common.h's
// kBindingParameters), so that runs differing only in their options share one compiled shader.
// Adding an option touches this struct and MakeParameters (raytrace/packing.h), nothing else.
#ifndef DAYFLUX_CORE_PARAMETERS_H
#define DAYFLUX_CORE_PARAMETERS_H

#include "raytrace/core/language.h"

#ifdef __cplusplus
namespace dayflux::core {
// ParameterReal: the options' real numbers, double on the CPU, float on the GPU.
template <typename ParameterReal>
struct BasicParameters {
#else
#define ParameterReal float
struct Parameters {
#endif
    // The scene's centre, added back where bins see points; on the GPU as float and what float
    // rounding left of it (0 on the CPU), since a shader has no double without shaderFloat64.
    // (Every member is 4 bytes on the GPU: std430's layout is GpuParameters' C++ one, unpadded.)
    ParameterReal centre_x, centre_y, centre_z;
    ParameterReal centre_rest_x, centre_rest_y, centre_rest_z;
    ParameterReal lw;   // -lw
    ParameterReal dj;   // -dj
    ParameterReal st;   // -st
    ParameterReal ss;   // -ss
    ParameterReal ds;   // -ds
    int ab;             // -ab
    int ad;             // -ad
    int lr;             // -lr
    int asub;           // -asub (1: none; read where DAYFLUX_ASUB is compiled)
    int irradiance;     // -I (0 or 1)
    int first_hit;      // -i (0 or 1)
    int contributions;  // -V+ (0 or 1)
    int nsources;       // the packed sources
    int ndirect;        // of them, those sampled with shadow rays (not glow)
    uint seed;          // -seed, its 64 bits folded into 32
};

#ifdef __cplusplus
using CpuParameters = BasicParameters<double>;
using GpuParameters = BasicParameters<float>;
}  // namespace dayflux::core
#else
#undef ParameterReal
#endif
#endif  // DAYFLUX_CORE_PARAMETERS_H
