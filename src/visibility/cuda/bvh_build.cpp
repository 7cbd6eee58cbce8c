// Builds the CUDA backend's BVH on the CPU with Embree's BVH builder
// (rtcBuildBVH: binned SAH, optionally with spatial splits) and flattens it
// into the layout of cuda/bvh.h.
//
// Stich M., Friedrich H., Dietrich A. Spatial splits in bounding volume
// hierarchies. High-Performance Graphics 2009.
// Wald I., Woop S., Benthin C., Johnson G. S., Ernst M. Embree: a kernel
// framework for efficient CPU ray tracing. ACM TOG 33(4), 2014.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <string>

#include <embree3/rtcore.h>
#include <fmt/format.h>

#include "skybake/error.h"
#include "skybake/mesh.h"
#include "visibility/cuda/bvh.h"

namespace skybake::visibility {

namespace {

// The tree as Embree's callbacks build it, in memory of Embree's thread-local
// allocators (released with the RTCBVH).
struct BuildNode {
    bool leaf;
};
struct BuildInner : BuildNode {
    BuildNode* child[2];
    RTCBounds bounds[2];
};
struct BuildLeaf : BuildNode {
    std::uint32_t count;
    std::uint32_t ids[kMaxLeafTriangles];
};

struct BuildContext {
    const Mesh* mesh;
    std::atomic<bool> leaf_overflow{false}; // a leaf larger than kMaxLeafTriangles (never with maxLeafSize set)
};

void* create_node(RTCThreadLocalAllocator alloc, unsigned child_count, void*) {
    auto* n = static_cast<BuildInner*>(rtcThreadLocalAlloc(alloc, sizeof(BuildInner), 16));
    n->leaf = false;
    n->child[0] = n->child[1] = nullptr;
    return n;
}

void set_children(void* node, void** children, unsigned child_count, void*) {
    auto* n = static_cast<BuildInner*>(node);
    for (unsigned i = 0; i < 2; ++i)
        n->child[i] = i < child_count ? static_cast<BuildNode*>(children[i]) : nullptr;
}

void set_bounds(void* node, const RTCBounds** bounds, unsigned child_count, void*) {
    auto* n = static_cast<BuildInner*>(node);
    for (unsigned i = 0; i < 2 && i < child_count; ++i)
        n->bounds[i] = *bounds[i];
}

void* create_leaf(RTCThreadLocalAllocator alloc, const RTCBuildPrimitive* prims, size_t count, void* user) {
    auto* l = static_cast<BuildLeaf*>(rtcThreadLocalAlloc(alloc, sizeof(BuildLeaf), 16));
    l->leaf = true;
    if (count > kMaxLeafTriangles)
        static_cast<BuildContext*>(user)->leaf_overflow = true;
    l->count = std::uint32_t(std::min<size_t>(count, kMaxLeafTriangles));
    for (std::uint32_t i = 0; i < l->count; ++i)
        l->ids[i] = prims[i].primID;
    return l;
}

// Bounds of the parts of a triangle (already clipped to prim's box) on either
// side of the plane x[dim] = pos.
void split_primitive(const RTCBuildPrimitive* prim, unsigned dim, float pos, RTCBounds* left, RTCBounds* right,
                     void* user) {
    const Mesh& mesh = *static_cast<const BuildContext*>(user)->mesh;
    const std::uint32_t* idx = &mesh.indices[3 * std::size_t(prim->primID)];
    const float inf = std::numeric_limits<float>::infinity();
    glm::vec3 llo(inf), lhi(-inf), rlo(inf), rhi(-inf);
    auto grow = [](glm::vec3& lo, glm::vec3& hi, const glm::vec3& p) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    };
    for (int e = 0; e < 3; ++e) {
        const glm::vec3 a = mesh.positions[idx[e]], b = mesh.positions[idx[(e + 1) % 3]];
        if (a[int(dim)] <= pos)
            grow(llo, lhi, a);
        if (a[int(dim)] >= pos)
            grow(rlo, rhi, a);
        if ((a[int(dim)] < pos && b[int(dim)] > pos) || (a[int(dim)] > pos && b[int(dim)] < pos)) {
            const float t = (pos - a[int(dim)]) / (b[int(dim)] - a[int(dim)]);
            glm::vec3 p = a + t * (b - a);
            p[int(dim)] = pos;
            grow(llo, lhi, p);
            grow(rlo, rhi, p);
        }
    }
    const glm::vec3 plo(prim->lower_x, prim->lower_y, prim->lower_z), phi(prim->upper_x, prim->upper_y, prim->upper_z);
    llo = glm::max(llo, plo), lhi = glm::min(lhi, phi);
    rlo = glm::max(rlo, plo), rhi = glm::min(rhi, phi);
    lhi[int(dim)] = std::min(lhi[int(dim)], pos);
    rlo[int(dim)] = std::max(rlo[int(dim)], pos);
    *left = RTCBounds{llo.x, llo.y, llo.z, 0.0f, lhi.x, lhi.y, lhi.z, 0.0f};
    *right = RTCBounds{rlo.x, rlo.y, rlo.z, 0.0f, rhi.x, rhi.y, rhi.z, 0.0f};
}

BvhTriangle make_triangle(const Mesh& mesh, std::uint32_t t) {
    const std::uint32_t* i = &mesh.indices[3 * std::size_t(t)];
    const glm::vec3 p0 = mesh.positions[i[0]];
    BvhTriangle tri{};
    tri.p0 = p0;
    tri.e1 = mesh.positions[i[1]] - p0;
    tri.e2 = mesh.positions[i[2]] - p0;
    tri.id = t;
    return tri;
}

// Depth-first flattening: inner nodes in pre-order, leaf triangles in the
// order the leaves are met.
class Flattener {
public:
    // out.soup must be filled: leaves copy their triangles from it.
    Flattener(Bvh& out, float pad) : out_(out), pad_(pad) {}

