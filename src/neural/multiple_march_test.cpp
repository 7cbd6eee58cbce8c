// The multiple-scattering term of residual outputs as a correction of an
// isotropic march (src/neural/mlp_hd.h, analytic_multiple): the march against
// its closed form in a homogeneous medium, ψ's polynomial against a double
// evaluation, the fit against the sky's mean radiance by another sphere rule,
// and the weights file.
#include <cmath>
#include <vector>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "core/random.h"
#include "neural/error_bound_test_util.h"
#include "neural/internal.h"
#include "neural/mlp_hd.h"
#include "skybake/error.h"
#include "skybake/neural.h"
#include "skybake/sky.h"

namespace skybake {
namespace {

using namespace neural;

// A march over one component of constant density (a scale height of 10⁷ km)
// that scatters a fraction `albedo` of what it extinguishes, and ψ = psi0
// everywhere: M = ψ0 albedo (1 − e^(−β d)) exactly, whatever the steps.
MlpHD homogeneous(float beta, float albedo, float psi0) {
    MlpHD m;
    m.R0 = 6360.0f;
    m.Rtop = 6420.0f;
    m.scale_height = 8.0f; // the observer's altitude from its density, as always
    m.output_kind = kOutputsResidual;
    m.ext_count = 1;
    m.ext_height[0] = 1e7f;
    m.terms = 1;
    m.term_ext[0] = 0;
    for (int c = 0; c < 3; ++c) {
        m.ext_beta[0][c] = beta * float(c + 1);
        m.term_beta[0][c] = albedo * beta * float(c + 1);
        m.psi[c][0] = std::log(psi0);
    }
    m.multiple = 1;
    m.multiple_march = 1;
    return m;
}

// The ray's length from altitude h (km) at cos μ to the top or the ground, in double.
double ray_length(double h, double mu) {
    const double R0 = 6360.0, Rt = 6420.0, r = R0 + h;
    const double disc_ground = r * r * mu * mu - (r * r - R0 * R0);
    if (mu < 0.0 && disc_ground >= 0.0)
        return -r * mu - std::sqrt(disc_ground);
    return -r * mu + std::sqrt(r * r * mu * mu + Rt * Rt - r * r);
}

TEST(MultipleMarch, AHomogeneousMediumIsItsClosedForm) {
    SplitMix64 rng{0x3a7c4u};
    for (float beta : {1e-4f, 2e-3f, 0.05f, 1.0f}) { // thin (the series) to opaque
        const MlpHD m = homogeneous(beta, 0.8f, 0.03f);
        for (int n = 0; n < 200; ++n) {
            const double h = 59.0 * rng.uniform(), mu = 2.0 * rng.uniform() - 1.0;
            const double mu_s = 2.0 * rng.uniform() - 1.0;
            const double nu = mu * mu_s + std::sqrt((1 - mu * mu) * (1 - mu_s * mu_s)) * std::cos(6.283 * rng.uniform());
            float out[3];
            analytic_multiple(m, float(mu), float(nu), float(mu_s), float(std::exp(-h / 8.0)), out);
            const double d = ray_length(h, mu);
            for (int c = 0; c < 3; ++c) {
                const double want = 0.03 * 0.8 * -std::expm1(-double(beta) * (c + 1) * d);
                EXPECT_NEAR(out[c], want, 2e-4 * want) << "beta " << beta << " h " << h << " mu " << mu;
            }
        }
    }
}

TEST(MultipleMarch, AnObserverAboveTheTopWhoseRayMissesSeesNothing) {
    const MlpHD m = homogeneous(0.05f, 0.8f, 0.03f);
    const float density = float(std::exp(-80.0 / 8.0)); // 80 km up, 20 km above the top
    float out[3], base[3];
    // The top's horizon from 80 km is 4.5° below the horizontal: a ray 3° down misses it, 10° down meets it.
    analytic_multiple(m, -std::sin(3.0f * 0.0174533f), 0.3f, 0.5f, density, out);
    analytic_terms(m, -std::sin(3.0f * 0.0174533f), 0.3f, 0.5f, density, base);
    for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(out[c], 0.0f);
        EXPECT_EQ(base[c], 0.0f);
    }
    analytic_multiple(m, -std::sin(10.0f * 0.0174533f), 0.3f, 0.5f, density, out);
    EXPECT_GT(out[0], 0.0f);
}

TEST(MultipleMarch, PsiIsItsPolynomialClampedToItsDomain) {
    NeuralSky net = neural_test::with_marched_multiple(neural_test::with_encoding(
        neural_test::random_network("shared:8x6", 3), InputEncoding::Horizon, OutputEncoding::Residual, 4, true));
    const MlpHD m = make_mlp_hd(net);
    const double top = double(m.Rtop - m.R0), lo = net.encoding.multiple_psi_mu_min;
    SplitMix64 rng{0x951u};
    for (int n = 0; n < 500; ++n) {
        const double h = 70.0 * rng.uniform() - 5.0, mu_s = 2.0 * rng.uniform() - 1.0;
        const double x = std::clamp(2.0 * h / top - 1.0, -1.0, 1.0);
        const double y = std::clamp((mu_s - lo) / (1.0 - lo) * 2.0 - 1.0, -1.0, 1.0);
        for (int c = 0; c < 3; ++c) {
            double want = 0.0;
            for (int i = 0; i <= kPsiAltitudeDegree; ++i)
                for (int j = 0; j <= kPsiSunDegree; ++j)
                    want += net.encoding.multiple_psi[std::size_t(c * kPsiCoefficients + i * (kPsiSunDegree + 1) + j)] *
                            std::pow(x, i) * std::pow(y, j);
            EXPECT_NEAR(psi_log(m, c, float(h), float(mu_s)), want, 2e-5 * (1.0 + std::abs(want)));
        }
    }
}

// The sky's mean radiance over the sphere at altitude h and sun cosine mu_s,
// by a product rule (Gauss–Legendre in cos θ, split at the horizon's
// cosine, × uniform azimuths): not the Fibonacci sphere of the fit.
glm::dvec3 mean_radiance(const SkyModel& model, double h, double mu_s) {
    const double pi = 3.14159265358979323846, R0 = model.atmosphere().planet_radius_km;
    const double mu_h = -std::sqrt(std::max(0.0, 1.0 - (R0 / (R0 + h)) * (R0 / (R0 + h))));
    const double x[4] = {-0.861136311594053, -0.339981043584856, 0.339981043584856, 0.861136311594053};
    const double w[4] = {0.347854845137454, 0.652145154862546, 0.652145154862546, 0.347854845137454};
    const double cuts[4] = {-1.0, mu_h, 0.0, 1.0};
    glm::dvec3 sum(0.0);
    const double ss = std::sqrt(1.0 - mu_s * mu_s);
    for (int part = 0; part < 3; ++part) {
        const double a = cuts[part], b = cuts[part + 1];
        for (int panel = 0; panel < 4; ++panel) // four Gauss panels per interval
            for (int i = 0; i < 4; ++i) {
                const double pa = a + (b - a) * panel / 4.0, pb = a + (b - a) * (panel + 1) / 4.0;
                const double mu = 0.5 * (pa + pb) + 0.5 * (pb - pa) * x[i];
                for (int k = 0; k < 48; ++k) {
                    const double phi = 2.0 * pi * (k + 0.5) / 48.0;
                    const double nu = mu * mu_s + std::sqrt(std::max(0.0, 1.0 - mu * mu)) * ss * std::cos(phi);
                    sum += 0.5 * (pb - pa) * w[i] / 48.0 *
                           model.radiance_at_radius(R0 + h, mu, nu, mu_s, SkyMethod::Tables);
                }
            }
    }
    return sum / 2.0;
}

TEST(MultipleMarch, TheFitFollowsTheSkysMeanRadiance) {
    // Coarse orders tables (seconds, not a minute): the fit follows whatever sky it is given.
    Atmosphere atm = atmosphere_preset("earth");
    atm.scattering = Scattering::Multiple;
    SkyModelOptions o;
    o.multiple.r = 6;
    o.multiple.mu = 8;
    o.multiple.mu_s = 16;
    o.multiple.nu = 4;
    o.multiple.sphere = 8;
    const SkyModel model(atm, o);
    const std::vector<double> a = fit_multiple_psi(model, -0.5, Device::Cpu);
    ASSERT_EQ(a.size(), std::size_t(3 * kPsiCoefficients));
    EXPECT_EQ(a, fit_multiple_psi(model, -0.5, Device::Cpu)); // deterministic
    NeuralEncoding e;
    e.multiple = true;
    e.multiple_psi = a;
    MlpHD m;
    m.R0 = float(atm.planet_radius_km);
    m.Rtop = float(atm.top_radius_km);
    m.multiple = m.multiple_march = 1;
    for (int c = 0; c < 3; ++c)
        for (int i = 0; i < kPsiCoefficients; ++i)
            m.psi[c][i] = float(a[std::size_t(c * kPsiCoefficients + i)]);
    double worst = 0.0, sq = 0.0;
    int n = 0;
    for (double h : {0.0, 5.0, 20.0, 45.0})
        for (double elevation : {70.0, 30.0, 8.0, 2.0, 0.0, -3.0, -8.0, -14.0}) {
            const double mu_s = std::sin(elevation * 3.14159265358979323846 / 180.0);
            const glm::dvec3 mean = mean_radiance(model, h, mu_s);
            for (int c = 0; c < 3; ++c) {
                const double r = double(psi_log(m, c, float(h), float(mu_s))) - std::log(mean[c]);
                worst = std::max(worst, std::abs(r));
                sq += r * r;
                ++n;
            }
        }
    const double rms = std::sqrt(sq / n);
    std::printf("ln psi against the mean radiance: rms %.3f, worst %.3f nats over %d values\n", rms, worst, n);
    // A base the network corrects within e^±2; measured on these coarse
    // tables rms 0.38, worst 1.15 nats (deep twilight at the ground, where a
    // degree-6 polynomial bends least well). A wrong mapping of either
    // argument is off by several nats.
    EXPECT_LT(rms, 0.5);
    EXPECT_LT(worst, 1.5);
}

TEST(MultipleMarch, TheWeightsFileKeepsPsiAndChecksIt) {
    const NeuralSky net = neural_test::with_marched_multiple(neural_test::with_encoding(
        neural_test::random_network("shared:8x6", 3), InputEncoding::Horizon, OutputEncoding::Residual, 4, true));
    const std::string text = neural_sky_to_json(net);
    const NeuralSky back = neural_sky_from_json(text);
    EXPECT_EQ(back.encoding.multiple_psi, net.encoding.multiple_psi);
    EXPECT_EQ(back.encoding.multiple_psi_mu_min, net.encoding.multiple_psi_mu_min);
    const SkySample s{0.1f, 0.3f, -0.05f, 0.7f};
    EXPECT_EQ(neural_sky_radiance(back, s), neural_sky_radiance(net, s));
    // The term follows the march: twice ψ, twice the multiply scattered light.
    NeuralSky brighter = net;
    for (int c = 0; c < 3; ++c)
        brighter.encoding.multiple_psi[std::size_t(c * kPsiCoefficients)] += std::log(2.0);
    NeuralSky single_only = net;
    single_only.encoding.multiple_psi.assign(single_only.encoding.multiple_psi.size(), -80.0); // ψ ≈ 0
    const glm::vec3 one = neural_sky_radiance(single_only, s);
    EXPECT_NEAR(glm::length(neural_sky_radiance(brighter, s) - one), 2.0f * glm::length(neural_sky_radiance(net, s) - one),
                1e-5f * glm::length(neural_sky_radiance(net, s)));
    // Bad files: one clear error naming the field.
    auto expect_error = [&](const std::string& from, const std::string& to) {
        std::string bad = text;
        const std::size_t at = bad.find(from);
        ASSERT_NE(at, std::string::npos) << from;
        bad.replace(at, from.size(), to);
        try {
            neural_sky_from_json(bad);
            ADD_FAILURE() << "accepted " << to;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("multiple_psi"), std::string::npos) << e.what();
        }
    };
    expect_error("\"mu_s_min\": -0.5", "\"mu_s_min\": 0.9");
    expect_error("\"mu_s_min\": -0.5", "\"mu_s_min\": \"low\"");
    expect_error("\"log_psi\": [", "\"log_psi\": [[1.0],");
}

} // namespace
} // namespace skybake
