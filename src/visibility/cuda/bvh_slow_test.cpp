// The CUDA bake's thread bodies on the host against the Embree bake, on
// larger inputs: two real models and the seed's table case (5k vertices,
// lebedev:5810).
#include <gtest/gtest.h>

#include "skybake/mesh.h"
#include "skybake/sphere.h"
#include "visibility/cuda/bake_plan.h"
#include "visibility/cuda/test_scenes.h"

using namespace skybake;
using namespace skybake::visibility;
using namespace skybake::visibility_test;

namespace {

void check(const std::string& label, const Mesh& m, const char* spec, bool tie_free_scene) {
    SCOPED_TRACE(label);
    const SphereRule rule = parse_rule(spec);
    BakeOptions o;
    o.store_bits = true;
    BakeOutputs e;
    EmbreeBackend embree;
    embree.bake(m, rule, o, e);
    const BakeOutputs g = emulated(m, rule, o, TraceMethod::Bvh);
    const Agreement a = compare_bakes(m, rule, o, g, e);
    a.print((label + " " + spec + ", host emulation").c_str());
    expect_agreement(a, tie_free_scene || rule.rotate_per_vertex);
}

} // namespace

TEST(CudaBakeSlow, RealModelsMatchEmbree) {
    const std::string models = SKYBAKE_ASSIMP_MODELS;
    check("2CylinderEngine", load_mesh(models + "/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb"),
          "lebedev:110+rotate", true);
    check("Wuson", load_mesh(models + "/OBJ/WusonOBJ.obj"), "lebedev:590", true);
}

TEST(CudaBakeSlow, SeedTableCaseMatchesEmbree) {
    check("city", ao_test::generated(ProceduralKind::City, 3000), "lebedev:5810", false);
}
