// The Monte Carlo path tracer: Chandrasekhar's albedo problem (all orders, a
// closed form independent of the tracer), single scattering against the exact
// quadrature, order bookkeeping, thin atmospheres, determinism and bad options.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "skybake/error.h"
#include "skybake/sky.h"
#include "skybake/sky_path_tracer.h"
#include "sky/quadrature.h"

namespace skybake {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Chandrasekhar's H-function of isotropic scattering with albedo ϖ, from the
// fixed point of 1/H(μ) = √(1 − ϖ) + (ϖ/2) ∫₀¹ μ' H(μ') / (μ + μ') dμ'
// (Radiative Transfer, ch. V, eq. 15), by Nyström's method.
class HFunction {
public:
    explicit HFunction(double albedo, int nodes = 96) : w_(albedo) {
        sky::gauss_legendre_unit(nodes, x_, q_);
        h_.assign(x_.size(), 1.0);
        for (int it = 0; it < 20000; ++it) {
            double change = 0.0;
            std::vector<double> next(h_.size());
            for (std::size_t i = 0; i < x_.size(); ++i) {
                next[i] = (*this)(x_[i]);
                change = std::max(change, std::abs(next[i] - h_[i]));
            }
            h_ = next;
            if (change < 1e-14)
                break;
        }
    }
    double operator()(double mu) const {
        double s = 0.0;
        for (std::size_t j = 0; j < x_.size(); ++j)
            s += q_[j] * x_[j] * h_[j] / (mu + x_[j]);
        return 1.0 / (std::sqrt(1.0 - w_) + 0.5 * w_ * s);
    }

private:
    double w_;
    std::vector<double> x_, q_, h_;
};

TEST(ChandrasekharH, MeetsItsMomentIdentity) {
    // H(0) = 1 and α0 = ∫₀¹ H dμ = (2/ϖ)(1 − √(1 − ϖ)) (Radiative Transfer, ch. V, eq. 19).
    std::vector<double> x, w;
    sky::gauss_legendre_unit(200, x, w);
    for (const double albedo : {0.5, 0.9, 0.99}) {
        const HFunction h(albedo);
        EXPECT_NEAR(h(0.0), 1.0, 1e-9) << albedo;
        double a0 = 0.0;
        for (std::size_t i = 0; i < x.size(); ++i)
            a0 += w[i] * h(x[i]);
        EXPECT_NEAR(a0, 2.0 / albedo * (1.0 - std::sqrt(1.0 - albedo)), 1e-7) << albedo;
        EXPECT_GT(h(1.0), h(0.5)); // H grows with μ
    }
}

TEST(PathTracer, SlabReflectionIsChandrasekharsAlbedoProblem) {
    PathTracerOptions opt;
    opt.paths = 1u << 16;
    for (const double albedo : {0.5, 0.9, 0.99}) {
        const HFunction h(albedo);
        for (const double mu_sun : {0.3, 0.8}) {
            for (const double mu : {0.2, 0.6, 1.0}) {
                const double exact = albedo / (4.0 * kPi) * mu_sun / (mu + mu_sun) * h(mu) * h(mu_sun);
                const PathTracedRadiance r = path_trace_slab_reflection(SlabMedium{albedo}, mu, mu_sun, opt);
                EXPECT_NEAR(r.mean.x, exact, 3.0 * r.standard_error.x)
                    << "albedo " << albedo << " mu_sun " << mu_sun << " mu " << mu;
                EXPECT_LT(r.standard_error.x, 0.02 * exact);
                EXPECT_EQ(r.mean.x, r.mean.z);
            }
        }
    }
}

TEST(PathTracer, SlabFirstOrderIsTheClosedForm) {
    // Order 1 alone: (ϖ/4π) μ0/(μ + μ0), the H = 1 term.
    PathTracerOptions opt;
    opt.paths = 1u << 15;
    opt.max_order = 1;
    const double albedo = 0.7, mu_sun = 0.5, mu = 0.9;
    const PathTracedRadiance r = path_trace_slab_reflection(SlabMedium{albedo}, mu, mu_sun, opt);
    EXPECT_NEAR(r.mean.x, albedo / (4.0 * kPi) * mu_sun / (mu + mu_sun), 3.0 * r.standard_error.x);
}

struct View {
    const char* name;
    double altitude_km, cos_view_zenith, cos_view_sun, cos_sun_zenith;
};

std::vector<View> views() {
    const double d = kPi / 180.0;
    return {
        {"noon zenith", 0.0, 1.0, std::cos(30 * d), std::cos(30 * d)},
        {"sunset, 10° above the horizon towards the sun", 0.0, std::sin(10 * d), std::cos(10 * d), 0.0},
        {"orbit, 400 km, down", 400.0, -0.95, -0.6, 0.7},
    };
}

TEST(PathTracer, FirstOrderIsTheExactSingleScattering) {
    const Atmosphere atm = atmosphere_preset("earth");
    const SkyModel model(atm);
    PathTracerOptions opt;
    opt.paths = 1u << 14;
    opt.max_order = 1;
    for (const View& v : views()) {
        const double r = atm.planet_radius_km + v.altitude_km;
        const glm::dvec3 exact =
            model.radiance_at_radius(r, v.cos_view_zenith, v.cos_view_sun, v.cos_sun_zenith, SkyMethod::Exact);
        const PathTracedRadiance pt = path_trace_sky(atm, r, v.cos_view_zenith, v.cos_view_sun, v.cos_sun_zenith, opt);
        for (int c = 0; c < 3; ++c) {
            EXPECT_NEAR(pt.mean[c], exact[c], 3.0 * pt.standard_error[c]) << v.name << " channel " << c;
            EXPECT_LT(pt.standard_error[c], 0.05 * exact[c]) << v.name;
        }
    }
}

TEST(PathTracer, OrderRangesAddUp) {
    // The same seed draws the same paths: orders 1, then 2.., sum to all orders.
    const Atmosphere atm = atmosphere_preset("earth");
    const double r = atm.planet_radius_km;
    PathTracerOptions opt;
    opt.paths = 4096;
    const PathTracedRadiance all = path_trace_sky(atm, r, 0.5, 0.6, 0.8, opt);
    opt.max_order = 1;
    const PathTracedRadiance first = path_trace_sky(atm, r, 0.5, 0.6, 0.8, opt);
    opt.max_order = 1 << 20;
    opt.min_order = 2;
    const PathTracedRadiance rest = path_trace_sky(atm, r, 0.5, 0.6, 0.8, opt);
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(first.mean[c] + rest.mean[c], all.mean[c], 1e-12 * all.mean[c]);
        EXPECT_GT(rest.mean[c], 0.05 * all.mean[c]); // multiple scattering is not negligible on Earth
    }
}

