// What the two replay benchmarks (ray_replay_bench.cpp for Embree, gpu_replay_bench.cpp for the
// GPU) share: their own leading options, the sensors from stdin, and every K-th of them.
#pragma once

#include <algorithm>
#include <iostream>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "util/errors.h"

namespace dayflux::bench {

// Takes the leading "-name N" options named in values (each N a whole number, at least 1, or 0
// for those in zero_allowed) off args, leaving rcontrib-gpu's options and scene.
inline void TakeCounts(std::vector<std::string> *args,
                       const std::map<std::string, size_t *> &values,
                       const std::set<std::string> &zero_allowed = {}) {
    while (args->size() > 2 && values.count((*args)[1])) {
        const size_t least = zero_allowed.count((*args)[1]) ? 0 : 1;
        *values.at((*args)[1]) = std::max<size_t>(least, std::stoul((*args)[2]));
        args->erase(args->begin() + 1, args->begin() + 3);
    }
}

// Rays of 6 numbers each.
inline std::vector<double> ReadRays(std::istream &in) {
    std::vector<double> rays;
    double v;
    while (in >> v) rays.push_back(v);
    if (rays.empty() || rays.size() % 6) ErrorExit("<stdin>: expected rays of 6 numbers");
    return rays;
}

// Every k-th ray.
inline std::vector<double> EveryKth(const std::vector<double> &rays, size_t k) {
    std::vector<double> subset;
    for (size_t i = 0; i < rays.size() / 6; i += k)
        subset.insert(subset.end(), &rays[6 * i], &rays[6 * i + 6]);
    return subset;
}

}  // namespace dayflux::bench
