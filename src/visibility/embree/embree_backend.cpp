// Embree 3 visibility backend.
//
// Wald I., Woop S., Benthin C., Johnson G. S., Ernst M. Embree: a kernel
// framework for efficient CPU ray tracing. ACM TOG 33(4), SIGGRAPH 2014.
//
// trace() casts, for each vertex, the rule directions on or above its horizon
// from one origin. Directions are visited in a fixed coherent order (Morton
// order of the octahedral map, bake_common.h). With a large rule they are issued
// as 16-ray packets (rtcOccluded16, coherent context flag): rays of one packet
// share the origin and point into a small patch of the sphere, so they traverse
// the BVH together. With a small rule a packet would spread over the whole sky
// and single rays (rtcOccluded1) are faster.
// Vertices are spread over TBB tasks; each vertex's words depend on that vertex
// alone, so they do not depend on the chunking or the thread count.
#include "visibility/embree/embree_backend.h"

#include <algorithm>
#include <atomic>
#include <cassert>
#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "core/parallel.h"
#include "skybake/error.h"
#include "skybake/mesh.h"
#include "skybake/sphere.h"
#include "visibility/trace_hd.h"

namespace skybake::visibility {

namespace {

constexpr int kPacket = 16;
// Rules with at least this many directions are traced in 16-ray packets, others
// ray by ray (measured crossover: between 590 and 1202 on the city scenes).
constexpr std::uint32_t kPacketMinDirections = 1000;

const char* error_name(RTCError code) {
    switch (code) {
    case RTC_ERROR_NONE: return "no error";
    case RTC_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case RTC_ERROR_INVALID_OPERATION: return "invalid operation";
    case RTC_ERROR_OUT_OF_MEMORY: return "out of memory";
    case RTC_ERROR_UNSUPPORTED_CPU: return "unsupported CPU";
    case RTC_ERROR_CANCELLED: return "cancelled";
    default: return "unknown error";
    }
}

RTCIntersectContext coherent_context() {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    return ctx;
}

RTCIntersectContext incoherent_context() {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    return ctx;
}

void set_lane(RTCRay16& r, int lane, const glm::vec3& o, const glm::vec3& d, float t_min, float t_max) {
    r.org_x[lane] = o.x;
    r.org_y[lane] = o.y;
    r.org_z[lane] = o.z;
    r.tnear[lane] = t_min;
    r.dir_x[lane] = d.x;
    r.dir_y[lane] = d.y;
    r.dir_z[lane] = d.z;
    r.time[lane] = 0.0f;
    r.tfar[lane] = t_max;
    r.mask[lane] = 0xffffffffu;
    r.id[lane] = unsigned(lane);
    r.flags[lane] = 0;
}

} // namespace

EmbreeBackend::EmbreeBackend() {
    device_ = rtcNewDevice("verbose=0");
    if (!device_)
        throw Error(fmt::format("cannot start Embree: {}", error_name(rtcGetDeviceError(nullptr))), "backend");
    rtcSetDeviceErrorFunction(device_, &EmbreeBackend::error_callback, this);
}

EmbreeBackend::~EmbreeBackend() {
    if (scene_)
        rtcReleaseScene(scene_);
    if (device_)
        rtcReleaseDevice(device_);
}

void EmbreeBackend::error_callback(void* self, RTCError code, const char* message) {
    auto* b = static_cast<EmbreeBackend*>(self);
    std::lock_guard lock(b->error_mutex_);
    b->last_error_ = fmt::format("{}{}{}", error_name(code), message && *message ? ": " : "", message ? message : "");
}

void EmbreeBackend::check(const char* what) {
    const RTCError code = rtcGetDeviceError(device_);
    if (code == RTC_ERROR_NONE)
        return;
    std::string detail;
    {
        std::lock_guard lock(error_mutex_);
        detail = last_error_.empty() ? error_name(code) : last_error_;
    }
    if (code == RTC_ERROR_OUT_OF_MEMORY)
        throw Error(fmt::format("Embree ran out of memory while {}; use a smaller mesh or a machine with more memory",
                                what),
                    "backend");
    throw Error(fmt::format("Embree failed while {}: {}", what, detail), "backend");
}

// Occlusion and intersection filter for BackFaces::Ignore: a candidate hit on
// a triangle seen from behind (direction along its front normal) is rejected.
void EmbreeBackend::back_face_filter(const RTCFilterFunctionNArguments* args) {
    const auto* self = static_cast<const EmbreeBackend*>(args->geometryUserPtr);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] != -1)
            continue;
        const unsigned prim = RTCHitN_primID(args->hit, args->N, i);
        const glm::vec3 d(RTCRayN_dir_x(args->ray, args->N, i), RTCRayN_dir_y(args->ray, args->N, i),
                          RTCRayN_dir_z(args->ray, args->N, i));
        if (glm::dot(self->face_normals_[prim], d) > 0.0f)
            args->valid[i] = 0;
    }
}