TEST(PathTracer, ThinAtmosphereHasLittleMultipleScattering) {
    Atmosphere atm = atmosphere_preset("earth");
    for (AtmosphereComponent& c : atm.components) {
        c.scattering_per_km *= 0.01;
        c.extinction_per_km *= 0.01;
    }
    atm.ground_albedo = glm::dvec3(0.0);
    PathTracerOptions opt;
    opt.paths = 1u << 14;
    const double r = atm.planet_radius_km;
    opt.max_order = 1;
    const PathTracedRadiance first = path_trace_sky(atm, r, 0.3, 0.2, 0.7, opt);
    opt.max_order = 1 << 20;
    opt.min_order = 2;
    const PathTracedRadiance rest = path_trace_sky(atm, r, 0.3, 0.2, 0.7, opt);
    for (int c = 0; c < 3; ++c)
        EXPECT_LT(rest.mean[c], 0.01 * first.mean[c]) << c; // optical depth ≲ 0.01 at this scale
}

TEST(PathTracer, GroundAlbedoOnlyAddsLight) {
    Atmosphere dark = atmosphere_preset("earth");
    dark.ground_albedo = glm::dvec3(0.0);
    Atmosphere bright = dark;
    bright.ground_albedo = glm::dvec3(0.8);
    PathTracerOptions opt;
    opt.paths = 8192;
    const double r = dark.planet_radius_km;
    const PathTracedRadiance a = path_trace_sky(dark, r, 0.2, 0.1, 0.6, opt);
    const PathTracedRadiance b = path_trace_sky(bright, r, 0.2, 0.1, 0.6, opt);
    for (int c = 0; c < 3; ++c)
        EXPECT_GT(b.mean[c] - a.mean[c], 3.0 * std::hypot(a.standard_error[c], b.standard_error[c])) << c;
}

TEST(PathTracer, DeterministicInTheSeed) {
    const Atmosphere atm = atmosphere_preset("earth");
    PathTracerOptions opt;
    opt.paths = 2048;
    const PathTracedRadiance a = path_trace_sky(atm, atm.planet_radius_km + 1.0, 0.4, 0.3, 0.5, opt);
    const PathTracedRadiance b = path_trace_sky(atm, atm.planet_radius_km + 1.0, 0.4, 0.3, 0.5, opt);
    EXPECT_EQ(a.mean, b.mean);
    EXPECT_EQ(a.standard_error, b.standard_error);
    opt.seed = 2;
    const PathTracedRadiance c = path_trace_sky(atm, atm.planet_radius_km + 1.0, 0.4, 0.3, 0.5, opt);
    EXPECT_NE(a.mean, c.mean);
}

