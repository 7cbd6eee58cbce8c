// The distributed tracer in one process (no job): its chunks, the words it
// gathers and the driver's replay of them give the single-process bake bit
// for bit. The runs under mpirun are tests/mpi/mpi_cli_test.py.
#include <gtest/gtest.h>

#include "skybake/bake.h"
#include "skybake/distributed.h"
#include "skybake/mesh.h"
#include "skybake/sphere.h"
#include "skybake/texture_bake.h"

namespace skybake {
namespace {

Mesh city() {
    ProceduralOptions p;
    p.kind = ProceduralKind::City;
    p.target_triangles = 800;
    Mesh m = generate_mesh(p);
    compute_normals(m);
    return m;
}

TEST(DistributedTracer, GivesTheSingleProcessBakeBitForBit) {
    if (!build_has_mpi())
        GTEST_SKIP() << "built without MPI";
    for (const char* rule_spec : {"lebedev:50", "fibonacci:100+rotate"}) {
        const SphereRule rule = parse_rule(rule_spec);
        for (const char* backend : {"brute", "embree"}) {
            Mesh a = city(), b = city();
            BakeOptions o;
            o.store_bits = true;
            BakeOutputs plain, spread;
            auto local = make_visibility_tracer(backend);
            bake_ambient_occlusion(a, rule, *local, o, &plain);
            auto distributed = make_distributed_tracer(make_visibility_tracer(backend));
            const AoBakeReport r = bake_ambient_occlusion(b, rule, *distributed, o, &spread);
            EXPECT_EQ(r.backend, backend);
            EXPECT_EQ(spread.visibility_bits, plain.visibility_bits) << rule_spec << " " << backend;
            EXPECT_EQ(spread.ao, plain.ao);
            EXPECT_EQ(spread.shading, plain.shading);
            EXPECT_EQ(spread.rays, plain.rays);
            const DistributedStats s = last_distributed_stats();
            EXPECT_EQ(s.points, a.vertex_count());
            EXPECT_GT(s.chunks, 1u); // several chunks even in one process
            EXPECT_EQ(s.bytes_gathered, 0u); // nothing came from another rank
        }
    }
}

} // namespace
} // namespace skybake
