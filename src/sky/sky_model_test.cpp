// Sky colour: the exact reference against closed forms, the seed's sum
// against the exact reference, and the invariants of the input space.
#include <cmath>
#include <random>

#include <glm/common.hpp>
#include <glm/exponential.hpp>
#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "skybake/core.h"
#include "skybake/sky.h"
#include "sky/sky_hd.h"

using namespace skybake;

namespace {

double rel(const glm::dvec3& a, const glm::dvec3& b) {
    const double m = std::max({std::abs(b.x), std::abs(b.y), std::abs(b.z)});
    const glm::dvec3 d = glm::abs(a - b);
    return std::max({d.x, d.y, d.z}) / m;
}

// Single-scattered zenith radiance with the sun at the zenith (REFERENCE.md):
// both paths run straight up, so the attenuation is the whole column's,
// L/E = exp(−τ) Σ_k τ_s,k p_k(1), with τ_s,k = β_s,k ∫ρ_k dh.
glm::dvec3 zenith_closed_form(const Atmosphere& a) {
    const double top = a.top_radius_km - a.planet_radius_km;
    glm::dvec3 tau(0.0), sum(0.0);
    for (const AtmosphereComponent& c : a.components) {
        double column = 0.0;
        if (c.profile == DensityProfile::Exponential)
            column = c.scale_height_km * (1.0 - std::exp(-top / c.scale_height_km));
        else if (c.profile == DensityProfile::Tent)
            column = c.tent_half_width_km; // the whole tent lies below the top
        tau += c.extinction_per_km * column;
        sum += c.scattering_per_km * column * phase_function(c.phase, c.phase_g, 1.0);
    }
    return glm::exp(-tau) * sum;
}

} // namespace

TEST(PhaseFunctions, NormalisedOverTheSphere) {
    // 2π ∫ p(μ) dμ over [−1, 1]; the seed's printed Mie form integrates to 1/4.
    const auto integral = [](PhaseFunction p, double g, double moment) {
        const int n = 200000;
        double s = 0.0;
        for (int i = 0; i < n; ++i) {
            const double mu = -1.0 + (i + 0.5) * 2.0 / n;
            s += phase_function(p, g, mu) * std::pow(mu, moment);
        }
        return 2.0 * M_PI * s * 2.0 / n;
    };
    EXPECT_NEAR(integral(PhaseFunction::Rayleigh, 0.0, 0), 1.0, 1e-6);
    for (double g : {0.0, 0.5, 0.76}) {
        EXPECT_NEAR(integral(PhaseFunction::HenyeyGreenstein, g, 0), 1.0, 1e-4) << g;
        EXPECT_NEAR(integral(PhaseFunction::HenyeyGreenstein, g, 1), g, 1e-4) << g; // mean cosine
        EXPECT_NEAR(integral(PhaseFunction::CornetteShanks, g, 0), 1.0, 1e-4) << g;
        EXPECT_NEAR(integral(PhaseFunction::SeedMie, g, 0), 0.25, 1e-4) << g;
    }
}

TEST(PhaseFunctions, SharedFloatCodeMatchesDouble) {
    for (int p = 0; p <= 4; ++p)
        for (double mu : {-1.0, -0.3, 0.0, 0.7, 1.0}) {
            const double d = phase_function(PhaseFunction(p), 0.76, mu);
            EXPECT_NEAR(sky::phase_value(p, 0.76f, float(mu)), d, 1e-5 * (1 + d)) << p << " " << mu;
        }
}

TEST(SampleSpace, RealDirectionsGiveValidTriples) {
    std::mt19937 rng(7);
    std::normal_distribution<double> n;
    for (int i = 0; i < 1000; ++i) {
        glm::dvec3 v[3];
        for (auto& x : v)
            x = glm::normalize(glm::dvec3(n(rng), n(rng), n(rng)));
        const double a = glm::dot(v[0], v[1]), b = glm::dot(v[1], v[2]), c = glm::dot(v[0], v[2]);
        EXPECT_TRUE(is_valid_cosine_triple(a, b, c, 1e-9));
    }
    // cos(V,U) = 1 forces cos(V,L) = cos(U,L).
    EXPECT_FALSE(is_valid_cosine_triple(1.0, 0.5, -0.5));
    EXPECT_FALSE(is_valid_cosine_triple(1.0, 1.0, -1.0));
    EXPECT_TRUE(is_valid_cosine_triple(1.0, 0.3, 0.3));
    EXPECT_FALSE(is_valid_cosine_triple(1.5, 0.0, 0.0));
}

