// Residual outputs (src/neural/mlp_hd.h, [SECTION] Residual outputs): the
// analytic single scattering that the network corrects, piece by piece
// against independent computations: the planet's shadow on the ray against a
// brute-force march of the same ray, the Chapman integrals against numerical
// quadrature, and the whole march against the sky model.
#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <gtest/gtest.h>

#include "core/random.h"
#include "neural/internal.h"
#include "neural/mlp_hd.h"
#include "sky/planet_shadow_hd.h"
#include "skybake/neural.h"
#include "skybake/sky.h"

namespace skybake {
namespace {

using namespace neural;

constexpr double kR = 6360.0;

// The march's encoding for an atmosphere: residual outputs, one term per scatterer.
MlpHD residual_hd(const Atmosphere& atm) {
    NeuralEncoding e;
    e.outputs = OutputEncoding::Residual;
    e.inputs = InputEncoding::Horizon;
    for (int k : phase_term_components(atm)) {
        const AtmosphereComponent& c = atm.components[std::size_t(k)];
        e.terms.push_back({c.name, c.phase, c.phase_g, glm::dvec3(1.0)});
    }
    MlpHD m;
    set_encoding_hd(e, atm, m);
    return m;
}

glm::dvec3 unit(SplitMix64& rng) {
    const double z = 2.0 * rng.uniform() - 1.0, phi = 2.0 * M_PI * rng.uniform();
    return {std::sqrt(1.0 - z * z) * std::cos(phi), std::sqrt(1.0 - z * z) * std::sin(phi), z};
}

bool in_shadow(const glm::dvec3& p, const glm::dvec3& s) {
    const double a = glm::dot(p, s);
    return a < 0.0 && glm::dot(p - a * s, p - a * s) < kR * kR;
}

TEST(ResidualOutputs, TheShadowOnTheRayIsABruteForceMarchOfIt) {
    // shadow_span (float, clipped to the ray's d km in the atmosphere) against
    // a 3D march of the same ray in double, and against the double interval of
    // sky/planet_shadow_hd.h.
    const MlpHD m = residual_hd(atmosphere_preset("earth"));
    SplitMix64 rng{0x5bad1e5u};
    int shadowed = 0, lit = 0;
    for (int n = 0; n < 3000; ++n) {
        const double h = 60.0 * rng.uniform();
        const glm::dvec3 up(0.0, 0.0, 1.0), v = unit(rng), s = unit(rng);
        const float mu = float(v.z), nu = float(glm::dot(v, s)), mu_s = float(s.z);
        const ViewRayHD ray = view_ray_at(m, mu, float(h));
        float lo = 0.0f, hi = 0.0f;
        const bool got = shadow_span(ray.r, ray.rho, mu, nu, mu_s, ray.d, lo, hi);
        const double r = kR + double(ray.h);
        const double step = 0.05;
        double first = -1.0, last = -1.0;
        for (double t = 0.0; t <= double(ray.d); t += step)
            if (in_shadow(r * up + t * glm::dvec3(v), s)) {
                if (first < 0.0)
                    first = t;
                last = t;
            }
        const sky::ShadowInterval<double> exact = sky::planet_shadow_interval(r, kR, double(mu), double(nu),
                                                                              double(mu_s));
        if (first < 0.0) {
            ++lit;
            // Lit all along, or a sliver of shadow the march stepped over.
            EXPECT_TRUE(!got || hi - lo < 2.0 * step) << n << ": " << lo << " " << hi;
            continue;
        }
        ++shadowed;
        ASSERT_TRUE(got) << n;
        EXPECT_NEAR(lo, first, step) << n;
        EXPECT_NEAR(hi, last, step) << n;
        EXPECT_NEAR(lo, std::max(exact.t0, 0.0), 2e-3 + 1e-5 * double(ray.d)) << n;
        EXPECT_NEAR(hi, std::min(exact.t1, double(ray.d)), 2e-3 + 1e-5 * double(ray.d)) << n;
    }
    std::printf("%d rays partly in shadow, %d lit\n", shadowed, lit);
    EXPECT_GT(shadowed, 300);
    EXPECT_GT(lit, 300);
}

// ∫ exp(−h(t)/H) dt over [a, b] of the ray from altitude h0 at cos zenith μ,
// by Simpson's rule in double on 20,000 intervals.
double density_integral(double h0, double mu, double H, double a, double b) {
    const int n = 20000;
    const double r = kR + h0, dt = (b - a) / n;
    auto rho = [&](double t) { return std::exp(-(std::sqrt(r * r + 2.0 * r * mu * t + t * t) - kR) / H); };
    double s = rho(a) + rho(b);
    for (int i = 1; i < n; ++i)
        s += (i % 2 ? 4.0 : 2.0) * rho(a + i * dt);
    return s * dt / 3.0;
}

TEST(ResidualOutputs, ChapmanDepthsAreTheDensityIntegrals) {
    // chapman_depth from altitude h towards cos χ against quadrature to
    // 1,500 km (e^(−60) of the density beyond): within 1% above the horizon
    // and below it, for the aerosols' and the air's scale heights (0.45%
    // measured).
    SplitMix64 rng{0xc4a9u};
    double worst = 0.0;
    for (int n = 0; n < 200; ++n) {
        const double H = n % 2 ? 8.0 : 1.2;
        const double h = 60.0 * rng.uniform() * rng.uniform();
        const double c = 2.0 * rng.uniform() - 1.0;
        const double x0 = (kR + h) * std::sqrt(1.0 - c * c) - kR; // periapsis altitude
        if (c < 0.0 && x0 < 0.0)
            continue; // the ray meets the ground
        const double want = density_integral(h, c, H, 0.0, 1500.0);
        const double got = chapman_depth(float(h), float(kR), float(H), float(c), float(std::exp(-h / H)));
        worst = std::max(worst, std::abs(got / want - 1.0));
        EXPECT_NEAR(got / want, 1.0, 0.01) << "h " << h << " cos " << c << " H " << H;
    }
    std::printf("chapman_depth: worst relative error %.4f\n", worst);
}

TEST(ResidualOutputs, ChapmanSegmentsAreTheDensityIntegralsWhereTheyAreUsed) {
    // chapman_segment over parts of view rays that span at least 2.5 scale
    // heights (where the march trusts it fully): within 1% of quadrature
    // (0.44% measured).
    SplitMix64 rng{0x5e9u};
    int used = 0;
    double worst = 0.0;
    for (int n = 0; n < 600 && used < 150; ++n) {
        const double H = n % 2 ? 8.0 : 1.2;
        const double h = 60.0 * rng.uniform();
        const double mu = 2.0 * rng.uniform() - 1.0;
        const double r = kR + h;
        const double disc = r * r * (mu * mu - 1.0) + kR * kR;
        const double d = mu < 0.0 && disc >= 0.0 ? -r * mu - std::sqrt(disc)
                                                  : -r * mu + std::sqrt(r * r * (mu * mu - 1.0) + 6420.0 * 6420.0);
        const double a = d * rng.uniform() * 0.5, b = a + (d - a) * (0.2 + 0.8 * rng.uniform());
        auto alt = [&](double t) { return std::sqrt(r * r + 2.0 * r * mu * t + t * t) - kR; };
        const double tl = std::clamp(-r * mu, a, b);
        if ((alt(a) + alt(b) - 2.0 * alt(tl)) / H < 2.5)
            continue;
        ++used;
        const double want = density_integral(h, mu, H, a, b);
        auto cosine = [&](double t) { return (r * mu + t) / (kR + alt(t)); };
        const double got = chapman_segment(float(kR), float(H), float(alt(a)), float(cosine(a)),
                                           float(std::exp(-alt(a) / H)), float(alt(b)), float(cosine(b)),
                                           float(std::exp(-alt(b) / H)));
        worst = std::max(worst, std::abs(got / want - 1.0));
        EXPECT_NEAR(got / want, 1.0, 0.01) << "h " << h << " mu " << mu << " [" << a << ", " << b << "] H " << H;
    }
    std::printf("chapman_segment: %d parts, worst relative error %.4f\n", used, worst);
    EXPECT_GE(used, 100);
}

TEST(ResidualOutputs, TheAnalyticMarchFollowsTheSkyModelOverAFlight) {
    // The march alone (the network's outputs all 0.5: no correction) against
    // the sky model's single scattering, over a flight's samples (0 to 60 km,
    // the sun down to −20°): the decades are the march's, the network only
    // corrects tens of percent. Where the model's ray is dark, the march's is
    // dark too but for the slivers of light the model's 64 steps step over
    // (below 1e-4 of the brightest sample).
    const Atmosphere atm = atmosphere_preset("earth");
    const MlpHD m = residual_hd(atm);
    const SkyModel model(atm);
    const std::vector<SkySample> s = draw_flight_samples(4000, 3, atm);
    std::vector<glm::vec3> ref(s.size());
    evaluate_sky(model, s, ref, SkyMethod::Tables);
    std::vector<double> err;
    int dark = 0;
    double brightest = 0.0;
    for (const glm::vec3& c : ref)
        brightest = std::max(brightest, double(glm::length(c)));
    for (std::size_t i = 0; i < s.size(); ++i) {
        float base[kMaxOutputs];
        analytic_terms(m, s[i].cos_view_zenith, s[i].cos_view_sun, s[i].cos_sun_zenith, s[i].density, base);
        glm::dvec3 a(0.0);
        for (int k = 0; k < m.terms; ++k)
            a += double(sky::phase_value(m.term_phase[k], m.term_g[k], s[i].cos_view_sun)) *
                 glm::dvec3(base[3 * k], base[3 * k + 1], base[3 * k + 2]);
        const double n = glm::length(glm::dvec3(ref[i]));
        if (n == 0.0) {
            ++dark;
            EXPECT_LT(glm::length(a), 1e-4 * brightest) << i;
            continue;
        }
        err.push_back(glm::length(a - glm::dvec3(ref[i])) / n);
    }
    std::sort(err.begin(), err.end());
    double mean = 0.0;
    for (double e : err)
        mean += e / double(err.size());
    const double p50 = err[err.size() / 2], p90 = err[err.size() * 9 / 10];
    std::printf("analytic march vs the sky model: %zu lit samples, mean %.4f, p50 %.4f, p90 %.4f; %d dark\n",
                err.size(), mean, p50, p90, dark);
    EXPECT_GT(dark, 50);
    // Measured: mean 0.093, p50 0.030, p90 0.199.
    EXPECT_LT(p50, 0.04);
    EXPECT_LT(p90, 0.25);
    EXPECT_LT(mean, 0.12);
}

} // namespace
} // namespace skybake
