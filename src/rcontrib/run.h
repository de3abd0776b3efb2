// An rcontrib run from its options: the scene read (files and octrees, in order), the engine
// created, every record traced to the outputs, which are committed at the end. rcontrib-gpu and
// rfluxmtx-gpu share it.
#pragma once

#include <tbb/global_control.h>

#include <string>
#include <vector>

#include "raytrace/engine.h"
#include "rcontrib/options.h"
#include "rcontrib/outputs.h"
#include "rcontrib/records.h"
#include "scene/flatten.h"

namespace dayflux {

// header_args: the command line for the outputs' headers; header_lines: lines put before it
// (after any octree's); rays: the input rays (by default the standard input, in the -f format).
void RunRcontrib(const RcontribOptions &o, const std::vector<std::string> &header_args,
                 const std::string &header_lines = "", RaySource rays = nullptr);

// The engine for a run of o over flat, with contrib (o.contrib, or a variant of it) and the
// engine options given.
std::unique_ptr<ContribEngine> CreateRunEngine(const RcontribOptions &o, const FlatScene &flat,
                                               const ContribOptions &contrib,
                                               const EngineOptions &engine);

// -n: at most threads threads while the result lives (all cores for 0).
std::unique_ptr<tbb::global_control> LimitThreads(int threads);

// The scene files and octrees, in order, flattened; the octrees' headers in *octree_header.
FlatScene ReadRcontribScene(const std::vector<std::string> &files, std::string *octree_header);

// Traces every record to outputs and commits them. A run stopped by SIGINT or SIGTERM
// (Interrupted) or by an error (UserError: a full disk, a lost GPU, a bad ray) keeps the records
// it wrote in the partial files, and its message says so.
void TraceToOutputs(const RcontribOptions &o, ContribEngine &engine, RcontribOutputs &outputs,
                    RaySource rays);

}  // namespace dayflux
