// stitch_texture_seams(): two quads that share an edge in space, laid out as
// separate UV islands (the edge at other places, and reversed, on the two
// sides). The stitched texture is read with sample_texture(), the viewer's
// look-up, at points of the seam other than the ones the stitcher used.
#include <random>

#include <gtest/gtest.h>

#include "skybake/error.h"
#include "skybake/texture_bake.h"

namespace skybake {
namespace {

constexpr int kSize = 64;

// Quad A: x in [0, 1]; quad B: x in [1, 2], folded up by 90° about the shared
// edge x = 1. The shared edge's vertices appear once per quad, with other UVs.
Mesh two_islands(bool same_uvs_on_the_seam = false) {
    Mesh m;
    m.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, // A
                   {1, 0, 0}, {1, 0, 1}, {1, 1, 1}, {1, 1, 0}}; // B
    m.indices = {0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7};
    std::vector<glm::vec2> uv = {{0.10f, 0.10f}, {0.40f, 0.10f}, {0.40f, 0.45f}, {0.10f, 0.45f},
                                 // B's copy of the edge runs the other way, elsewhere in the texture
                                 {0.85f, 0.90f}, {0.55f, 0.90f}, {0.55f, 0.55f}, {0.85f, 0.55f}};
    if (same_uvs_on_the_seam) { // B's edge vertices at A's UVs: split for normals only
        uv[4] = uv[1];
        uv[7] = uv[2];
    }
    m.texcoords = {uv};
    return m;
}

AoTexture as_texture(const std::vector<float>& values) {
    AoTexture t;
    t.texture_size = kSize;
    t.ao = values;
    return t;
}

// The largest |A − B| over n points of the shared edge, read on both sides.
double seam_mismatch(const Mesh& m, const std::vector<float>& values, int n) {
    const AoTexture t = as_texture(values);
    const auto& uv = m.texcoords[0];
    double worst = 0.0;
    for (int i = 0; i < n; ++i) {
        const float f = (float(i) + 0.37f) / float(n); // off the stitcher's own points
        const glm::vec2 a = glm::mix(uv[1], uv[2], f), b = glm::mix(uv[4], uv[7], f);
        worst = std::max(worst, double(std::abs(sample_texture(t, a) - sample_texture(t, b))));
    }
    return worst;
}

std::vector<float> noise(unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<float> v(std::size_t(kSize) * kSize);
    for (float& x : v)
        x = u(rng);
    return v;
}

TEST(TextureSeams, BothSidesReadAlikeAfterStitching) {
    const Mesh m = two_islands();
    std::vector<float> values = noise(7);
    const std::vector<float> before = values;
    const double mismatch_before = seam_mismatch(m, values, 101);
    ASSERT_GT(mismatch_before, 0.2); // random texels disagree
    const SeamStitchReport r = stitch_texture_seams(m, 0, values, kSize);
    EXPECT_EQ(r.seam_edges, 1u); // the shared edge; the quads' diagonals and borders are not shared
    EXPECT_GT(r.lookups, 2u * 19u);
    EXPECT_NEAR(r.mismatch_before_max, mismatch_before, 0.1);
    EXPECT_LT(r.mismatch_after_max, 1e-3);
    // Read by the viewer's look-up, between the stitcher's points too.
    EXPECT_LT(seam_mismatch(m, values, 101), 0.02 * mismatch_before);
    // Only the texels under the seam's look-ups changed, and all stay in [0, 1].
    std::size_t changed = 0;
    for (std::size_t k = 0; k < values.size(); ++k) {
        changed += values[k] != before[k];
        EXPECT_GE(values[k], 0.0f);
        EXPECT_LE(values[k], 1.0f);
    }
    EXPECT_GT(changed, 0u);
    EXPECT_LE(changed, r.texels_changed);
    EXPECT_LT(r.texels_changed, 4u * 2u * 24u); // two thin bands along a 22-texel edge
}

TEST(TextureSeams, AConstantTextureAndASeamlessLayoutStayAsTheyAre) {
    std::vector<float> flat(std::size_t(kSize) * kSize, 0.625f);
    stitch_texture_seams(two_islands(), 0, flat, kSize);
    for (float v : flat)
        ASSERT_NEAR(v, 0.625f, 1e-6f);
    std::vector<float> values = noise(3);
    const std::vector<float> before = values;
    const SeamStitchReport r = stitch_texture_seams(two_islands(true), 0, values, kSize);
    EXPECT_EQ(r.seam_edges, 0u);
    EXPECT_EQ(values, before);
}

TEST(TextureSeams, BadArguments) {
    std::vector<float> values(10);
    try {
        stitch_texture_seams(two_islands(), 0, values, kSize);
        ADD_FAILURE();
    } catch (const Error& e) {
        EXPECT_EQ(e.where(), "values");
    }
    values.resize(std::size_t(kSize) * kSize);
    try {
        stitch_texture_seams(two_islands(), 1, values, kSize);
        ADD_FAILURE();
    } catch (const Error& e) {
        EXPECT_EQ(e.where(), "uv_set");
    }
}

} // namespace
} // namespace skybake
