// Both multiple-scattering methods against the Monte Carlo path tracer on
// Earth, at noon and at sunset (the figures of docs/sky.md).
//   orders:   converge to it as orders grow; with 8 orders every channel is
//             within 1% plus three standard errors of the path tracer;
//   night:    the orders' second order at the zenith against a direct
//             integral of the single-scattered light (no grid, no path
//             tracer: at −12° and below the tracer's paths almost never find
//             the lit air);
//   hillaire: within 6% plus three standard errors (our bound: Hillaire 2020
//             assumes isotropic, infinitely repeated second-order light, and
//             reports that it holds for Earth-like atmospheres; measured here
//             up to 5%).
// The single-scattering part comes from the exact quadrature in both the
// reference and the methods, so the comparison is of orders 2 and up.
#include <cmath>
#include <cstdio>
#include <memory>

#include <glm/exponential.hpp>

#include <gtest/gtest.h>

#include "skybake/sky.h"
#include "skybake/sky_path_tracer.h"
#include "sky/scattering_orders.h"

namespace skybake {
namespace {

constexpr double kPiD = 3.14159265358979323846;
constexpr double kDeg = kPiD / 180.0;

struct View {
    const char* name;
    double cos_view_zenith, cos_view_sun, cos_sun_zenith;
};

const View kViews[] = {
    {"noon (sun 60° high), zenith", 1.0, std::cos(30 * kDeg), std::cos(30 * kDeg)},
    {"sunset (sun on the horizon), zenith", 1.0, 0.0, 0.0},
};

struct Reference {
    glm::dvec3 single{0.0};     // exact quadrature
    PathTracedRadiance multiple; // path tracer, orders 2 and up
    glm::dvec3 total() const { return single + multiple.mean; }
};

class MultipleScatteringAgainstPathTracer : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        const Atmosphere atm = atmosphere_preset("earth");
        const SkyModel single(atm);
        PathTracerOptions opt;
        opt.paths = 1u << 18;
        opt.min_order = 2;
        for (int i = 0; i < 2; ++i) {
            const View& v = kViews[i];
            refs_[i].single = single.radiance_at_radius(atm.planet_radius_km, v.cos_view_zenith, v.cos_view_sun,
                                                        v.cos_sun_zenith, SkyMethod::Exact);
            refs_[i].multiple = path_trace_sky(atm, atm.planet_radius_km, v.cos_view_zenith, v.cos_view_sun,
                                               v.cos_sun_zenith, opt);
        }
    }
    static Reference refs_[2];
};
Reference MultipleScatteringAgainstPathTracer::refs_[2];

TEST_F(MultipleScatteringAgainstPathTracer, OrdersConvergeToIt) {
    const Atmosphere atm = atmosphere_preset("earth");
    // 16 polar samples, not the default 24: by day the two agree within 0.3%
    // (docs/sky.md, "The sphere rule"), and the test takes half the time.
    MultipleScatteringResolution res;
    res.sphere = 16;
    const sky::ScatteringOrders orders = sky::ScatteringOrders::compute(atm, res, 8, true);
    for (int i = 0; i < 2; ++i) {
        const View& v = kViews[i];
        const Reference& ref = refs_[i];
        glm::dvec3 sum = ref.single;
        double blue_error[9] = {};
        for (int n = 2; n <= 8; ++n) {
            sum += orders.order_radiance(n, atm.planet_radius_km, v.cos_view_zenith, v.cos_sun_zenith, v.cos_view_sun);
            blue_error[n] = std::abs(sum.z - ref.total().z);
        }
        EXPECT_GT(blue_error[2], blue_error[4]) << v.name;
        EXPECT_GT(blue_error[4], blue_error[8]) << v.name;
        for (int c = 0; c < 3; ++c) {
            const double bound = 0.01 * ref.total()[c] + 3.0 * ref.multiple.standard_error[c];
            EXPECT_NEAR(sum[c], ref.total()[c], bound) << v.name << ", channel " << c;
            // The reference is sharp enough for the 1% to mean something.
            EXPECT_LT(3.0 * ref.multiple.standard_error[c], 0.01 * ref.total()[c]) << v.name;
        }
    }
}

