// rfluxmtx's command line, screened as RADIANCE's rfluxmtx screens it, and the rcontrib command
// it becomes: rcontrib's options as given (those rfluxmtx refuses refused here), the output
// format with a double input in sampling mode, -c, then for each receiver its -o, -f, -p, -bn,
// -b and -m, then -y (the sender's bins) in sampling mode. dayflux's own engine options
// (-backend, -device, -gpu_traversal, -gpu_accum, -gpu_cal, -gpu_scratch, -seed, -asub, -se,
// -progress) pass through.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "rfluxmtx/annotations.h"

namespace dayflux {

struct RfluxmtxCommand {
    std::vector<std::string> rcontrib;  // rcontrib-gpu's arguments so far (its name first)
    std::string sender;                 // empty: pass-through mode (rays from the input)
    std::string receiver;
    std::vector<std::string> system;  // scene files and octrees (-i octree)
    int samples = 0;                  // rays per sender bin (-c), or per record in pass-through
    bool verbose = false;             // -v: the rcontrib command to the standard error
    uint64_t seed = 0;                // -seed (ours), for the sender's samples too
};

RfluxmtxCommand ParseRfluxmtxCommand(const std::vector<std::string> &args);

// finish_receiver() for each receiver: -o -f -p -bn -b -m. Each .cal file is loaded once.
std::vector<std::string> ReceiverArguments(const std::vector<FluxGroup> &receivers);

}  // namespace dayflux
