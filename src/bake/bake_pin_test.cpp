// Pins the bake's results: a 64-bit FNV-1a digest of every output (AO, A,
// bent normals, visibility bits, ray and clamped counts) for each backend,
// scene, rule and option set, against the digests the bake gave when they were
// recorded. A change to the bake's structure must leave every digest as it is;
// a change to its answers must update this table on purpose, and say by how
// much the answers moved (docs/baking.md).
//
// Regenerate after an intended change: SKYBAKE_PRINT_DIGESTS=1 ./bake_tests
// --gtest_filter='BakePin.*' prints the table in this file's format.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <string>

#include <gtest/gtest.h>

#include "bake/ao_test_util.h"
#include "bake/cuda_bake_test_util.h"
#include "skybake/bake.h"
#include "skybake/mesh.h"
#include "skybake/sphere.h"
#include "visibility/cuda/bvh.h"

using namespace skybake;

namespace {

struct Digest {
    std::uint64_t h = 1469598103934665603ull;
    void add(const void* data, std::size_t bytes) {
        const auto* p = static_cast<const unsigned char*>(data);
        for (std::size_t i = 0; i < bytes; ++i) {
            h ^= p[i];
            h *= 1099511628211ull;
        }
    }
    template <class T>
    void add_vector(const std::vector<T>& v) {
        add(v.data(), v.size() * sizeof(T));
    }
};

std::uint64_t digest(const BakeOutputs& o) {
    Digest d;
    d.add_vector(o.ao);
    d.add_vector(o.shading);
    d.add_vector(o.bent_normal);
    d.add_vector(o.visibility_bits);
    d.add(&o.rays, sizeof(o.rays));
    d.add(&o.clamped_vertices, sizeof(o.clamped_vertices));
    d.add(&o.ray_offset, sizeof(o.ray_offset));
    return d.h;
}

struct Case {
    const char* scene;
    const char* rule;
    int options; // index into option_set()
};

BakeOptions option_set(int i) {
    BakeOptions o;
    o.store_bits = true;
    if (i == 1) {
        o.normalize = true;
        o.back_faces = BackFaces::Ignore;
        o.max_distance = 0.4f;
    }
    return o;
}

// name → digest, recorded with the bake as it was when the table was written.
const std::map<std::string, std::uint64_t>& golden() {
    static const std::map<std::string, std::uint64_t> table = {
#include "bake/bake_pin_digests.inc"
    };
    return table;
}

void check(const std::string& key, const BakeOutputs& out) {
    const std::uint64_t got = digest(out);
    if (std::getenv("SKYBAKE_PRINT_DIGESTS"))
        std::printf("        {\"%s\", 0x%016llxull},\n", key.c_str(), static_cast<unsigned long long>(got));
    const auto it = golden().find(key);
    ASSERT_NE(it, golden().end()) << "no recorded digest for " << key;
    EXPECT_EQ(got, it->second) << key << ": the bake's outputs changed";
}

} // namespace

TEST(BakePin, EveryBackendGivesTheRecordedOutputs) {
    const std::vector<std::pair<std::string, Mesh>> scenes = {
        {"soup", visibility_test::random_soup(3, 400)},
        {"city", ao_test::generated(ProceduralKind::City, 3000)},
        {"spider", visibility_test::spider()},
    };
    for (const auto& [name, mesh] : scenes)
        for (const char* spec : {"lebedev:590", "lebedev:302+rotate", "fibonacci:40"})
            for (int opt = 0; opt < 2; ++opt) {
                const SphereRule rule = parse_rule(spec);
                const BakeOptions o = option_set(opt);
                const std::string base = name + "/" + spec + "/" + std::to_string(opt);
                Mesh m = mesh;
                BakeOutputs out;
                bake_ambient_occlusion(m, rule, "embree", o, &out);
                check(base + "/embree", out);
                if (name == "soup") {
                    Mesh b = mesh;
                    bake_ambient_occlusion(b, rule, "brute", o, &out);
                    check(base + "/brute", out);
                    check(base + "/cuda-per-vertex",
                          visibility_test::emulated(mesh, rule, o, TraceMethod::PerVertex, 1000));
                }
                check(base + "/cuda-bvh", visibility_test::emulated(mesh, rule, o, TraceMethod::Bvh, 1000));
            }
}
