// One bake job (skybake/bake_job.h): the same results as the bakes it runs,
// one acceleration structure per mesh, and its checks before any ray.
#include <algorithm>

#include <gtest/gtest.h>

#include "skybake/bake_job.h"
#include "skybake/error.h"

namespace skybake {
namespace {

// A city with planar UVs over its footprint (overlaps on walls: fine here).
Mesh city() {
    ProceduralOptions o;
    o.kind = ProceduralKind::City;
    o.target_triangles = 3000;
    Mesh m = generate_mesh(o);
    compute_normals(m);
    glm::vec3 lo(1e30f), hi(-1e30f);
    for (const auto& p : m.positions) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    m.texcoords.assign(1, {});
    for (const auto& p : m.positions)
        m.texcoords[0].emplace_back((p.x - lo.x) / (hi.x - lo.x), (p.z - lo.z) / (hi.z - lo.z));
    return m;
}

std::string field(const BakeJob& job) {
    try {
        check_bake_job(job);
    } catch (const Error& e) {
        return e.where();
    }
    return "(accepted)";
}

TEST(BakeJob, EverythingOverOneAccelerationStructure) {
    Mesh mesh = city();
    BakeJob job;
    job.rule = parse_rule("lebedev:50");
    job.tracer.device = "cpu";
    job.bits = true;
    job.texture.emplace();
    job.texture->texture_size = 64;
    job.preview.emplace();
    job.preview->width = 64;
    job.preview->height = 48;
    const BakeJobResult r = run_bake_job(mesh, job);
    EXPECT_EQ(r.acceleration_structures, 1) << "vertices, texels and the preview share Embree's scene";
    EXPECT_EQ(r.choice.backend->name, "embree");
    ASSERT_TRUE(r.texture.has_value());
    EXPECT_GT(r.texture->covered_texels, 0u);
    EXPECT_EQ(r.preview.width, 64);

    // The same as each bake on its own, with its own tracer.
    Mesh alone = city();
    BakeOptions o;
    o.store_bits = true;
    BakeOutputs out;
    const auto tracer = make_visibility_tracer("embree");
    bake_ambient_occlusion(alone, job.rule, *tracer, o, &out);
    EXPECT_EQ(r.outputs.visibility_bits, out.visibility_bits);
    EXPECT_EQ(r.outputs.ao, out.ao);
    const AoTexture t = bake_ao_texture(alone, job.rule, *tracer, BakeOptions{}, *job.texture);
    EXPECT_EQ(r.texture->ao, t.ao);
    AoPreviewOptions p = *job.preview;
    const Image own = render_texture_preview(alone, t, 0, {}, p);
    EXPECT_EQ(r.preview.rgb, own.rgb) << "the preview through the bake's scene is the preview through its own";
}

TEST(BakeJob, BouncesReuseTheTracersStructure) {
    Mesh mesh = city();
    BakeJob job;
    job.rule = parse_rule("lebedev:50");
    job.tracer.device = "cpu";
    job.shading = false;
    job.transfer.emplace();
    job.transfer->order = 2;
    job.transfer->kind = TransferKind::Interreflected;
    job.transfer->bounces = 1;
    const BakeJobResult r = run_bake_job(mesh, job);
    EXPECT_EQ(r.acceleration_structures, 1);
    EXPECT_GT(r.transfer_report.bounce_rays, 0u);

    Mesh alone = city();
    const auto tracer = make_visibility_tracer("embree");
    const auto queries = make_ray_queries("embree");
    Transfer t;
    bake_transfer(alone, job.rule, *tracer, BakeOptions{}, *job.transfer, mesh_albedo(alone), queries.get(), t);
    EXPECT_EQ(r.transfer.coeffs, t.coeffs);
}

TEST(BakeJob, ChecksComeBeforeAnyRay) {
    BakeJob job;
    job.rule = parse_rule("lebedev:50");
    EXPECT_EQ(field(job), "(accepted)");
    job.rule = parse_rule("phong:a=4,n=3");
    EXPECT_EQ(field(job), "rule");
    job.rule = parse_rule("lebedev:50");
    job.tracer.backend = "raster";
    job.tracer.method = "directional";
    job.options.max_distance = 1.0f;
    EXPECT_EQ(field(job), "max_distance");
    job.options.max_distance = std::numeric_limits<float>::infinity();
    job.rule = parse_rule("lebedev:50+rotate");
    EXPECT_EQ(field(job), "rule");
    job = BakeJob{};
    job.rule = parse_rule("lebedev:50");
    job.tracer.backend = "raster";
    job.transfer.emplace();
    job.transfer->kind = TransferKind::Interreflected;
    job.transfer->bounces = 1;
    EXPECT_EQ(field(job), "backend") << "bounces need closest hits";
    job = BakeJob{};
    job.rule = parse_rule("lebedev:50");
    job.shading = false;
    EXPECT_EQ(field(job), "shading");
    job.transfer.emplace();
    job.preview.emplace();
    EXPECT_EQ(field(job), "preview");
}

} // namespace
} // namespace skybake