void EmbreeBackend::set_mesh(const Mesh& mesh, BackFaces back_faces) {
    validate_mesh(mesh, "mesh");
    if (scene_) {
        rtcReleaseScene(scene_);
        scene_ = nullptr;
    }
    const std::size_t nv = mesh.vertex_count(), nt = mesh.triangle_count();
    RTCScene scene = rtcNewScene(device_);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
    RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vb = static_cast<float*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), nv));
    auto* ib = static_cast<unsigned*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), nt));
    if (!vb || !ib) {
        rtcReleaseGeometry(geom);
        rtcReleaseScene(scene);
        check("allocating the mesh buffers");
        throw Error("Embree could not allocate the mesh buffers", "backend");
    }
    for (std::size_t v = 0; v < nv; ++v) {
        vb[3 * v] = mesh.positions[v].x;
        vb[3 * v + 1] = mesh.positions[v].y;
        vb[3 * v + 2] = mesh.positions[v].z;
    }
    std::copy(mesh.indices.begin(), mesh.indices.end(), ib);
    face_normals_.clear();
    if (back_faces == BackFaces::Ignore) {
        face_normals_.resize(nt);
        for (std::size_t t = 0; t < nt; ++t) {
            const glm::vec3 p0 = mesh.positions[mesh.indices[3 * t]];
            const glm::vec3 p1 = mesh.positions[mesh.indices[3 * t + 1]];
            const glm::vec3 p2 = mesh.positions[mesh.indices[3 * t + 2]];
            face_normals_[t] = glm::cross(p1 - p0, p2 - p0);
        }
        rtcSetGeometryUserData(geom, this);
        rtcSetGeometryOccludedFilterFunction(geom, &EmbreeBackend::back_face_filter);
        rtcSetGeometryIntersectFilterFunction(geom, &EmbreeBackend::back_face_filter);
    }
    rtcCommitGeometry(geom);
    rtcAttachGeometry(scene, geom);
    rtcReleaseGeometry(geom);
    rtcCommitScene(scene);
    if (rtcGetDeviceError(device_) != RTC_ERROR_NONE) {
        rtcReleaseScene(scene);
        check(fmt::format("building the BVH of {} triangles", nt).c_str());
    }
    scene_ = scene;
}

void EmbreeBackend::occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded) const {
    assert(scene_ && rays.size() == occluded.size());
    const std::size_t packets = (rays.size() + kPacket - 1) / kPacket;
    parallel_for(packets, 64, [&](std::size_t b, std::size_t e) {
        RTCIntersectContext ctx = incoherent_context();
        alignas(64) RTCRay16 r;
        alignas(64) int valid[kPacket];
        for (std::size_t p = b; p < e; ++p) {
            const std::size_t first = p * kPacket;
            const int n = int(std::min<std::size_t>(kPacket, rays.size() - first));
            for (int l = 0; l < kPacket; ++l) {
                valid[l] = l < n ? -1 : 0;
                if (l < n) {
                    const Ray& ray = rays[first + std::size_t(l)];
                    set_lane(r, l, ray.origin, ray.direction, ray.t_min, ray.t_max);
                }
            }
            rtcOccluded16(valid, scene_, &ctx, &r);
            for (int l = 0; l < n; ++l)
                occluded[first + std::size_t(l)] = r.tfar[l] == -std::numeric_limits<float>::infinity() ? 1 : 0;
        }
    });
}

