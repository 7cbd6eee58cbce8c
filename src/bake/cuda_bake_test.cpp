// The CUDA bake on the CPU: the kernels' thread bodies run on the host
// (EmulatedCudaTracer) through the bake driver, against the Embree bake.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "bake/cuda_bake_test_util.h"
#include "skybake/bake.h"
#include "skybake/core.h"
#include "skybake/error.h"

using namespace skybake;
using namespace skybake::visibility;
using namespace skybake::visibility_test;

// The kernels' thread bodies, run on the host, against the Embree bake
// (expect_agreement: bits, AO, and the same floats wherever the bits agree).
TEST(CudaBake, EmulatedKernelsMatchEmbree) {
    struct Case {
        const char* rule;
        BackFaces back;
        float max_distance;
        bool normalize;
    };
    const Case cases[] = {{"lebedev:590", BackFaces::Occlude, INFINITY, false},
                          {"lebedev:302+rotate", BackFaces::Occlude, INFINITY, true},
                          {"fibonacci:500", BackFaces::Ignore, INFINITY, false},
                          {"lebedev:266", BackFaces::Occlude, 0.2f, false}};
    for (const auto& [name, m] : scenes()) {
        for (const Case& c : cases) {
            SCOPED_TRACE(name + " " + c.rule);
            const SphereRule rule = parse_rule(c.rule);
            BakeOptions o;
            o.store_bits = true;
            o.back_faces = c.back;
            o.normalize = c.normalize;
            o.max_distance = std::isfinite(c.max_distance) ? c.max_distance * compute_bounds(m).diagonal() : INFINITY;
            BakeOutputs e;
            EmbreeBackend embree;
            bake_shading(m, rule, embree, o, e);
            const BakeOutputs g = emulated(m, rule, o, TraceMethod::Bvh);
            const Agreement a = compare_bakes(m, rule, o, g, e);
            a.print((name + " " + c.rule + ", host emulation").c_str());
            expect_agreement(a, tie_free(name, rule));
        }
    }
}

TEST(CudaBake, EveryMethodAndChunkingGiveTheSameBits) {
    const Mesh m = generated(ProceduralKind::City, 1500);
    const SphereRule rule = parse_rule("lebedev:194+rotate");
    BakeOptions o;
    o.store_bits = true;
    const BakeOutputs a = emulated(m, rule, o, TraceMethod::Bvh);
    const BakeOutputs b = emulated(m, rule, o, TraceMethod::PerVertex);
    const BakeOutputs c = emulated(m, rule, o, TraceMethod::Bvh, 7); // many small chunks
    for (const BakeOutputs* x : {&b, &c}) {
        EXPECT_EQ(x->visibility_bits, a.visibility_bits);
        EXPECT_EQ(x->ao, a.ao);
        EXPECT_EQ(x->shading, a.shading);
        EXPECT_EQ(x->bent_normal, a.bent_normal);
        EXPECT_EQ(x->rays, a.rays);
    }
}

TEST(CudaBake, MethodNamesAndTheCpuBackendsRefuseOthers) {
    for (TraceMethod mth : {TraceMethod::Bvh, TraceMethod::PerVertex, TraceMethod::PerPolygon})
        EXPECT_EQ(parse_trace_method(trace_method_name(mth)), mth);
    const auto names = visibility_backend_names();
    EXPECT_EQ(std::count(names.begin(), names.end(), "cuda"), 1); // listed in every build ...
    const TracerBackend& cuda = find_tracer_backend("cuda");
    if (!build_has_cuda() || cuda_device_count() == 0)
        EXPECT_FALSE(cuda.problem().empty()); // ... and says why it cannot run
    EXPECT_EQ(std::count(names.begin(), names.end(), "embree"), 1);
    Mesh m = generated(ProceduralKind::Sphere, 200);
    BakeOptions o;
    o.method = TraceMethod::PerPolygon;
    BakeOutputs out;
    for (const char* b : {"embree", "brute"}) {
        try {
            bake_ambient_occlusion(m, parse_rule("lebedev:50"), b, o, &out);
            ADD_FAILURE() << b << " accepted per-polygon";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("cuda"), std::string::npos) << e.what();
            EXPECT_EQ(e.where(), "method");
        }
        // A tracer made without the method does not bake with it either.
        auto tracer = make_visibility_tracer(b);
        EXPECT_THROW(bake_shading(m, parse_rule("lebedev:50"), *tracer, o, out), Error);
    }
}

TEST(CudaBake, WithoutADeviceTheBackendIsAClearError) {
    if (cuda_device_count() > 0)
        GTEST_SKIP() << "a CUDA device is present";
    try {
        make_visibility_tracer("cuda");
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("on the CPU"), std::string::npos) << what; // says what to use instead
        EXPECT_EQ(e.where(), "device");
        EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
}
