// rcontrib's loop over its input: rays (origin and direction) read from the standard input in
// the -f format, traced in blocks on the engine (blocks in parallel on the CPU), summed into
// records of -c rays (or, partial, at the end of input; -c 0: one record of every ray), written
// in input order. A zero direction counts as a ray that contributes nothing and flushes the
// outputs (a caller feeding rays through a pipe gets results so far).
#pragma once

#include <functional>

#include "raytrace/engine.h"
#include "rcontrib/options.h"
#include "rcontrib/outputs.h"

namespace dayflux {

// Traces every record to outputs, after skipping those it already holds (-r: as many input rays,
// times -c, are skipped, and the rest keep their random numbers, so a recovered run ends as an
// uninterrupted one would have). Errors where the input ends before -y records.
// rays: where the input rays come from (origin and direction into ray; false at the end of
// input); by default the standard input in the -f format.
using RaySource = std::function<bool(double ray[6])>;

// The standard input's rays in format (6 numbers each, no header), with a warning where -ff or
// -fd reads what looks like text.
RaySource StandardInputRays(DataFormat format);

// Errors (naming input ray `number`, from 1) on NaN, infinity or a coordinate beyond 1e12; a
// direction too short for the engines' float is made unit length, or zero (a flush) where its
// squared length underflows, as RADIANCE's normalize() finds it zero.
void CheckInputRay(double ray[6], uint64_t number);
void TraceRecords(const RcontribOptions &o, ContribEngine &engine, RcontribOutputs &outputs,
                  RaySource rays = nullptr);

}  // namespace dayflux
