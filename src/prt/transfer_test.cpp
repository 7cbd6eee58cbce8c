// Transfer bake: closed forms and identities (skybake/prt.h).
//  - convex sphere: shadowed transfer = unshadowed, bit for bit;
//  - constant light: shadowed B = albedo · AO from the same bits;
//  - unshadowed transfer of an SH light = Ramamoorthi & Hanrahan's irradiance
//    convolution, (Â_l / π) L_lm Y_lm(n);
//  - bounces: each bounce adds at most albedo_max times the previous one.
#include <algorithm>
#include <cmath>
#include <random>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "skybake/error.h"
#include "skybake/image.h"
#include "skybake/prt.h"

namespace skybake {
namespace {

Mesh sphere_mesh(std::uint64_t triangles = 2000) {
    ProceduralOptions o;
    o.kind = ProceduralKind::Sphere;
    o.target_triangles = triangles;
    Mesh m = generate_mesh(o);
    compute_normals(m);
    return m;
}

Mesh city_mesh(std::uint64_t triangles = 3000) {
    ProceduralOptions o;
    o.kind = ProceduralKind::City;
    o.target_triangles = triangles;
    Mesh m = generate_mesh(o);
    compute_normals(m);
    return m;
}

Transfer bake(Mesh& mesh, const std::string& rule_spec, TransferKind kind, int order,
              TransferModel model = TransferModel::Prt) {
    const SphereRule rule = parse_rule(rule_spec);
    const auto tracer = make_visibility_tracer("embree");
    TransferOptions o;
    o.order = order;
    o.kind = kind;
    o.model = model;
    Transfer t;
    bake_transfer(mesh, rule, *tracer, BakeOptions{}, o, {}, nullptr, t);
    return t;
}

ShLight random_light(int order, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    ShLight l;
    l.order = order;
    for (int i = 0; i < sh_count(order); ++i)
        l.coeffs.emplace_back(u(rng), u(rng), u(rng));
    return l;
}

TEST(Transfer, ConvexSphereShadowedEqualsUnshadowed) {
    Mesh mesh = sphere_mesh();
    const Transfer s = bake(mesh, "lebedev:590", TransferKind::Shadowed, 3);
    const Transfer u = bake(mesh, "lebedev:590", TransferKind::Unshadowed, 3);
    ASSERT_EQ(s.coeffs.size(), mesh.vertex_count() * 16);
    ASSERT_EQ(s.coeffs.size(), u.coeffs.size());
    for (std::size_t i = 0; i < s.coeffs.size(); ++i)
        ASSERT_EQ(s.coeffs[i], u.coeffs[i]) << i;
    // Constant light L: B = albedo · L · Σ w 4 (n·x)+, 1 up to the rule's
    // error for the clamped cosine.
    const glm::vec3 albedo(0.25f, 0.5f, 0.75f), L(2.0f, 3.0f, 4.0f);
    const std::vector<glm::vec3> rho(mesh.vertex_count(), albedo);
    const std::vector<glm::vec3> b = relight(s, constant_light(L, 3), rho);
    double worst = 0.0;
    for (const glm::vec3& x : b)
        for (int c = 0; c < 3; ++c)
            worst = std::max(worst, std::abs(double(x[c]) / double(albedo[c] * L[c]) - 1.0));
    std::printf("convex sphere, lebedev:590: max |B / (albedo L) - 1| = %.3g\n", worst);
    EXPECT_LT(worst, 2e-3);
}

TEST(Transfer, ConstantLightIsAlbedoTimesAoFromTheSameBits) {
    for (const char* spec : {"lebedev:590", "design:t13+rotate=3"}) {
        Mesh mesh = city_mesh();
        const Transfer t = bake(mesh, spec, TransferKind::Shadowed, 2);
        Mesh ao_mesh = mesh;
        BakeOutputs out;
        bake_ambient_occlusion(ao_mesh, parse_rule(spec), "embree", BakeOptions{}, &out);
        const std::vector<glm::vec3> rho(mesh.vertex_count(), glm::vec3(0.5f));
        const std::vector<glm::vec3> b = relight(t, constant_light(glm::vec3(1.0f), 2), rho);
        // AO is clamped to [0, 1] (a rule's sum can exceed 1 for an open
        // vertex); the transfer is not.
        double worst = 0.0;
        std::size_t occluded = 0;
        for (std::size_t v = 0; v < b.size(); ++v) {
            worst = std::max(worst, std::abs(std::min(double(b[v].x), 0.5) - 0.5 * double(out.ao[v])));
            occluded += out.ao[v] < 0.9f;
        }
        std::printf("%s: max |B - albedo AO| = %.3g over %zu vertices (%zu with AO < 0.9)\n", spec, worst, b.size(),
                    occluded);
        EXPECT_GT(occluded, b.size() / 20) << "the scene should shadow itself";
        EXPECT_LT(worst, 4e-6) << spec; // float sums in two orders
    }
}

// Ramamoorthi & Hanrahan 2001: irradiance E(n) = Σ Â_l L_lm Y_lm(n), and the
// Lambertian radiance is ρ E / π.
void check_unshadowed(int order, const char* spec, double tolerance) {
    Mesh mesh = sphere_mesh(500);
    const Transfer t = bake(mesh, spec, TransferKind::Unshadowed, order);
    for (std::uint64_t seed = 1; seed <= 3; ++seed) {
        const ShLight light = random_light(order, seed);
        const std::vector<glm::vec3> rho(mesh.vertex_count(), glm::vec3(1.0f));
        const std::vector<glm::vec3> b = relight(t, light, rho);
        double norm = 0.0;
        for (const glm::vec3& c : light.coeffs)
            norm += double(glm::dot(c, c));
        norm = std::sqrt(norm);
        double worst = 0.0;
        std::vector<double> y(std::size_t(sh_count(order)));
        for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
            const glm::dvec3 n = glm::normalize(glm::dvec3(mesh.normals[v]));
            sh_eval(order, n, y.data());
            glm::dvec3 e(0.0);
            for (int l = 0; l <= order; ++l)
                for (int m = -l; m <= l; ++m)
                    e += clamped_cosine_zonal(l) / M_PI * y[std::size_t(sh_index(l, m))] *
                         glm::dvec3(light.coeffs[std::size_t(sh_index(l, m))]);
            worst = std::max(worst, glm::length(glm::dvec3(b[v]) - e) / norm);
        }
        std::printf("order %d, %s, light %llu: max |B - R&H| / |L| = %.3g\n", order, spec, (unsigned long long)seed,
                    worst);
        EXPECT_LT(worst, tolerance);
    }
}

TEST(Transfer, UnshadowedIsTheIrradianceConvolution) {
    check_unshadowed(3, "lebedev:5810", 2e-4);
    check_unshadowed(8, "lebedev:5810", 5e-4);
}

TEST(Transfer, ShadingCoefficientModelOnAConvexSphereIsTheUnshadowedIrradiance) {
    Mesh mesh = sphere_mesh(500);
    const Transfer a = bake(mesh, "lebedev:5810", TransferKind::Shadowed, 4, TransferModel::ShadingCoefficient);
    const Transfer u = bake(mesh, "lebedev:5810", TransferKind::Unshadowed, 4);
    // A = 1 on a convex mesh up to the rule's error for the step; the
    // analytic and the quadrature transfer agree to the rule's error too.
    double worst = 0.0;
    for (std::size_t i = 0; i < a.coeffs.size(); ++i)
        worst = std::max(worst, double(std::abs(a.coeffs[i] - u.coeffs[i])));
    std::printf("shading-coefficient vs unshadowed on a sphere: max |ΔT| = %.3g\n", worst);
    EXPECT_LT(worst, 2e-3);
}

TEST(Transfer, BouncesAddLessEachTime) {
    Mesh mesh = city_mesh(2000);
    const SphereRule rule = parse_rule("lebedev:302");
    const auto tracer = make_visibility_tracer("embree");
    const auto queries = make_ray_queries("embree");
    const float albedo_max = 0.8f;
    std::vector<glm::vec3> rho(mesh.vertex_count());
    for (std::size_t v = 0; v < rho.size(); ++v)
        rho[v] = glm::vec3(albedo_max, 0.5f, 0.2f) * (0.5f + 0.5f * float(v % 2));
    std::vector<std::vector<glm::vec3>> b;
    for (int n = 0; n <= 3; ++n) {
        TransferOptions o;
        o.order = 2;
        o.kind = n == 0 ? TransferKind::Shadowed : TransferKind::Interreflected;
        o.bounces = n;
        Transfer t;
        bake_transfer(mesh, rule, *tracer, BakeOptions{}, o, rho, queries.get(), t);
        EXPECT_EQ(t.channels, n == 0 ? 1 : 3);
        b.push_back(relight(t, constant_light(glm::vec3(1.0f), 2), rho));
    }
    // Constant light: each bounce's increment Δ_n ≥ 0, and the gather has
    // row sums ≤ 1, so max Δ_n ≤ albedo_max · max Δ_{n−1}.
    double previous = 0.0;
    for (int n = 1; n <= 3; ++n) {
        double largest = 0.0;
        for (std::size_t v = 0; v < b[0].size(); ++v)
            for (int c = 0; c < 3; ++c) {
                const double d = double(b[std::size_t(n)][v][c]) - double(b[std::size_t(n - 1)][v][c]);
                EXPECT_GE(d, -1e-6);
                largest = std::max(largest, d);
            }
        std::printf("bounce %d: max increment %.4g\n", n, largest);
        if (n == 1) {
            EXPECT_GT(largest, 1e-3);
        } else {
            EXPECT_LE(largest, albedo_max * previous * (1.0 + 1e-5));
        }
        previous = largest;
    }
}

// Inside a sphere, the form factor from any point to a piece of the sphere
// is that piece's area over 4πR². For the hemispherical bowl every inner point
// therefore sees the open half (AO = f = 1/2) and gathers from the bowl with
// weight 1 − f, whatever its place: under constant light L and albedo ρ,
//     B_N = ρ L f Σ_{k=0..N} (ρ (1 − f))^k  →  ρ L f / (1 − ρ (1 − f)).
TEST(Transfer, BowlConvergesToTheInfiniteBounceLimit) {
    ProceduralOptions p;
    p.kind = ProceduralKind::Bowl;
    p.target_triangles = 4000;
    Mesh mesh = generate_mesh(p);
    compute_normals(mesh);
    const SphereRule rule = parse_rule("lebedev:1202");
    const auto tracer = make_visibility_tracer("embree");
    const auto queries = make_ray_queries("embree");
    const float rho = 0.6f;
    const std::vector<glm::vec3> albedo(mesh.vertex_count(), glm::vec3(rho));
    const double f = 0.5;
    for (int n : {1, 3, 8}) {
        TransferOptions o;
        o.order = 0;
        o.kind = TransferKind::Interreflected;
        o.bounces = n;
        Transfer t;
        bake_transfer(mesh, rule, *tracer, BakeOptions{}, o, albedo, queries.get(), t);
        const std::vector<glm::vec3> b = relight(t, constant_light(glm::vec3(1.0f), 0), albedo);
        double want = 0.0;
        for (int k = 0; k <= n; ++k)
            want += rho * f * std::pow(rho * (1.0 - f), k);
        double worst = 0.0, mean = 0.0;
        std::size_t count = 0;
        for (std::size_t v = 0; v < b.size(); ++v)
            if (mesh.positions[v].y < -0.3f) { // away from the rim
                worst = std::max(worst, std::abs(double(b[v].x) / want - 1.0));
                mean += double(b[v].x);
                ++count;
            }
        std::printf("bowl, %d bounces: closed form %.5f (limit %.5f), mean %.5f over %zu vertices, max relative "
                    "error %.3g\n",
                    n, want, rho * f / (1.0 - rho * (1.0 - f)), mean / double(count), count, worst);
        EXPECT_GT(count, 100u);
        // Each vertex has the rule's error for the visibility step at the
        // rim's circle (a few percent with lebedev:1202); it averages out.
        EXPECT_NEAR(mean / double(count) / want, 1.0, 1e-3) << n;
        EXPECT_LT(worst, 0.05) << n;
    }
}

// The bowl again, its albedo in a material's image (0.6) and wrong per
// vertex (0.2): the bounces read the image where they land, so the closed
// form of ρ = 0.6 holds; per vertex it would be far off.
TEST(Transfer, BouncesReadTheMaterialImageAtTheHit) {
    ProceduralOptions p;
    p.kind = ProceduralKind::Bowl;
    p.target_triangles = 4000;
    Mesh mesh = generate_mesh(p);
    compute_normals(mesh);
    mesh.materials.resize(1);
    mesh.materials[0].base_color = glm::vec4(1.0f);
    mesh.parts.assign(1, MeshPart{"bowl", 0});
    mesh.triangle_parts.assign(mesh.triangle_count(), 0);
    mesh.texcoords.assign(1, std::vector<glm::vec2>(mesh.vertex_count()));
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
        mesh.texcoords[0][v] = glm::vec2(3.1f * mesh.positions[v].x, 2.7f * mesh.positions[v].z);
    const float rho = 0.6f;
    Image image(3, 2);
    std::fill(image.rgb.begin(), image.rgb.end(), rho);
    const std::vector<Image> images{image};
    glm::vec3 at;
    ASSERT_TRUE(surface_base_color(mesh, images, 7, 0.2f, 0.3f, at));
    EXPECT_EQ(at, glm::vec3(rho));
    EXPECT_FALSE(surface_base_color(mesh, {}, 7, 0.2f, 0.3f, at)) << "no image: the vertices' albedo";

    const SphereRule rule = parse_rule("lebedev:1202");
    const auto tracer = make_visibility_tracer("embree");
    const auto queries = make_ray_queries("embree");
    const std::vector<glm::vec3> wrong(mesh.vertex_count(), glm::vec3(0.2f)), right(mesh.vertex_count(), glm::vec3(rho));
    TransferOptions o;
    o.order = 0;
    o.kind = TransferKind::Interreflected;
    o.bounces = 3;
    Transfer t;
    bake_transfer(mesh, rule, *tracer, BakeOptions{}, o, wrong, queries.get(), t, images);
    const std::vector<glm::vec3> b = relight(t, constant_light(glm::vec3(1.0f), 0), right);
    const double f = 0.5;
    double want = 0.0;
    for (int k = 0; k <= o.bounces; ++k)
        want += rho * f * std::pow(rho * (1.0 - f), k);
    double mean = 0.0;
    std::size_t count = 0;
    for (std::size_t v = 0; v < b.size(); ++v)
        if (mesh.positions[v].y < -0.3f) {
            mean += double(b[v].x);
            ++count;
        }
    ASSERT_GT(count, 100u);
    std::printf("bowl, albedo from the image at the hits: closed form %.5f, mean %.5f\n", want, mean / double(count));
    EXPECT_NEAR(mean / double(count) / want, 1.0, 1e-3);
}

TEST(Transfer, ConvexSphereHasNoBounces) {
    Mesh mesh = sphere_mesh(500);
    const SphereRule rule = parse_rule("lebedev:302");
    const auto tracer = make_visibility_tracer("embree");
    const auto queries = make_ray_queries("brute");
    const std::vector<glm::vec3> rho(mesh.vertex_count(), glm::vec3(0.9f));
    TransferOptions o;
    o.kind = TransferKind::Interreflected;
    o.bounces = 2;
    Transfer t;
    const TransferReport r = bake_transfer(mesh, rule, *tracer, BakeOptions{}, o, rho, queries.get(), t);
    EXPECT_EQ(r.bounce_rays, 0u);
    const Transfer s = bake(mesh, "lebedev:302", TransferKind::Shadowed, 3);
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
        for (int c = 0; c < 3; ++c)
            for (int i = 0; i < 16; ++i)
                ASSERT_EQ(t.vertex(v, c)[i], s.vertex(v)[i]);
}

TEST(Transfer, BadInput) {
    Mesh mesh = sphere_mesh(200);
    const SphereRule rule = parse_rule("lebedev:50");
    const auto tracer = make_visibility_tracer("embree");
    Transfer t;
    auto where = [&](TransferOptions o, RayQueries* q = nullptr) -> std::string {
        try {
            bake_transfer(mesh, rule, *tracer, BakeOptions{}, o, std::vector<glm::vec3>(mesh.vertex_count()), q, t);
        } catch (const Error& e) {
            return e.where();
        }
        return "no error";
    };
    TransferOptions o;
    o.order = 9;
    EXPECT_EQ(where(o), "order");
    o.order = -1;
    EXPECT_EQ(where(o), "order");
    o = {};
    o.kind = TransferKind::Interreflected;
    o.bounces = 1;
    EXPECT_EQ(where(o), "backend");
    o.bounces = 0;
    EXPECT_EQ(where(o), "bounces");
    o = {};
    o.bounces = 2;
    EXPECT_EQ(where(o), "bounces");
    EXPECT_THROW(parse_transfer_kind("glossy"), Error);
    EXPECT_EQ(parse_transfer_model("shading-coefficient"), TransferModel::ShadingCoefficient);
}

} // namespace
} // namespace skybake