void EmbreeBackend::intersect(std::span<const Ray> rays, std::span<RayHit> hits) const {
    assert(scene_ && rays.size() == hits.size());
    const std::size_t packets = (rays.size() + kPacket - 1) / kPacket;
    parallel_for(packets, 16, [&](std::size_t b, std::size_t e) {
        RTCIntersectContext ctx = incoherent_context();
        alignas(64) RTCRayHit16 rh;
        alignas(64) int valid[kPacket];
        for (std::size_t p = b; p < e; ++p) {
            const std::size_t first = p * kPacket;
            const int n = int(std::min<std::size_t>(kPacket, rays.size() - first));
            for (int l = 0; l < kPacket; ++l) {
                valid[l] = l < n ? -1 : 0;
                if (l < n) {
                    const Ray& ray = rays[first + std::size_t(l)];
                    set_lane(rh.ray, l, ray.origin, ray.direction, ray.t_min, ray.t_max);
                    rh.hit.geomID[l] = RTC_INVALID_GEOMETRY_ID;
                    rh.hit.instID[0][l] = RTC_INVALID_GEOMETRY_ID;
                }
            }
            rtcIntersect16(valid, scene_, &ctx, &rh);
            for (int l = 0; l < n; ++l) {
                RayHit& h = hits[first + std::size_t(l)];
                if (rh.hit.geomID[l] == RTC_INVALID_GEOMETRY_ID) {
                    h = RayHit{};
                } else {
                    h.t = rh.ray.tfar[l];
                    h.triangle = rh.hit.primID[l];
                    h.u = rh.hit.u[l];
                    h.v = rh.hit.v[l];
                }
            }
        }
    });
}

std::uint32_t EmbreeBackend::set_rule(const TraceRule& rule) {
    rule_ = rule;
    // Without rotation every vertex has the same directions: keep one copy,
    // structure of arrays.
    const auto directions = std::uint32_t(rule.points.size());
    fixed_x_.resize(directions);
    fixed_y_.resize(directions);
    fixed_z_.resize(directions);
    for (std::uint32_t j = 0; j < directions; ++j) {
        fixed_x_[j] = rule.points[j].x;
        fixed_y_[j] = rule.points[j].y;
        fixed_z_[j] = rule.points[j].z;
    }
    return 0xffffffffu;
}

