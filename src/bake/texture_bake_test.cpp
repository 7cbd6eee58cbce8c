// Texture bakes: conservative coverage, overlap detection, gutters, the
// closed form on the bowl, and agreement with the vertex bake.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>

#include "skybake/bake.h"
#include "skybake/error.h"
#include "skybake/mesh.h"
#include "skybake/sphere.h"
#include "skybake/texture_bake.h"
#include "skybake/visibility.h"

using namespace skybake;

namespace {

// Planar UVs over the xz square [-1, 1]^2 (unique for a height field seen from above).
void planar_uvs(Mesh& m) {
    m.texcoords.assign(1, {});
    for (const auto& p : m.positions)
        m.texcoords[0].emplace_back(std::clamp((p.x + 1.0f) * 0.5f, 0.0f, 1.0f),
                                    std::clamp((p.z + 1.0f) * 0.5f, 0.0f, 1.0f));
}

Mesh one_triangle(glm::vec2 a, glm::vec2 b, glm::vec2 c) {
    Mesh m;
    m.positions = {{a.x, 0, a.y}, {b.x, 0, b.y}, {c.x, 0, c.y}};
    m.indices = {0, 1, 2};
    compute_normals(m);
    m.texcoords = {{a, b, c}};
    return m;
}

int texel_count(const TexelSamples& s) {
    return int(s.texels.size());
}

} // namespace

TEST(TextureBake, CoverageIsConservative) {
    // Every point of the triangle's UV footprint falls in a covered texel; a
    // texel far from it is not covered.
    const glm::vec2 a(0.113f, 0.207f), b(0.731f, 0.388f), c(0.302f, 0.904f);
    const Mesh m = one_triangle(a, b, c);
    TextureBakeOptions o;
    o.texture_size = 64;
    const TexelSamples s = texel_samples(m, o);
    std::vector<bool> covered(64 * 64, false);
    for (std::uint32_t k : s.texels)
        covered[k] = true;
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int i = 0; i < 20000; ++i) {
        float l0 = u(rng), l1 = u(rng);
        if (l0 + l1 > 1.0f)
            l0 = 1.0f - l0, l1 = 1.0f - l1;
        const glm::vec2 p = l0 * a + l1 * b + (1.0f - l0 - l1) * c;
        const int x = std::min(63, int(p.x * 64)), y = std::min(63, int(p.y * 64));
        ASSERT_TRUE(covered[std::size_t(y) * 64 + std::size_t(x)]) << p.x << " " << p.y;
    }
    EXPECT_FALSE(covered[63 * 64 + 63]);
    // Conservative, not bloated: at most the area plus a one-texel band along the perimeter.
    const double area = 0.5 * std::abs((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x)) * 64 * 64;
    const double perimeter = (glm::length(b - a) + glm::length(c - b) + glm::length(a - c)) * 64;
    EXPECT_GT(texel_count(s), area);
    EXPECT_LT(texel_count(s), area + 2.0 * perimeter + 4);
    EXPECT_EQ(s.overlapping_texels, 0u);
    // Every sample point lies on the triangle (y = 0, inside its xz footprint).
    for (const auto& p : s.points.positions)
        ASSERT_NEAR(p.y, 0.0f, 1e-6f);
}

TEST(TextureBake, OverlappingUvsAreReported) {
    Mesh m = generate_mesh({ProceduralKind::Terrain, 2000, 1});
    planar_uvs(m);
    TextureBakeOptions o;
    o.texture_size = 128;
    EXPECT_EQ(texel_samples(m, o).overlapping_texels, 0u) << "a unique layout";
    // Stack the left half of the layout onto the right half.
    for (auto& uv : m.texcoords[0])
        uv.x = uv.x < 0.5f ? uv.x + 0.5f : uv.x;
    const TexelSamples s = texel_samples(m, o);
    EXPECT_GT(s.overlapping_texels, 1000u);
    EXPECT_GT(s.overlapping_triangles, 100u);
}