TEST(SampleSpace, DrawnSamplesAreValidAndDeterministic) {
    const auto a = draw_sky_samples(5000, 42);
    set_thread_count(1);
    const auto b = draw_sky_samples(5000, 42);
    set_thread_count(0);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
        ASSERT_TRUE(is_valid_sky_sample(a[i], 0.0));
        EXPECT_EQ(a[i].cos_view_sun, b[i].cos_view_sun);
        EXPECT_EQ(a[i].density, b[i].density);
    }
}

TEST(SeedSum, VectorFormEqualsTheSeedsDihedralFormula) {
    // Seed: cos θ_v = cos α_v cos β0 + sin α_v sin β0 cos Λ with
    // cos Λ = (cos θ0 − cos α0 cos β0)/(sin α0 sin β0). sky_hd.h uses
    // (r0 cos θ0 + v cos β0)/r_v; they must agree.
    const double r0 = 6372.0;
    for (double ca : {0.9, 0.3, -0.2})
        for (double cb : {0.8, -0.4})
            for (double cosl : {0.7, -0.5}) {
                const double sa = std::sqrt(1 - ca * ca), sb = std::sqrt(1 - cb * cb);
                const double ct0 = ca * cb + sa * sb * cosl;
                for (double v : {1.0, 50.0, 400.0}) {
                    const double rv = std::sqrt(r0 * r0 + v * v + 2 * r0 * v * ca);
                    const double cav = (r0 * ca + v) / rv, sav = r0 * sa / rv;
                    const double seed = cav * cb + sav * sb * cosl;
                    EXPECT_NEAR((r0 * ct0 + v * cb) / rv, seed, 1e-12);
                }
            }
}

TEST(SkyExact, ZenithWithSunAtZenithMatchesClosedForm) {
    for (const char* name : {"earth", "paper", "paper-dense"}) {
        const SkyModel model(atmosphere_preset(name));
        const glm::dvec3 expect = zenith_closed_form(model.atmosphere());
        EXPECT_LT(rel(model.radiance({1.0f, 1.0f, 1.0f, 1.0f}, SkyMethod::Exact), expect), 1e-6) << name;
        EXPECT_LT(rel(model.radiance({1.0f, 1.0f, 1.0f, 1.0f}, SkyMethod::Tables), expect), 0.02) << name;
    }
}

TEST(SkyModel, SunFarBelowTheHorizonGivesZero) {
    // The sun 30° below the horizon lights nothing the observer can see
    // (the atmosphere's top is 10° of arc away at most).
    const SkyModel model(atmosphere_preset("earth"));
    const double ct = std::cos(M_PI / 2 + M_PI / 6);
    for (double cv : {1.0, 0.3, 0.0, -0.2}) {
        const double sv = std::sqrt(1 - cv * cv), st = std::sqrt(1 - ct * ct);
        const SkySample s{float(cv), float(cv * ct + sv * st * 0.3), float(ct), 1.0f};
        EXPECT_EQ(model.radiance(s, SkyMethod::Tables), glm::dvec3(0.0));
        EXPECT_EQ(model.radiance(s, SkyMethod::Exact), glm::dvec3(0.0));
    }
}

TEST(SkyModel, SumConvergesAsStepsDouble) {
    // Midpoint rule: differences between successive doublings shrink.
    Atmosphere a = atmosphere_preset("earth");
    a.table_rule = TableRule::Refined;
    const SkyModel model(a);
    for (const SkySample s : {SkySample{0.2f, 0.5f, 0.6f, 1.0f}, SkySample{0.05f, 0.9f, 0.2f, 0.8f}}) {
        double prev = -1.0;
        glm::dvec3 last = model.radiance_tables(s, 8);
        for (int steps = 16; steps <= 256; steps *= 2) {
            const glm::dvec3 next = model.radiance_tables(s, steps);
            const double d = rel(next, last);
            if (prev >= 0.0) {
                EXPECT_LT(d, 0.6 * prev + 1e-5) << steps;
            }
            prev = d;
            last = next;
        }
        // ... towards the exact value (to the tables' accuracy), with either spacing.
        const glm::dvec3 exact = model.radiance(s, SkyMethod::Exact);
        EXPECT_LT(rel(last, exact), 0.01);
        EXPECT_LT(rel(model.radiance_tables(s, 1024, true), exact), 0.01);
        EXPECT_LT(rel(model.radiance_tables(s, 16), exact), rel(model.radiance_tables(s, 16, true), exact));
    }
}