TEST_F(MultipleScatteringAgainstPathTracer, HillaireIsWithinItsBound) {
    Atmosphere atm = atmosphere_preset("earth");
    atm.scattering = Scattering::Multiple;
    atm.multiple_method = MultipleScatteringMethod::Hillaire;
    const SkyModel model(atm);
    for (int i = 0; i < 2; ++i) {
        const View& v = kViews[i];
        const Reference& ref = refs_[i];
        const glm::dvec3 got = model.radiance_at_radius(atm.planet_radius_km, v.cos_view_zenith, v.cos_view_sun,
                                                        v.cos_sun_zenith, SkyMethod::Exact);
        for (int c = 0; c < 3; ++c) {
            const double bound = 0.06 * ref.total()[c] + 3.0 * ref.multiple.standard_error[c];
            EXPECT_NEAR(got[c], ref.total()[c], bound) << v.name << ", channel " << c;
        }
    }
}

} // namespace
} // namespace skybake

namespace skybake {
namespace {

// Second-order light at the zenith, integrated directly: along the vertical
// from altitude `from_km`, Σk σs,k ρk(h) ∫4π pk(ω·z) L1(h, ω) dω, attenuated
// by the column below, with L1 the single-scattering radiance the air at h
// sees along ω (`method`: the seed's sum, SkyMethod::Tables, or the exact
// quadrature). Steps of dh km; 1° in elevation × (360 / naz)° in azimuth.
// From sea level (Tables, 0.5 km, 72 azimuths): halving the steps or the
// elevation spacing, or 64 steps in L1, moves it by < 16% at −12° and −16°.
// From 50 km (Exact, 2 km, 36 azimuths): within 0.6% of 1 km and 72
// azimuths at −8°; the seed's sum there is 11% bright in blue.
glm::dvec3 direct_second_order_zenith(const Atmosphere& atm, double mu_s, double from_km = 0.0,
                                      SkyMethod method = SkyMethod::Tables, double dh_km = 0.5, int naz = 72) {
    const SkyModel single(atm);
    const double R0 = atm.planet_radius_km, top = atm.top_radius_km - R0;
    const double sin_s = std::sqrt(std::max(0.0, 1.0 - mu_s * mu_s));
    const int steps = std::max(1, int((top - from_km) / dh_km)), nel = 180;
    const double dh = (top - from_km) / steps;
    glm::dvec3 sum(0.0), tau(0.0);
    for (int i = 0; i < steps; ++i) {
        const double h = from_km + (i + 0.5) * dh;
        glm::dvec3 ext(0.0);
        for (const AtmosphereComponent& c : atm.components)
            ext += c.extinction_per_km * relative_density(c, h);
        tau += 0.5 * dh * ext; // to the step's midpoint
        glm::dvec3 in_scatter(0.0);
        for (int e = 0; e < nel; ++e) {
            const double el = -0.5 * kPiD + (e + 0.5) * (kPiD / nel);
            const double cz = std::sin(el), cr = std::cos(el);
            const double d_omega = cr * (kPiD / nel) * (2.0 * kPiD / naz);
            for (int a = 0; a < naz; ++a) {
                // The sun lies in the x–z plane at azimuth 0.
                const double nu = cr * std::cos((a + 0.5) * (2.0 * kPiD / naz)) * sin_s + cz * mu_s;
                const glm::dvec3 L1 = single.radiance_at_radius(R0 + h, cz, nu, mu_s, method);
                for (const AtmosphereComponent& c : atm.components)
                    if (c.phase != PhaseFunction::None)
                        in_scatter += c.scattering_per_km * relative_density(c, h) *
                                      phase_function(c.phase, c.phase_g, cz) * L1 * d_omega;
            }
        }
        sum += glm::exp(-tau) * in_scatter * dh;
        tau += 0.5 * dh * ext;
    }
    return sum;
}

// At night the orders' second order at the zenith (default grid) follows the
// direct integral: measured 0.97, 0.98, 0.94 of it at −12° and 0.94, 1.09,
// 0.93 at −16° (R, G, B). At −16° the path tracer's second order (next
// events through the sunlit air, 2^15 paths) agrees with the direct
// integral too: 2.8e-10, 6.0e-11, 1.3e-10 (three standard errors 11–19%)
// against 2.9e-10, 5.4e-11, 1.2e-10. The former sphere rule (split at the
// horizontal alone, 16 samples) gave 0.73 in blue at −12° and 1.65 at −16°;
// split at the geometric horizon alone (24 samples), 0.27 in blue at −16°
// (docs/sky.md, "The sphere rule").
TEST(MultipleScatteringAtNight, ZenithSecondOrderFollowsADirectIntegral) {
    const Atmosphere atm = atmosphere_preset("earth");
    const sky::ScatteringOrders orders = sky::ScatteringOrders::compute(atm, MultipleScatteringResolution{}, 2, true);
    const struct {
        double sun_deg, factor;
    } cases[] = {{-12.0, 1.25}, {-16.0, 1.25}};
    for (const auto& k : cases) {
        const double mu_s = std::cos((90.0 - k.sun_deg) * kDeg);
        const glm::dvec3 direct = direct_second_order_zenith(atm, mu_s);
        const glm::dvec3 grid = orders.order_radiance(2, atm.planet_radius_km, 1.0, mu_s, mu_s);
        std::printf("sun %g°: second order at the zenith, grid %.3g %.3g %.3g, direct %.3g %.3g %.3g\n", k.sun_deg,
                    grid.x, grid.y, grid.z, direct.x, direct.y, direct.z);
        for (int c = 0; c < 3; ++c) {
            EXPECT_GT(direct[c], 0.0);
            EXPECT_LT(grid[c], k.factor * direct[c]) << k.sun_deg << "°, channel " << c;
            EXPECT_GT(grid[c], direct[c] / k.factor) << k.sun_deg << "°, channel " << c;
        }
    }
}

} // namespace
} // namespace skybake