// Next events through the sunlit air: the same expectation as the sun's,
// checked on the albedo problem (all orders, closed form) and against the
// default estimator, and its first order is the adaptive quadrature.
TEST(PathTracerSunlitAir, SlabReflectionIsChandrasekharsAlbedoProblem) {
    PathTracerOptions opt;
    opt.paths = 1u << 14;
    opt.next_event = NextEvent::SunlitAir;
    for (const double albedo : {0.5, 0.99}) {
        const HFunction h(albedo);
        for (const double mu_sun : {0.3, 0.8}) {
            for (const double mu : {0.2, 1.0}) {
                const double exact = albedo / (4.0 * kPi) * mu_sun / (mu + mu_sun) * h(mu) * h(mu_sun);
                const PathTracedRadiance r = path_trace_slab_reflection(SlabMedium{albedo}, mu, mu_sun, opt);
                EXPECT_NEAR(r.mean.x, exact, 3.0 * r.standard_error.x)
                    << "albedo " << albedo << " mu_sun " << mu_sun << " mu " << mu;
                EXPECT_LT(r.standard_error.x, 0.02 * exact);
            }
        }
    }
}

TEST(PathTracerSunlitAir, FirstOrderIsTheAdaptiveQuadrature) {
    // Its graded Gauss–Legendre rule against SkyModel's adaptive Gauss–Kronrod
    // one, over the day, the terminator and deep twilight, from the ground and
    // from orbit: measured within 1.5e-4.
    const Atmosphere atm = atmosphere_preset("earth");
    const SkyModel model(atm);
    PathTracerOptions opt;
    opt.paths = 2;
    opt.max_order = 1;
    opt.next_event = NextEvent::SunlitAir;
    const double d = kPi / 180.0;
    std::vector<View> cases = views();
    for (const double sun : {2.0, -4.0, -8.0, -12.0})
        for (const double h : {0.0, 10.0, 50.0}) {
            const double tv = kPi - std::asin(atm.planet_radius_km / (atm.planet_radius_km + h)) - 1.0 * d;
            const double ts = (90.0 - sun) * d;
            cases.push_back({"horizon towards the sun", h, std::cos(tv), std::cos(tv - ts), std::cos(ts)});
            cases.push_back({"horizon away from the sun", h, std::cos(tv), std::cos(tv + ts), std::cos(ts)});
        }
    for (const View& v : cases) {
        const double r = atm.planet_radius_km + v.altitude_km;
        const glm::dvec3 exact =
            model.radiance_at_radius(r, v.cos_view_zenith, v.cos_view_sun, v.cos_sun_zenith, SkyMethod::Exact);
        const PathTracedRadiance pt = path_trace_sky(atm, r, v.cos_view_zenith, v.cos_view_sun, v.cos_sun_zenith, opt);
        for (int c = 0; c < 3; ++c) {
            EXPECT_EQ(pt.standard_error[c], 0.0);
            EXPECT_NEAR(pt.mean[c], exact[c], 3e-4 * exact[c] + 1e-300) << v.name << " " << v.altitude_km;
        }
    }
}

TEST(PathTracerSunlitAir, AgreesWithTheSunsNextEvents) {
    const Atmosphere atm = atmosphere_preset("earth");
    const double d = kPi / 180.0, R0 = atm.planet_radius_km;
    struct Case {
        const char* name;
        double h, mu, nu, mu_s;
    };
    const double tv = kPi - std::asin(R0 / (R0 + 10.0)) - 1.0 * d, ts = 94.0 * d;
    const Case cases[] = {
        {"noon zenith", 0.0, 1.0, std::cos(30 * d), std::cos(30 * d)},
        {"10 km, sun -4°, horizon away from it", 10.0, std::cos(tv), std::cos(tv + ts), std::cos(ts)},
    };
    for (const Case& k : cases) {
        PathTracerOptions opt;
        opt.min_order = 2;
        opt.paths = 1u << 14;
        const PathTracedRadiance a = path_trace_sky(atm, R0 + k.h, k.mu, k.nu, k.mu_s, opt);
        opt.next_event = NextEvent::SunlitAir;
        opt.paths = 1u << 10;
        const PathTracedRadiance b = path_trace_sky(atm, R0 + k.h, k.mu, k.nu, k.mu_s, opt);
        for (int c = 0; c < 3; ++c) {
            const double sigma = std::hypot(a.standard_error[c], b.standard_error[c]);
            EXPECT_NEAR(a.mean[c], b.mean[c], 3.0 * sigma) << k.name << " channel " << c;
            EXPECT_LT(sigma, 0.2 * a.mean[c]) << k.name;
        }
    }
}

