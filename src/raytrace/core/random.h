// Random numbers for the estimator, the same on every backend: a counter-based hash (PCG's
// output function over a 32-bit state), so that a stream keyed by (seed, input ray, replica)
// and restarted at each cell of a first hemisphere can be replayed anywhere, and both drivers
// draw the same numbers for the same record, ray and bounce. Uniform numbers have 24 bits, which
// float holds exactly, so C++ and GLSL see the same values.
#ifndef DAYFLUX_CORE_RANDOM_H
#define DAYFLUX_CORE_RANDOM_H

#include "raytrace/core/language.h"

#ifdef __cplusplus
namespace dayflux::core {
#endif

inline uint Pcg(uint v) {
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

inline uint Key(uint a, uint b, uint c, uint d) { return Pcg(a ^ Pcg(b ^ Pcg(c ^ Pcg(d)))); }

// Replicas from kPairedReplicas up come in pairs (2k, 2k + 1) whose first-level hemispheres share
// their grid's turn and differ only in the cells' own numbers: each cell's two samples are then
// alike in law, so that the pair's difference, row by row, estimates the variance of a stratified
// hemisphere without splitting it (-target_error). Other replicas turn their grids their own way.
CONST uint kPairedReplicas = 0x40000000u;
inline uint TurnReplica(uint replica) {
    return replica >= kPairedReplicas ? (replica & ~1u) : replica;
}

// A uniform number in [0, 1) from a hashed state.
inline real UnitInterval(uint state) { return real(state >> 8u) * (1.0 / 16777216.0); }

#ifdef __cplusplus
}  // namespace dayflux::core
#endif
#endif  // DAYFLUX_CORE_RANDOM_H
