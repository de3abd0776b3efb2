// The flat BVH the GPU walks where it has no ray queries: every primitive in exactly one leaf,
// every node's box holding what lies below it, first children right after their parents.
#include "raytrace/bvh.h"

#include <gtest/gtest.h>

#include <random>

namespace dayflux {
namespace {

bool Contains(const float lo[3], const float hi[3], const float *b) {
    for (int k = 0; k < 3; ++k)
        if (b[k] < lo[k] || b[3 + k] > hi[k]) return false;
    return true;
}

TEST(Bvh, HoldsEveryBoxOnceInsideItsNodes) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-100, 100), s(0, 3);
    std::vector<float> boxes;
    const int n = 5000;
    for (int i = 0; i < n; ++i) {
        const float x = u(rng), y = u(rng), z = u(rng);
        const float b[6] = {x, y, z, x + s(rng), y + s(rng), z};  // some flat, as triangles are
        boxes.insert(boxes.end(), b, b + 6);
    }
    const FlatBvh bvh = BuildBvh(boxes);
    ASSERT_FALSE(bvh.nodes.empty());
    std::vector<int> seen(n, 0);
    // Walk it as the shader does, checking containment on the way down.
    std::vector<int> stack = {0};
    while (!stack.empty()) {
        const int at = stack.back();
        stack.pop_back();
        const FlatBvhNode &node = bvh.nodes[at];
        if (node.count == 0) {
            ASSERT_GT(node.index, at + 1);
            for (int child : {at + 1, node.index}) {
                const FlatBvhNode &c = bvh.nodes[child];
                const float b[6] = {c.lo[0], c.lo[1], c.lo[2], c.hi[0], c.hi[1], c.hi[2]};
                EXPECT_TRUE(Contains(node.lo, node.hi, b));
                stack.push_back(child);
            }
            continue;
        }
        for (int i = 0; i < node.count; ++i) {
            const int p = bvh.prims[node.index + i];
            ASSERT_GE(p, 0);
            ASSERT_LT(p, n);
            ++seen[p];
            EXPECT_TRUE(Contains(node.lo, node.hi, &boxes[6 * p]));
        }
    }
    for (int i = 0; i < n; ++i) ASSERT_EQ(seen[i], 1) << i;
    EXPECT_EQ(bvh.prims.size(), static_cast<size_t>(n));
    EXPECT_TRUE(BuildBvh({}).nodes.empty());
}

// The packed form the GPU walks (each node its children's bounds, leaves as references): the
// same boxes over the same primitives, each reached once, from a tree or from a lone leaf.
std::vector<float> RandomBoxes(int n, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-100, 100), s(0, 3);
    std::vector<float> boxes;
    for (int i = 0; i < n; ++i) {
        const float x = u(rng), y = u(rng), z = u(rng);
        const float b[6] = {x, y, z, x + s(rng), y + s(rng), z + s(rng)};
        boxes.insert(boxes.end(), b, b + 6);
    }
    return boxes;
}

TEST(Bvh, PackedForTheGpuReachesEveryBoxOnce) {
    for (int n : {3000, 1}) {
        const std::vector<float> boxes = RandomBoxes(n, 7);
        const FlatBvh bvh = BuildBvh(boxes);
        const std::vector<core::PackedBvhNode> packed = PackBvh(bvh);
        ASSERT_FALSE(packed.empty());
        EXPECT_EQ(packed.size(), n == 1 ? 1u : bvh.nodes.size() / 2);  // the inner nodes
        std::vector<int> seen(n, 0);
        std::vector<int32_t> stack = {0};
        while (!stack.empty()) {
            const int32_t at = stack.back();
            stack.pop_back();
            ASSERT_LT(at, static_cast<int32_t>(packed.size()));
            const core::PackedBvhNode &node = packed[at];
            for (int c = 0; c < (n == 1 ? 1 : 2); ++c) {  // (a lone leaf is both children)
                const core::PackedBvhChild &child = node.child[c];
                if (child.ref >= 0) {
                    ASSERT_GT(child.ref, at);  // depth first: no cycles
                    stack.push_back(child.ref);
                    continue;
                }
                const int first = ~child.ref >> core::kBvhLeafCountBits;
                const int count = ~child.ref & ((1 << core::kBvhLeafCountBits) - 1);
                ASSERT_GT(count, 0);
                const float lo[3] = {child.lo.x, child.lo.y, child.lo.z};
                const float hi[3] = {child.hi.x, child.hi.y, child.hi.z};
                for (int i = first; i < first + count; ++i) {
                    const int p = bvh.prims[i];
                    ++seen[p];
                    EXPECT_TRUE(Contains(lo, hi, &boxes[6 * p]));
                }
            }
        }
        for (int i = 0; i < n; ++i) ASSERT_EQ(seen[i], 1) << n << " " << i;
    }
    EXPECT_TRUE(PackBvh(BuildBvh({})).empty());
}

}  // namespace
}  // namespace dayflux