    // Appends `node` and returns its encoded child reference.
    std::int32_t emit(const BuildNode* node, int depth) {
        out_.depth = std::max(out_.depth, depth);
        if (node->leaf) {
            const auto* l = static_cast<const BuildLeaf*>(node);
            const auto first = std::uint32_t(out_.triangles.size());
            if (first + l->count >= kMaxBvhTriangleRefs)
                throw Error(fmt::format("the BVH needs more than {} triangle references; the CUDA backend takes "
                                        "meshes up to about 100 million triangles",
                                        kMaxBvhTriangleRefs),
                            "backend");
            for (std::uint32_t k = 0; k < l->count; ++k)
                out_.triangles.push_back(out_.soup[l->ids[k]]);
            return encode_leaf(first, l->count);
        }
        const auto* n = static_cast<const BuildInner*>(node);
        const auto index = std::int32_t(out_.nodes.size());
        out_.nodes.emplace_back();
        for (int c = 0; c < 2; ++c) {
            if (!n->child[c]) { // a node with one child: the other is an empty leaf in the same box
                set_box(std::size_t(index), c, n->bounds[0]);
                out_.nodes[std::size_t(index)].child[c] = encode_leaf(0, 0);
                continue;
            }
            set_box(std::size_t(index), c, n->bounds[c]);
            const std::int32_t child = emit(n->child[c], depth + 1);
            out_.nodes[std::size_t(index)].child[c] = child;
        }
        return index;
    }

    void set_box(std::size_t node, int c, const RTCBounds& b) {
        float* box = out_.nodes[node].box + 6 * c;
        box[0] = b.lower_x - pad_, box[1] = b.upper_x + pad_;
        box[2] = b.lower_y - pad_, box[3] = b.upper_y + pad_;
        box[4] = b.lower_z - pad_, box[5] = b.upper_z + pad_;
    }

private:
    Bvh& out_;
    float pad_;
};

struct DeviceHolder {
    RTCDevice device = nullptr;
    RTCBVH bvh = nullptr;
    std::mutex mutex;
    std::string error;
    ~DeviceHolder() {
        if (bvh)
            rtcReleaseBVH(bvh);
        if (device)
            rtcReleaseDevice(device);
    }
};

void on_error(void* user, RTCError code, const char* message) {
    auto* h = static_cast<DeviceHolder*>(user);
    std::lock_guard lock(h->mutex);
    h->error = message ? message : "error " + std::to_string(int(code));
}

} // namespace

