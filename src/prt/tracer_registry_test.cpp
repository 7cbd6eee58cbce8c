// The registry of visibility backends (skybake/visibility.h, [SECTION]
// Backends): one set of rules for every front end, and a backend that exists
// only in this test, registered here, running a whole AO and PRT bake.
#include <algorithm>
#include <atomic>

#include <gtest/gtest.h>

#include "skybake/bake.h"
#include "skybake/core.h"
#include "skybake/error.h"
#include "skybake/prt.h"

namespace skybake {
namespace {

std::string error_field(const TracerRequest& r) {
    try {
        resolve_tracer(r);
    } catch (const Error& e) {
        return e.where();
    }
    return "(accepted)";
}

TracerRequest request(std::string device, std::string backend = "", std::string method = "",
                      std::uint32_t resolution = 0, bool closest_hit = false) {
    TracerRequest r;
    r.device = std::move(device);
    r.backend = std::move(backend);
    r.method = std::move(method);
    r.resolution = resolution;
    r.closest_hit = closest_hit;
    return r;
}

TEST(TracerRegistry, TheBuildsBackendsDeclareWhatTheyCanDo) {
    const auto names = visibility_backend_names();
    for (const char* n : {"embree", "cuda", "raster", "brute"})
        EXPECT_EQ(std::count(names.begin(), names.end(), n), 1) << n;
    EXPECT_EQ(names.front(), "embree"); // the CPU's default is registered first
    EXPECT_TRUE(find_tracer_backend("embree").closest_hit);
    EXPECT_FALSE(find_tracer_backend("raster").closest_hit);
    EXPECT_TRUE(find_tracer_backend("raster").resolution);
    EXPECT_EQ(find_tracer_backend("raster").device, "opengl");
    EXPECT_EQ(find_tracer_backend("cuda").methods.size(), 3u);
    EXPECT_EQ(default_trace_method("raster"), TraceMethod::Cube);
    for (const TracerBackend& b : tracer_backends())
        EXPECT_FALSE(b.summary.empty()) << b.name;
}

TEST(TracerRegistry, OneDeviceChoiceForEveryFrontEnd) {
    // auto: a CUDA GPU when one answers, else the CPU's first backend.
    const TracerChoice a = resolve_tracer(request("auto"));
    EXPECT_EQ(a.backend->name, cuda_device_count() > 0 ? "cuda" : "embree");
    EXPECT_EQ(resolve_tracer(request("cpu")).backend->name, "embree");
    EXPECT_EQ(resolve_tracer(request("cuda")).backend->name, "cuda"); // resolved; creating it needs the GPU
    const TracerChoice gl = resolve_tracer(request("opengl"));
    EXPECT_EQ(gl.backend->name, "raster");
    EXPECT_EQ(gl.method, TraceMethod::Cube);
    EXPECT_EQ(resolve_tracer(request("auto", "raster", "directional", 512)).method, TraceMethod::Directional);
    EXPECT_EQ(resolve_tracer(request("auto", "", "", 0, true)).backend->closest_hit, true);

    // Each refusal names the field at fault.
    EXPECT_EQ(error_field(request("tpu")), "device");
    EXPECT_EQ(error_field(request("cuda", "embree")), "device");
    EXPECT_EQ(error_field(request("cpu", "raster")), "device");
    EXPECT_EQ(error_field(request("auto", "optix")), "backend");
    EXPECT_EQ(error_field(request("auto", "embree", "per-polygon")), "method");
    EXPECT_EQ(error_field(request("auto", "raster", "bvh")), "method");
    EXPECT_EQ(error_field(request("auto", "", "octree")), "method");
    EXPECT_EQ(error_field(request("auto", "embree", "", 256)), "resolution");
    EXPECT_EQ(error_field(request("auto", "raster", "", 0, true)), "backend");
    EXPECT_EQ(error_field(request("opengl", "", "", 0, true)), "backend");
    try {
        resolve_tracer(request("auto", "optix"));
    } catch (const Error& e) {
        EXPECT_NE(e.message().find("embree, cuda, raster, brute"), std::string::npos) << e.message();
    }
}

TEST(TracerRegistry, RegistrationIsChecked) {
    TracerBackend dup;
    dup.name = "embree";
    dup.device = "cpu";
    dup.methods = {TraceMethod::Bvh};
    dup.make_tracer = [](TraceMethod, std::uint32_t) { return make_visibility_tracer("embree"); };
    EXPECT_THROW(register_tracer_backend(dup), Error);
    TracerBackend empty;
    empty.name = "test-empty";
    EXPECT_THROW(register_tracer_backend(empty), Error);
    const auto names = visibility_backend_names();
    EXPECT_EQ(std::count(names.begin(), names.end(), "test-empty"), 0);
}

// A backend of this test alone: Embree underneath, counting the acceleration
// structures it is asked to build. Nothing outside this file knows it.
std::atomic<int> g_builds{0};

class CountingTracer final : public VisibilityTracer, public RayQueries {
public:
    const char* name() const override { return "test-counting"; }
    void set_mesh(const Mesh& mesh, BackFaces back_faces) override {
        ++g_builds;
        tracer_->set_mesh(mesh, back_faces);
        queries_->set_mesh(mesh, back_faces);
    }
    std::uint32_t set_rule(const TraceRule& rule) override { return tracer_->set_rule(rule); }
    void trace(const TraceChunk& chunk) override { tracer_->trace(chunk); }
    void occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded) const override {
        queries_->occluded(rays, occluded);
    }
    void intersect(std::span<const Ray> rays, std::span<RayHit> hits) const override {
        queries_->intersect(rays, hits);
    }

private:
    std::unique_ptr<VisibilityTracer> tracer_ = make_visibility_tracer("embree");
    std::unique_ptr<RayQueries> queries_ = make_ray_queries("embree");
};

void register_counting_backend() {
    static const bool once = [] {
        TracerBackend b;
        b.name = "test-counting";
        b.device = "cpu";
        b.summary = "Embree, counting its builds (tests only)";
        b.methods = {TraceMethod::Bvh};
        b.closest_hit = true;
        b.make_tracer = [](TraceMethod, std::uint32_t) { return std::make_unique<CountingTracer>(); };
        b.make_ray_queries = [] { return std::make_unique<CountingTracer>(); };
        register_tracer_backend(std::move(b));
        return true;
    }();
    (void)once;
}

Mesh city() {
    ProceduralOptions o;
    o.kind = ProceduralKind::City;
    o.target_triangles = 2000;
    Mesh m = generate_mesh(o);
    compute_normals(m);
    return m;
}

TEST(TracerRegistry, ABackendRegisteredInATestBakesAoAndPrt) {
    register_counting_backend();
    const auto names = visibility_backend_names();
    EXPECT_EQ(names.back(), "test-counting");
    // Registered after Embree, it is not the CPU's default; named, it is chosen.
    EXPECT_EQ(resolve_tracer(request("cpu")).backend->name, "embree");
    const TracerChoice c = resolve_tracer(request("cpu", "test-counting", "", 0, true));
    EXPECT_EQ(c.backend->name, "test-counting");
    EXPECT_EQ(error_field(request("cuda", "test-counting")), "device");

    const SphereRule rule = parse_rule("lebedev:110");
    // AO: the same bits as Embree's, through the registry by name.
    Mesh a = city(), b = city();
    BakeOptions o;
    o.store_bits = true;
    BakeOutputs mine, theirs;
    g_builds = 0;
    const AoBakeReport r = bake_ambient_occlusion(a, rule, "test-counting", o, &mine);
    EXPECT_EQ(r.backend, "test-counting");
    EXPECT_EQ(g_builds.load(), 1);
    bake_ambient_occlusion(b, rule, "embree", o, &theirs);
    EXPECT_EQ(mine.visibility_bits, theirs.visibility_bits);
    EXPECT_EQ(mine.ao, theirs.ao);

    // PRT with a bounce: the tracer for the words, the queries for the gathers.
    Mesh p = city(), q = city();
    TransferOptions t;
    t.order = 2;
    t.kind = TransferKind::Interreflected;
    t.bounces = 1;
    const std::vector<glm::vec3> albedo(p.vertex_count(), glm::vec3(0.5f, 0.4f, 0.3f));
    Transfer tp, tq;
    {
        const auto tracer = make_visibility_tracer(c);
        const auto queries = make_ray_queries(c);
        bake_transfer(p, rule, *tracer, BakeOptions{}, t, albedo, queries.get(), tp);
    }
    {
        const auto tracer = make_visibility_tracer("embree");
        const auto queries = make_ray_queries("embree");
        bake_transfer(q, rule, *tracer, BakeOptions{}, t, albedo, queries.get(), tq);
    }
    ASSERT_EQ(tp.coeffs.size(), tq.coeffs.size());
    EXPECT_EQ(tp.coeffs, tq.coeffs);
    EXPECT_GT(*std::max_element(tp.coeffs.begin(), tp.coeffs.end()), 0.1f);
}

} // namespace
} // namespace skybake
