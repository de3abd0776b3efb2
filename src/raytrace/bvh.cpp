#include "raytrace/bvh.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <mutex>
#include <new>

#include "util/errors.h"

namespace dayflux {

namespace {

// The builder's nodes, in Embree's thread-local memory until flattened.
struct Node {
    bool leaf = false;
    float lo[2][3], hi[2][3];  // inner: the children's bounds
    Node *child[2] = {nullptr, nullptr};
    std::vector<int32_t> *prims = nullptr;  // leaf: its primitives (owned by Build's list)
};

struct Build {
    std::vector<std::vector<int32_t> *> leaves;  // freed after flattening
    ~Build() {
        for (auto *l : leaves) delete l;
    }
};

void *CreateNode(RTCThreadLocalAllocator alloc, unsigned int count, void *) {
    CHECK(count == 2);
    return new (rtcThreadLocalAlloc(alloc, sizeof(Node), 16)) Node();
}

void SetChildren(void *node, void **children, unsigned int count, void *) {
    for (unsigned int i = 0; i < count; ++i)
        static_cast<Node *>(node)->child[i] = static_cast<Node *>(children[i]);
}

void SetBounds(void *node, const RTCBounds **bounds, unsigned int count, void *) {
    Node *n = static_cast<Node *>(node);
    for (unsigned int i = 0; i < count; ++i) {
        n->lo[i][0] = bounds[i]->lower_x, n->lo[i][1] = bounds[i]->lower_y,
        n->lo[i][2] = bounds[i]->lower_z;
        n->hi[i][0] = bounds[i]->upper_x, n->hi[i][1] = bounds[i]->upper_y,
        n->hi[i][2] = bounds[i]->upper_z;
    }
}

// Leaves are made on Embree's threads: each gets its own list, collected under a lock.
void *CreateLeaf(RTCThreadLocalAllocator alloc, const RTCBuildPrimitive *prims, size_t count,
                 void *user) {
    Node *n = new (rtcThreadLocalAlloc(alloc, sizeof(Node), 16)) Node();
    n->leaf = true;
    n->prims = new std::vector<int32_t>();
    for (size_t i = 0; i < count; ++i) n->prims->push_back(static_cast<int32_t>(prims[i].primID));
    static std::mutex lock;
    std::lock_guard<std::mutex> guard(lock);
    static_cast<Build *>(user)->leaves.push_back(n->prims);
    return n;
}

void Flatten(const Node *n, const float lo[3], const float hi[3], FlatBvh *out) {
    const size_t at = out->nodes.size();
    out->nodes.emplace_back();
    std::copy(lo, lo + 3, out->nodes[at].lo);
    std::copy(hi, hi + 3, out->nodes[at].hi);
    if (n->leaf) {
        out->nodes[at].count = static_cast<int32_t>(n->prims->size());
        out->nodes[at].index = static_cast<int32_t>(out->prims.size());
        out->prims.insert(out->prims.end(), n->prims->begin(), n->prims->end());
        return;
    }
    Flatten(n->child[0], n->lo[0], n->hi[0], out);
    out->nodes[at].index = static_cast<int32_t>(out->nodes.size());
    Flatten(n->child[1], n->lo[1], n->hi[1], out);
}

// Child `flat` of a packed node: its bounds and its reference (tables.h).
core::PackedBvhChild Child(const FlatBvh &bvh, const std::vector<int32_t> &packed_index,
                           int32_t flat) {
    const FlatBvhNode &n = bvh.nodes[flat];
    core::PackedBvhChild c{};
    c.lo = core::vec3(n.lo[0], n.lo[1], n.lo[2]);
    c.hi = core::vec3(n.hi[0], n.hi[1], n.hi[2]);
    c.ref = packed_index[flat];
    if (n.count > 0) {
        CHECK(n.count < (1 << core::kBvhLeafCountBits));  // (the builder's maxLeafSize)
        if (n.index >= (1 << (31 - core::kBvhLeafCountBits)))
            ErrorExit("more than 2^28 surfaces: beyond the GPU's own BVH walk (-backend embree)");
        c.ref = ~(n.index << core::kBvhLeafCountBits | n.count);
    }
    return c;
}

}  // namespace

std::vector<core::PackedBvhNode> PackBvh(const FlatBvh &bvh) {
    std::vector<core::PackedBvhNode> out;
    if (bvh.nodes.empty()) return out;
    std::vector<int32_t> packed_index(bvh.nodes.size(), -1);
    for (size_t i = 0; i < bvh.nodes.size(); ++i)
        if (bvh.nodes[i].count == 0)
            packed_index[i] = static_cast<int32_t>(out.size()), out.emplace_back();
    if (out.empty()) {  // a root that is a leaf: both children of a root of its own
        const core::PackedBvhChild leaf = Child(bvh, packed_index, 0);
        out.push_back(core::PackedBvhNode{{leaf, leaf}});
        return out;
    }
    for (size_t i = 0; i < bvh.nodes.size(); ++i) {
        if (bvh.nodes[i].count != 0) continue;
        out[packed_index[i]] = core::PackedBvhNode{{Child(bvh, packed_index, int32_t(i) + 1),
                                                    Child(bvh, packed_index, bvh.nodes[i].index)}};
    }
    return out;
}

FlatBvh BuildBvh(const std::vector<float> &boxes) {
    FlatBvh out;
    const size_t n = boxes.size() / 6;
    if (n == 0) return out;
    std::vector<RTCBuildPrimitive> prims(n);
    float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
    for (size_t i = 0; i < n; ++i) {
        const float *b = &boxes[6 * i];
        RTCBuildPrimitive &p = prims[i];
        p.lower_x = b[0], p.lower_y = b[1], p.lower_z = b[2];
        p.upper_x = b[3], p.upper_y = b[4], p.upper_z = b[5];
        p.geomID = 0;
        p.primID = static_cast<unsigned int>(i);
        for (int k = 0; k < 3; ++k)
            lo[k] = std::min(lo[k], b[k]), hi[k] = std::max(hi[k], b[3 + k]);
    }
    RTCDevice device = rtcNewDevice(nullptr);
    if (!device) ErrorExit("Embree: cannot create a device for the BVH builder");
    RTCBVH bvh = rtcNewBVH(device);
    Build build;
    RTCBuildArguments args = rtcDefaultBuildArguments();
    args.buildQuality = RTC_BUILD_QUALITY_MEDIUM;  // HIGH would want spatial splits
    args.maxBranchingFactor = 2;
    args.maxDepth = 64;  // the GPU's traversal stack holds as many
    args.maxLeafSize = 4;
    args.bvh = bvh;
    args.primitives = prims.data();
    args.primitiveCount = n;
    args.primitiveArrayCapacity = n;
    args.createNode = CreateNode;
    args.setNodeChildren = SetChildren;
    args.setNodeBounds = SetBounds;
    args.createLeaf = CreateLeaf;
    args.userPtr = &build;
    const Node *root = static_cast<const Node *>(rtcBuildBVH(&args));
    CHECK(root != nullptr);
    Flatten(root, lo, hi, &out);
    rtcReleaseBVH(bvh);
    rtcReleaseDevice(device);
    return out;
}

}  // namespace dayflux
