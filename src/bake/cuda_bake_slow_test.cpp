// The CUDA bake's thread bodies on the host against the Embree bake, on
// larger inputs: two real models and the seed's table case (5k vertices,
// lebedev:5810), and every setting the GPU tests use, so that a run on a GPU
// only has to confirm the same numbers.
#include <gtest/gtest.h>

#include <tuple>
#include <utility>

#include "skybake/mesh.h"
#include "skybake/sphere.h"
#include "bake/cuda_bake_test_util.h"
#include "skybake/bake.h"
#include "core/test_paths.h"

using namespace skybake;
using namespace skybake::visibility;
using namespace skybake::visibility_test;

namespace {

// The host emulation against Embree on one mesh and rule, with the bounds of
// expect_agreement(); returns the agreement for further checks.
Agreement check(const std::string& label, const Mesh& m, const char* spec, bool tie_free_scene,
                BackFaces back = BackFaces::Occlude) {
    SCOPED_TRACE(label);
    const SphereRule rule = parse_rule(spec);
    BakeOptions o;
    o.store_bits = true;
    o.back_faces = back;
    const Agreement a = compare_bakes(m, rule, o, emulated(m, rule, o, TraceMethod::Bvh), embree_bake(m, rule, o));
    a.print((label + " " + spec + " " + back_faces_name(back) + ", host emulation").c_str());
    expect_agreement(a, tie_free_scene || rule.rotate_per_vertex);
    return a;
}

} // namespace

TEST(CudaBakeSlow, RealModelsMatchEmbree) {
    const std::string models = skybake::test::assimp_models();
    check("2CylinderEngine", load_mesh(models + "/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb"),
          "lebedev:110+rotate", true);
    check("Wuson", load_mesh(models + "/OBJ/WusonOBJ.obj"), "lebedev:590", true);
}

TEST(CudaBakeSlow, SeedTableCaseMatchesEmbree) {
    check("city", generated(ProceduralKind::City, 3000), "lebedev:5810", false);
}

TEST(CudaBakeSlow, TheGpuTestsSettingsPassOnTheHost) {
    // cuda_bake_gpu_test.cpp, EveryMethodMatchesEmbreeAndTheHostEmulation:
    // the same scenes, rules and back-face modes, with the same bounds.
    for (const auto& [name, m] : scenes())
        for (const char* spec : gpu_test_rules())
            for (BackFaces back : gpu_test_back_faces())
                check(name, m, spec, tie_free(name, parse_rule(spec)), back);
}

TEST(CudaBakeSlow, TheGpuTestsRealModelsPassOnTheHost) {
    // cuda_bake_gpu_test.cpp, RealModelsMatchEmbree: strict bounds on both.
    const std::string models = skybake::test::assimp_models();
    for (const auto& [label, path, spec] :
         {std::tuple<const char*, const char*, const char*>{"engine", "/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb",
                                                            "lebedev:110+rotate"},
          {"wuson", "/OBJ/WusonOBJ.obj", "lebedev:5810"}})
        check(label, load_mesh(models + path), spec, true);
}

TEST(CudaBakeSlow, TheGpuCliTestsMeshesPassOnTheHost) {
    // tests/ao_gpu_test.cpp: a 5,000-triangle city and spider.obj at
    // lebedev:1202 (no rotation), at most 1e-4 of the bits differing and mean
    // AO within 1e-4.
    const Mesh city = generated(ProceduralKind::City, 5000), spider_mesh = spider();
    for (const auto& [label, m] : {std::pair<const char*, const Mesh&>{"city", city}, {"spider", spider_mesh}}) {
        const Agreement a = check(label, m, "lebedev:1202", true);
        EXPECT_LE(double(a.diff), 1e-4 * double(a.rays)) << label;
        EXPECT_LE(a.mean_ao, 1e-4) << label;
    }
}