Bvh build_bvh(const Mesh& mesh, bool spatial_splits) {
    validate_mesh(mesh, "mesh");
    const auto t0 = std::chrono::steady_clock::now();
    const std::size_t nt = mesh.triangle_count();
    if (nt >= kMaxBvhTriangleRefs / 2)
        throw Error(fmt::format("{} triangles is too many for the CUDA backend's BVH (at most {}); use --backend "
                                "embree",
                                nt, kMaxBvhTriangleRefs / 2 - 1),
                    "backend");

    Bvh out;
    out.soup.resize(nt);
    for (std::size_t t = 0; t < nt; ++t)
        out.soup[t] = make_triangle(mesh, std::uint32_t(t));

    // Room for the references spatial splits add.
    std::vector<RTCBuildPrimitive> prims(spatial_splits ? 2 * nt : nt);
    glm::vec3 lo(std::numeric_limits<float>::infinity()), hi(-std::numeric_limits<float>::infinity());
    for (std::size_t t = 0; t < nt; ++t) {
        const std::uint32_t* i = &mesh.indices[3 * t];
        const glm::vec3 a = mesh.positions[i[0]], b = mesh.positions[i[1]], c = mesh.positions[i[2]];
        const glm::vec3 l = glm::min(a, glm::min(b, c)), h = glm::max(a, glm::max(b, c));
        lo = glm::min(lo, l);
        hi = glm::max(hi, h);
        RTCBuildPrimitive& p = prims[t];
        p.lower_x = l.x, p.lower_y = l.y, p.lower_z = l.z, p.geomID = 0;
        p.upper_x = h.x, p.upper_y = h.y, p.upper_z = h.z, p.primID = unsigned(t);
    }
    // Widening: Möller–Trumbore in single precision can accept a point a few
    // ulps outside a triangle; the box must not cull it.
    const float scale = std::max(glm::length(hi - lo), std::max(glm::length(lo), glm::length(hi)));
    const float pad = 4e-6f * scale + std::numeric_limits<float>::min();

    DeviceHolder h;
    h.device = rtcNewDevice("verbose=0");
    if (!h.device)
        throw Error("cannot start Embree to build the BVH", "backend");
    rtcSetDeviceErrorFunction(h.device, &on_error, &h);
    h.bvh = rtcNewBVH(h.device);
    BuildContext ctx;
    ctx.mesh = &mesh;
    RTCBuildArguments args = rtcDefaultBuildArguments();
    args.byteSize = sizeof(args);
    // MEDIUM: binned SAH. HIGH adds spatial splits, which need splitPrimitive.
    args.buildQuality = spatial_splits ? RTC_BUILD_QUALITY_HIGH : RTC_BUILD_QUALITY_MEDIUM;
    args.buildFlags = RTC_BUILD_FLAG_NONE;
    args.maxBranchingFactor = 2;
    args.maxDepth = kBvhStackSize;
    args.sahBlockSize = 1;
    args.minLeafSize = 1;
    args.maxLeafSize = kMaxLeafTriangles;
    args.traversalCost = 1.0f;
    args.intersectionCost = 1.0f;
    args.bvh = h.bvh;
    args.primitives = prims.data();
    args.primitiveCount = nt;
    args.primitiveArrayCapacity = prims.size();
    args.createNode = create_node;
    args.setNodeChildren = set_children;
    args.setNodeBounds = set_bounds;
    args.createLeaf = create_leaf;
    args.splitPrimitive = spatial_splits ? split_primitive : nullptr;
    args.userPtr = &ctx;
    const auto* root = static_cast<const BuildNode*>(rtcBuildBVH(&args));
    if (!root || rtcGetDeviceError(h.device) != RTC_ERROR_NONE) {
        std::lock_guard lock(h.mutex);
        throw Error(fmt::format("Embree could not build the BVH of {} triangles: {}", nt,
                                h.error.empty() ? "unknown error" : h.error),
                    "backend");
    }

    if (ctx.leaf_overflow)
        throw Error(fmt::format("Embree built a leaf of more than {} triangles", kMaxLeafTriangles), "backend");

    Flattener flat(out, pad);
    out.nodes.reserve(2 * nt / kMaxLeafTriangles + 16);
    out.triangles.reserve(nt + nt / 4);
    if (root->leaf) {
        // A mesh small enough for one leaf: a root whose second child is an
        // empty leaf in the same box.
        out.nodes.emplace_back();
        const RTCBounds b{lo.x, lo.y, lo.z, 0.0f, hi.x, hi.y, hi.z, 0.0f};
        flat.set_box(0, 0, b);
        flat.set_box(0, 1, b);
        out.nodes[0].child[0] = flat.emit(root, 1);
        out.nodes[0].child[1] = encode_leaf(0, 0);
        out.depth = 1;
    } else {
        flat.emit(root, 0);
    }
    if (out.depth > kBvhStackSize)
        throw Error(fmt::format("the BVH is {} levels deep; the GPU traversal handles {}", out.depth, kBvhStackSize),
                    "backend");
    out.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return out;
}

} // namespace skybake::visibility
