// A bounding volume hierarchy over boxes, for devices that trace rays without ray queries (the
// GPU integrator's own traversal): built with Embree's BVH builder (binary, SAH), then laid out
// flat and depth first, each inner node's first child right after it.
#pragma once

#include <cstdint>
#include <vector>

#include "raytrace/core/tables.h"

namespace dayflux {

struct FlatBvhNode {
    float lo[3], hi[3];
    int32_t count = 0;  // primitives in a leaf; 0 for an inner node
    int32_t index = 0;  // leaf: first entry in FlatBvh::prims; inner node: its second child
};

struct FlatBvh {
    std::vector<FlatBvhNode> nodes;  // nodes[0] is the root (empty when there are no boxes)
    std::vector<int32_t> prims;      // primitive indices, leaf by leaf
};

// boxes: 6 floats per primitive (min xyz, max xyz); primitive i is box i.
FlatBvh BuildBvh(const std::vector<float> &boxes);

// bvh's inner nodes as the GPU walks them (core::PackedBvhNode: each holds its children's
// bounds), in the same depth-first order; a root that is a leaf is both children of one node.
// Empty for an empty bvh.
std::vector<core::PackedBvhNode> PackBvh(const FlatBvh &bvh);

}  // namespace dayflux