TEST(TextureBake, BadInputsNameTheirField) {
    Mesh m = one_triangle({0.1f, 0.1f}, {0.9f, 0.1f}, {0.1f, 0.9f});
    TextureBakeOptions o;
    o.texture_size = 8;
    try {
        texel_samples(m, o);
        FAIL();
    } catch (const Error& e) {
        EXPECT_EQ(e.where(), "texture_size");
    }
    o.texture_size = 64;
    o.uv_set = 1;
    try {
        texel_samples(m, o);
        FAIL();
    } catch (const Error& e) {
        EXPECT_EQ(e.where(), "uv_set");
    }
    o.uv_set = 0;
    m.texcoords[0][1].x = 1.25f;
    try {
        texel_samples(m, o);
        FAIL();
    } catch (const Error& e) {
        EXPECT_EQ(e.where(), "uv_set");
        EXPECT_NE(e.message().find("outside [0, 1]"), std::string::npos) << e.message();
    }
    m.texcoords.clear();
    EXPECT_THROW(texel_samples(m, o), Error);
}

TEST(TextureBake, DilationGrowsRingsWithTheirNeighboursMean) {
    const int n = 16;
    std::vector<float> v(n * n, 1.0f);
    std::vector<std::uint8_t> c(n * n, 0);
    v[8 * n + 8] = 0.25f;
    c[8 * n + 8] = 1;
    dilate_texture(v, c, n, 2);
    int grown = 0;
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const bool inside = std::abs(x - 8) <= 2 && std::abs(y - 8) <= 2;
            EXPECT_EQ(c[std::size_t(y * n + x)] != 0, inside) << x << " " << y;
            if (inside) {
                EXPECT_FLOAT_EQ(v[std::size_t(y * n + x)], 0.25f);
            }
            grown += c[std::size_t(y * n + x)] == 2;
        }
    EXPECT_EQ(grown, 24);
}

TEST(TextureBake, BowlIsOneHalfAtEveryTexel) {
    // Closed form (ambient_occlusion_test.cpp): AO = 1/2 at every inner point
    // of a hemispherical bowl. UVs: the bowl seen from above.
    Mesh m = generate_mesh({ProceduralKind::Bowl, 3000, 1});
    planar_uvs(m);
    const SphereRule rule = parse_rule("lebedev:590");
    const auto tracer = make_visibility_tracer("embree");
    TextureBakeOptions o;
    o.texture_size = 128;
    const AoTexture t = bake_ao_texture(m, rule, *tracer, {}, o);
    double sum = 0.0, worst = 0.0;
    std::size_t n = 0;
    for (std::size_t k = 0; k < t.ao.size(); ++k)
        if (t.coverage[k] == 1) {
            const double e = std::abs(t.ao[k] - 0.5);
            sum += e * e;
            worst = std::max(worst, e);
            ++n;
        }
    const double rms = std::sqrt(sum / double(n));
    std::printf("bowl texture %d^2: %zu texels, AO - 1/2 rms %.2e max %.2e\n", o.texture_size, n, rms, worst);
    EXPECT_GT(n, std::size_t(0.7 * 3.14159 / 4 * 128 * 128)); // the disk of the rim, seen from above
    // The vertex bake's bounds on the same bowl and rule (rule error dominates).
    EXPECT_LT(rms, 1e-2);
    EXPECT_LT(worst, 6e-2);
}

TEST(TextureBake, MatchesTheVertexBakeAtTheVertices) {
    // A finely tessellated terrain with a unique (planar) layout: the texture
    // read at each vertex's UV agrees with the vertex bake there.
    Mesh m = generate_mesh({ProceduralKind::Terrain, 20000, 3});
    planar_uvs(m);
    const SphereRule rule = parse_rule("lebedev:302");
    const auto tracer = make_visibility_tracer("embree");
    TextureBakeOptions o;
    o.texture_size = 512;
    const AoTexture t = bake_ao_texture(m, rule, *tracer, {}, o);
    bake_ambient_occlusion(m, rule, *tracer);
    const std::vector<float>& ao = m.find_attribute("ao")->values;
    double sum = 0.0, worst = 0.0;
    for (std::size_t v = 0; v < m.vertex_count(); ++v) {
        const double d = std::abs(double(sample_texture(t, m.texcoords[0][v])) - ao[v]);
        sum += d;
        worst = std::max(worst, d);
    }
    const double mean = sum / double(m.vertex_count());
    std::printf("terrain: %zu vertices, %zu texels; |texture - vertex| mean %.2e max %.2e\n", m.vertex_count(),
                t.covered_texels, mean, worst);
    EXPECT_LE(mean, 0.01);
    EXPECT_EQ(t.overlapping_texels, 0u);
}