TEST(SkyModel, TablesAgreeWithExactOnRandomSamples) {
    // docs/sky.md: median and 90th percentile of the relative error.
    Atmosphere a = atmosphere_preset("paper-dense");
    const SkyModel model(a, SkyModelOptions{{256, 128}, 64});
    const auto samples = draw_sky_samples(40, 3);
    std::vector<double> errs;
    for (const SkySample& s : samples) {
        const glm::dvec3 e = model.radiance(s, SkyMethod::Exact);
        if (std::max({e.x, e.y, e.z}) < 1e-6)
            continue; // night
        errs.push_back(rel(model.radiance(s, SkyMethod::Tables), e));
    }
    ASSERT_GT(errs.size(), 10u);
    std::sort(errs.begin(), errs.end());
    EXPECT_LT(errs[errs.size() / 2], 0.03);
}

TEST(SkyModel, ObserverInSpaceSeesTheSameAsAtTheTop) {
    const SkyModel model(atmosphere_preset("earth"));
    const Atmosphere& a = model.atmosphere();
    // From radius r far out, a ray with impact parameter p enters the top at
    // cos α_top = −sqrt(1 − p²/Rt²).
    const double r = a.top_radius_km + 5000.0, p = a.planet_radius_km + 30.0;
    const double cv = -std::sqrt(1 - p * p / (r * r));
    const double ct = -std::sqrt(1 - p * p / (a.top_radius_km * a.top_radius_km));
    const double v_in = r * -cv - std::sqrt(a.top_radius_km * a.top_radius_km - p * p);
    // Sun along the plane's normal-ish direction: cos β = 0.3.
    const double cs_far = 0.2;
    const double sv = std::sqrt(1 - cv * cv), ss = std::sqrt(1 - cs_far * cs_far);
    const double cvs = cv * cs_far + sv * ss * 0.5;
    const double cs_top = (r * cs_far + v_in * cvs) / a.top_radius_km;
    for (SkyMethod m : {SkyMethod::Tables, SkyMethod::Exact}) {
        const glm::dvec3 far = model.radiance_at_radius(r, cv, cvs, cs_far, m);
        const glm::dvec3 top = model.radiance_at_radius(a.top_radius_km, ct, cvs, cs_top, m);
        EXPECT_LT(rel(far, top), 1e-3);
    }
}

TEST(SkyModel, BatchMatchesSingleAndIgnoresThreadCount) {
    const SkyModel model(atmosphere_preset("paper"));
    const auto samples = draw_sky_samples(3000, 9);
    std::vector<glm::vec3> a(samples.size()), b(samples.size());
    evaluate_sky(model, samples, a, SkyMethod::Tables);
    set_thread_count(1);
    evaluate_sky(model, samples, b, SkyMethod::Tables);
    set_thread_count(0);
    for (std::size_t i = 0; i < samples.size(); i += 97) {
        EXPECT_EQ(a[i], b[i]);
        EXPECT_EQ(glm::dvec3(a[i]), model.radiance(samples[i], SkyMethod::Tables));
    }
}

TEST(SkyModel, BlueSkyRedderSunset) {
    const SkyModel model(atmosphere_preset("earth"));
    // Zenith at noon: blue dominates.
    const glm::dvec3 noon = model.radiance({1.0f, 0.9f, 0.9f, 1.0f}, SkyMethod::Tables);
    EXPECT_GT(noon.z, noon.y);
    EXPECT_GT(noon.y, noon.x);
    // Towards the sun at the horizon, the light is redder than at noon.
    const glm::dvec3 dusk = model.radiance({0.02f, 0.999f, 0.03f, 1.0f}, SkyMethod::Tables);
    EXPECT_GT(dusk.x / dusk.z, 2.0 * noon.x / noon.z);
}