namespace skybake {
namespace {

// 8° after sunset, the zenith from 50 km: the air above is in the shadow and
// its light comes from the lit air beyond the terminator. The grid's second
// order follows the direct integral with the exact single scattering:
// measured 0.993, 0.991, 0.989 of it (R, G, B). Interpolated linearly
// between radius nodes 7 km apart, where the light falls with the air's
// density, it was 1.16, 1.14, 1.15: per unit of the scattering coefficient
// (J) and of orders_scale (the radiance), the grid interpolates what is
// smooth (docs/sky.md, "Error over a grid of views").
TEST(MultipleScatteringAtTwilight, HighZenithSecondOrderFollowsADirectIntegral) {
    const Atmosphere atm = atmosphere_preset("earth");
    const sky::ScatteringOrders orders = sky::ScatteringOrders::compute(atm, MultipleScatteringResolution{}, 3, true);
    const double mu_s = std::cos(98.0 * kDeg), h = 50.0;
    const glm::dvec3 direct = direct_second_order_zenith(atm, mu_s, h, SkyMethod::Exact, 2.0, 36);
    const glm::dvec3 grid = orders.order_radiance(2, atm.planet_radius_km + h, 1.0, mu_s, mu_s);
    std::printf("50 km, sun -8°: second order at the zenith, grid %.4g %.4g %.4g, direct %.4g %.4g %.4g\n", grid.x,
                grid.y, grid.z, direct.x, direct.y, direct.z);
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(grid[c] / direct[c], 1.0, 0.05) << "channel " << c;
    // The third order against the path tracer's (2^14 paths, next events
    // through the sunlit air): measured 2.32e-10, 2.62e-10, 1.70e-9 against
    // 2.16e-10, 2.31e-10, 1.86e-9 (three standard errors 33–48%).
    PathTracerOptions opt;
    opt.min_order = 3;
    opt.max_order = 3;
    opt.paths = 1u << 14;
    opt.next_event = NextEvent::SunlitAir;
    const PathTracedRadiance traced = path_trace_sky(atm, atm.planet_radius_km + h, 1.0, mu_s, mu_s, opt);
    const glm::dvec3 third = orders.order_radiance(3, atm.planet_radius_km + h, 1.0, mu_s, mu_s);
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(third[c], traced.mean[c], 0.1 * traced.mean[c] + 3.0 * traced.standard_error[c]) << "channel " << c;
}

} // namespace
} // namespace skybake