TEST(PathTracerSunlitAir, ResolvesTheSkyBeyondTheTerminator) {
    // Sun 12° below the horizon, the zenith from sea level: no air above is
    // lit. The sun's next events almost never find the second order's light
    // there (2^14 paths: most channels see none); the sunlit air's do, with
    // 2^10 paths.
    const Atmosphere atm = atmosphere_preset("earth");
    const double mu_s = std::cos(102.0 * kPi / 180.0);
    PathTracerOptions opt;
    opt.min_order = 2;
    opt.max_order = 2;
    opt.paths = 1u << 10;
    opt.next_event = NextEvent::SunlitAir;
    const PathTracedRadiance b = path_trace_sky(atm, atm.planet_radius_km, 1.0, mu_s, mu_s, opt);
    opt.next_event = NextEvent::Sun;
    opt.paths = 1u << 14;
    const PathTracedRadiance a = path_trace_sky(atm, atm.planet_radius_km, 1.0, mu_s, mu_s, opt);
    for (int c = 0; c < 3; ++c) {
        EXPECT_GT(b.mean[c], 0.0);
        EXPECT_LT(b.standard_error[c], 0.25 * b.mean[c]) << "channel " << c;
        // The sun's estimate: no light, or an error above half of it.
        EXPECT_TRUE(a.mean[c] == 0.0 || a.standard_error[c] > 0.5 * a.mean[c]) << "channel " << c;
    }
}

TEST(PathTracerSunlitAir, FindsTheThirdOrderHighUp) {
    // The zenith from 50 km, the sun 8° below the horizon: the view ray's
    // collision probability is 1e-3, and paths start with that weight. A
    // roulette against an absolute weight ended all but 0.4% of them at
    // their first collision, and out of 2^14 paths the third order came
    // from one or none (0 in green). Against the path's own starting
    // weight, most paths reach it.
    const Atmosphere atm = atmosphere_preset("earth");
    const double mu_s = std::cos(98.0 * kPi / 180.0);
    PathTracerOptions opt;
    opt.min_order = 3;
    opt.max_order = 3;
    opt.paths = 1u << 14;
    opt.next_event = NextEvent::SunlitAir;
    const PathTracedRadiance m = path_trace_sky(atm, atm.planet_radius_km + 50.0, 1.0, mu_s, mu_s, opt);
    for (int c = 0; c < 3; ++c) {
        EXPECT_GT(m.mean[c], 0.0) << "channel " << c;
        EXPECT_LT(3.0 * m.standard_error[c], 0.6 * m.mean[c]) << "channel " << c;
    }
}

TEST(PathTracer, BadInputNamesTheField) {
    const Atmosphere atm = atmosphere_preset("earth");
    const double r = atm.planet_radius_km;
    PathTracerOptions opt;
    opt.paths = 1;
    EXPECT_THROW(path_trace_sky(atm, r, 1.0, 1.0, 1.0, opt), Error);
    opt.paths = 16;
    opt.min_order = 3;
    opt.max_order = 2;
    EXPECT_THROW(path_trace_sky(atm, r, 1.0, 1.0, 1.0, opt), Error);
    opt = {};
    EXPECT_THROW(path_trace_sky(atm, r, 1.0, -1.0, 1.0, opt), Error);       // not a cosine triple
    EXPECT_THROW(path_trace_sky(atm, r - 1.0, 1.0, 1.0, 1.0, opt), Error);  // under the ground
    EXPECT_THROW(path_trace_sky(atm, r, std::nan(""), 1.0, 1.0, opt), Error);
    EXPECT_THROW(path_trace_slab_reflection(SlabMedium{1.5}, 0.5, 0.5, opt), Error);
    EXPECT_THROW(path_trace_slab_reflection(SlabMedium{0.5}, 0.0, 0.5, opt), Error);
    try {
        path_trace_sky(atm, r, 1.0, 1.0, 1.0, PathTracerOptions{1});
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("paths"), std::string::npos);
    }
}

} // namespace
} // namespace skybake