void EmbreeBackend::trace(const TraceChunk& chunk) {
    assert(scene_);
    const TraceRule& rule = rule_;
    const auto directions = std::uint32_t(rule.points.size());
    const std::uint32_t words_per_vertex = rule.words_per_vertex;
    const float inf = std::numeric_limits<float>::infinity();
    // Packets pay when a vertex's rays are many, so that 16 consecutive ones in
    // the coherent order point into a small patch of sky; with few directions
    // single rays are faster (docs/PERFORMANCE.md).
    const bool packets = directions >= kPacketMinDirections;
    // Tasks of about 8k directions: enough to hide the scratch set-up.
    const std::size_t grain = std::clamp<std::size_t>(8192 / std::max<std::uint32_t>(directions, 1), 4, 256);
    parallel_for(chunk.count, grain, [&](std::size_t b, std::size_t e) {
        RTCIntersectContext ctx = coherent_context(), ctx1 = incoherent_context();
        alignas(64) RTCRay16 r;
        alignas(64) int valid[kPacket];
        // Per-direction scratch in visiting order, structure of arrays.
        std::vector<float> cs(directions), rx, ry, rz;
        if (rule.rotate) {
            rx.resize(directions);
            ry.resize(directions);
            rz.resize(directions);
        }
        const float* xs = rule.rotate ? rx.data() : fixed_x_.data();
        const float* ys = rule.rotate ? ry.data() : fixed_y_.data();
        const float* zs = rule.rotate ? rz.data() : fixed_z_.data();
        std::vector<std::uint32_t> sel(directions);
        std::vector<RTCRay> ray1;
        for (std::size_t i = b; i < e; ++i) {
            const glm::vec3 origin = chunk.origins[i], normal = chunk.normals[i];
            const glm::mat3 rotation = rule.rotate ? chunk.rotations[i] : glm::mat3(1.0f);
            std::uint32_t* words = chunk.words.data() + i * words_per_vertex;
            std::fill(words, words + words_per_vertex, 0u);
            // Directions and cosines once per vertex.
            for (std::uint32_t j = 0; j < directions; ++j) {
                glm::vec3 x;
                vertex_direction(rule.points[j], rotation, rule.rotate, normal, x, cs[j]);
                if (rule.rotate) {
                    rx[j] = x.x;
                    ry[j] = x.y;
                    rz[j] = x.z;
                }
            }
            // All rays of the vertex share origin and interval: set those lanes once.
            for (int l = 0; l < kPacket; ++l)
                set_lane(r, l, origin, normal, 0.0f, rule.t_max);
            // Branch-free selection of the directions on or above the horizon ...
            std::uint32_t m = 0;
            for (std::uint32_t j = 0; j < directions; ++j) {
                sel[m] = j;
                m += std::uint32_t(needs_ray(cs[j]));
            }
            if (!packets) {
                // ... one by one (few directions: a packet would spread over the
                // sky), set up first and traced in one tight loop, which measured
                // 15% faster than interleaving set-up and calls.
                ray1.resize(m);
                for (std::uint32_t q = 0; q < m; ++q) {
                    const std::uint32_t j = sel[q];
                    RTCRay& one = ray1[q];
                    one.org_x = origin.x;
                    one.org_y = origin.y;
                    one.org_z = origin.z;
                    one.tnear = 0.0f;
                    one.dir_x = xs[j];
                    one.dir_y = ys[j];
                    one.dir_z = zs[j];
                    one.time = 0.0f;
                    one.tfar = rule.t_max;
                    one.mask = 0xffffffffu;
                    one.id = 0;
                    one.flags = 0;
                }
                for (std::uint32_t q = 0; q < m; ++q)
                    rtcOccluded1(scene_, &ctx1, &ray1[q]);
                for (std::uint32_t q = 0; q < m; ++q)
                    if (ray1[q].tfar != -inf)
                        set_bit(words, rule.order[sel[q]]);
                continue;
            }
            // ... or 16 at a time. Occluded lanes come back with tfar = -inf.
            for (std::uint32_t base = 0; base < m; base += kPacket) {
                const int count = int(std::min<std::uint32_t>(kPacket, m - base));
                const std::uint32_t* lane_j = sel.data() + base;
                for (int l = 0; l < kPacket; ++l) {
                    valid[l] = l < count ? -1 : 0;
                    r.tfar[l] = rule.t_max;
                }
                for (int l = 0; l < count; ++l) {
                    r.dir_x[l] = xs[lane_j[l]];
                    r.dir_y[l] = ys[lane_j[l]];
                    r.dir_z[l] = zs[lane_j[l]];
                }
                rtcOccluded16(valid, scene_, &ctx, &r);
                for (int l = 0; l < count; ++l)
                    if (r.tfar[l] != -inf)
                        set_bit(words, rule.order[lane_j[l]]);
            }
        }
    });
}

} // namespace skybake::visibility

// Registered first: the CPU's default backend (skybake/visibility.h, [SECTION] Backends).
void skybake_register_embree_tracer() {
    using namespace skybake;
    TracerBackend b;
    b.name = "embree";
    b.device = "cpu";
    b.summary = "Intel Embree 3, every core";
    b.methods = {TraceMethod::Bvh};
    b.closest_hit = true;
    b.make_tracer = [](TraceMethod, std::uint32_t) { return std::make_unique<visibility::EmbreeBackend>(); };
    b.make_ray_queries = [] { return std::make_unique<visibility::EmbreeBackend>(); };
    register_tracer_backend(std::move(b));
}
