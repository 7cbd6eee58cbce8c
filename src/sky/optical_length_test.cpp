// Optical lengths: the exact quadrature against closed forms, the seed's
// tables against the exact quadrature.
// Closed forms: vertical ∫ exp(−h/H) dh; the Chapman function at the horizon
// (Chapman S. 1931; values from ../shared/docs/REFERENCE.md); the chord of a
// uniform shell.
#include <cmath>

#include <gtest/gtest.h>

#include "skybake/sky.h"
#include "sky/quadrature.h"
#include "sky/sky_hd.h"

using namespace skybake;

namespace {

Atmosphere single_exponential(double R0, double H, double top_height) {
    Atmosphere a;
    a.name = "test";
    a.planet_radius_km = R0;
    a.top_radius_km = R0 + top_height;
    AtmosphereComponent c;
    c.name = "gas";
    c.scale_height_km = H;
    c.scattering_per_km = c.extinction_per_km = glm::dvec3(0.01);
    a.components.push_back(c);
    return a;
}

} // namespace

TEST(Quadrature, Kronrod15IsExactForPolynomialsUpToDegree22) {
    for (int k = 0; k <= 22; ++k) {
        double err;
        const auto f = [k](double x) { return glm::dvec3(std::pow(x, k), 0.0, 0.0); };
        const double v = sky::gk15_panel(f, 0.0, 2.0, err).x;
        EXPECT_NEAR(v, std::pow(2.0, k + 1) / (k + 1), 1e-12 * std::pow(2.0, k + 1)) << "degree " << k;
    }
}

TEST(Quadrature, AdaptiveIntegratesSharpExponential) {
    const auto f = [](double x) { return glm::dvec3(std::exp(-x / 0.01), 0.0, 0.0); };
    const auto pts = sky::graded_breakpoints(0.0, 100.0, {0.0}, 0.0025);
    EXPECT_NEAR(sky::integrate_adaptive(f, pts, 1e-12, 1e-300).x, 0.01, 1e-13);
}

TEST(OpticalLengthExact, VerticalMatchesClosedForm) {
    // ∫_h^top exp(−z/H) dz = H (exp(−h/H) − exp(−h_top/H)).
    const Atmosphere a = atmosphere_preset("earth");
    for (int k = 0; k < 2; ++k) {
        const double H = a.components[std::size_t(k)].scale_height_km;
        const double top = a.top_radius_km - a.planet_radius_km;
        for (double h : {0.0, 1.0, 7.5, 30.0}) {
            const double expect = H * (std::exp(-h / H) - std::exp(-top / H));
            EXPECT_NEAR(optical_length_exact(a, k, h, 1.0), expect, 1e-10 * H) << "component " << k << " h " << h;
        }
    }
    // REFERENCE.md: Earth Rayleigh vertical optical depth 0.0464, 0.1084, 0.2647
    // (top at infinity; those figures are truncated: 8 km × 13.558e-3 = 0.108464).
    const Atmosphere far = single_exponential(6360.0, 8.0, 400.0);
    const double t = optical_length_exact(far, 0, 0.0, 1.0);
    EXPECT_NEAR(t * 5.802e-3, 0.0464, 1.5e-4);
    EXPECT_NEAR(t * 13.558e-3, 0.1084, 1.5e-4);
    EXPECT_NEAR(t * 33.100e-3, 0.2647, 1.5e-4);
}

TEST(OpticalLengthExact, HorizonMatchesChapmanFunction) {
    // Ch(x, 0) = 35.355 at x = 795 and 91.249 at x = 5300 (x = R/H); t = H Ch.
    const Atmosphere gas = single_exponential(6360.0, 8.0, 8.0 * 60.0);
    EXPECT_NEAR(optical_length_exact(gas, 0, 0.0, 0.0) / 8.0, 35.355, 2e-3);
    const Atmosphere aerosol = single_exponential(6360.0, 1.2, 1.2 * 60.0);
    EXPECT_NEAR(optical_length_exact(aerosol, 0, 0.0, 0.0) / 1.2, 91.249, 2e-3);
    // The asymptotic form: Ch(x, 90°) = x eˣ K₁(x) ≈ sqrt(πx/2)(1 + 3/(8x)),
    // 35.3548 at x = 795 (the next term, −15/(128x²), is 2e-7 relative).
    const double x = 6360.0 / 8.0;
    const double chapman = std::sqrt(M_PI * x / 2) * (1 + 3 / (8 * x));
    EXPECT_NEAR(chapman, 35.3548, 1e-4);
    EXPECT_NEAR(optical_length_exact(gas, 0, 0.0, 0.0) / 8.0, chapman, 1e-3);
}

TEST(OpticalLengthExact, UniformShellIsTheChordLength) {
    Atmosphere a = single_exponential(6360.0, 8.0, 60.0);
    a.components.push_back(a.components[0]);
    a.components[1].profile = DensityProfile::Constant;
    const double R0 = a.planet_radius_km, Rt = a.top_radius_km;
    for (double h : {0.0, 10.0, 59.0})
        for (double mu : {1.0, 0.5, 0.1, 0.0, -0.05}) {
            const double r = R0 + h;
            if (mu < 0 && r * r * (1 - mu * mu) < R0 * R0)
                continue;
            const double chord = std::sqrt(Rt * Rt - r * r * (1 - mu * mu)) - r * mu;
            EXPECT_NEAR(optical_length_exact(a, 1, h, mu), chord, 1e-9 * chord) << h << " " << mu;
        }
    // A ray into the ground never reaches the top.
    EXPECT_TRUE(std::isinf(optical_length_exact(a, 1, 0.0, -0.5)));
}

TEST(OpticalLengthTables, UniformShellRowsAreExact) {
    // With a constant profile every shell weight is 1, so the seed's shell sum
    // telescopes to the chord length exactly, at any resolution.
    Atmosphere a = single_exponential(6360.0, 8.0, 60.0);
    a.components.push_back(a.components[0]);
    a.components[1].profile = DensityProfile::Constant;
    const auto t = OpticalLengthTables::build(a, {16, 8});
    const double R0 = a.planet_radius_km, Rt = a.top_radius_km;
    for (int i = 0; i <= 16; ++i)
        for (int j = 0; j <= 8; ++j) {
            const double r = R0 + 60.0 * i / 16.0, mu = j / 8.0;
            const double chord = std::sqrt(Rt * Rt - r * r * (1 - mu * mu)) - r * mu;
            EXPECT_NEAR(t.length_table(1)[std::size_t(i * t.columns() + j)], chord, 1e-4 * (chord + 1)) << i << " " << j;
        }
}

TEST(OpticalLengthTables, VerticalRowsFollowTheSeedSum) {
    // Straight up (c = 1) the seed's sum is Σ ρ_i H ln(ρ_{i+1}/ρ_i): compute it
    // independently and compare, and the log-mean rule gives H(ρ − ρ_top).
    const Atmosphere a = single_exponential(6360.0, 8.0, 8.0 * 40.0);
    const int n = 64;
    const auto seed = OpticalLengthTables::build(a, {n, 8});
    Atmosphere b = a;
    b.table_rule = TableRule::Refined;
    const auto logmean = OpticalLengthTables::build(b, {n, 8});
    const double rho_top = std::exp(-40.0);
    for (int k = 1; k <= n; ++k) {
        double sum = 0.0;
        for (int i = 1; i < k; ++i)
            sum += (double(i) / n) * 8.0 * std::log(double(i + 1) / i);
        sum += rho_top * 8.0 * std::log((1.0 / n) / rho_top); // top shell, capped at the top
        const std::size_t idx = std::size_t(k) * std::size_t(seed.columns()) + std::size_t(seed.columns() - 1);
        EXPECT_NEAR(seed.length_table(0)[idx], sum, 2e-5 * 8.0) << k;
        EXPECT_NEAR(logmean.length_table(0)[idx], 8.0 * (double(k) / n - rho_top), 2e-5 * 8.0) << k;
    }
}

struct TableError {
    double worst = 0.0;     // max |table − exact| / max(exact, H), all points
    double upward_low = 0.0; // max |table − exact| / exact, upward rays below 10 km
};

// Table lookup against the exact length over altitudes 0..50 km and cosines
// −1..1 (rays that meet the ground have no finite exact value). H is the
// component's vertical optical length from the ground.
TableError table_error(const Atmosphere& a, int k, const TableResolution& res) {
    const auto t = OpticalLengthTables::build(a, res);
    const double H = a.components[std::size_t(k)].scale_height_km;
    TableError out;
    for (double h = 0.0; h <= 50.0; h += 2.5)
        for (double mu = -1.0; mu <= 1.0; mu += 1.0 / 32) {
            const double e = optical_length_exact(a, k, h, mu);
            if (std::isinf(e))
                continue;
            const double d = std::abs(t.optical_length(k, h, mu) - e);
            out.worst = std::max(out.worst, d / std::max(e, H));
            if (h <= 10.0 && mu >= 0.0)
                out.upward_low = std::max(out.upward_low, d / e);
        }
    return out;
}

TEST(OpticalLengthTables, MatchExactWithinStatedTolerance) {
    // docs/sky.md records the full figures. At 256 x 128 the seed's rule (the
    // density at each shell's outer edge) is within 4% for gas rays going up
    // from below 10 km, and halves its error when n doubles; the refined rule
    // is within 1% of max(exact, H) everywhere, for gas and aerosol.
    Atmosphere a = atmosphere_preset("earth");
    a.table_rule = TableRule::AsPublished;
    a.components.pop_back(); // ozone has its own test
    const TableError seed = table_error(a, 0, {256, 128});
    EXPECT_LT(seed.upward_low, 0.04);
    EXPECT_LT(table_error(a, 0, {512, 128}).upward_low, 0.6 * seed.upward_low);
    a.table_rule = TableRule::Refined;
    EXPECT_LT(table_error(a, 0, {256, 128}).worst, 0.01);
    EXPECT_LT(table_error(a, 1, {256, 128}).worst, 0.01);
}

TEST(OpticalLengthTables, ErrorShrinksWithResolution) {
    Atmosphere a = atmosphere_preset("paper");
    a.table_rule = TableRule::Refined;
    EXPECT_LT(table_error(a, 0, {256, 128}).worst, 0.5 * table_error(a, 0, {32, 16}).worst);
}

TEST(OpticalLengthTables, OzoneTentAgreesWithExact) {
    Atmosphere a = atmosphere_preset("earth");
    a.table_rule = TableRule::Refined;
    const auto t = OpticalLengthTables::build(a, {256, 128});
    for (double h : {0.0, 12.0, 30.0})
        for (double mu : {1.0, 0.6, 0.2}) {
            const double e = optical_length_exact(a, 2, h, mu);
            EXPECT_NEAR(t.optical_length(2, h, mu), e, 0.01 * e + 1e-3) << h << " " << mu;
        }
    // Vertical from the ground: the whole tent, 15 km.
    EXPECT_NEAR(optical_length_exact(a, 2, 0.0, 1.0), 15.0, 1e-8);
}

TEST(OpticalLengthTables, ContinuousAcrossTheHorizon) {
    // The seed's symmetry for c < 0 must join the table at c = 0.
    const Atmosphere a = atmosphere_preset("paper");
    const auto t = OpticalLengthTables::build(a, {256, 128});
    for (int k = 0; k < 2; ++k)
        for (double h : {0.0, 0.5, 3.0, 20.0}) {
            const double at = t.optical_length(k, h, 0.0);
            const double up = t.optical_length(k, h, 1e-5);
            const double down = t.optical_length(k, h, -1e-5);
            EXPECT_NEAR(up, at, 1e-3 * at) << k << " " << h;
            EXPECT_NEAR(down, at, 1e-3 * at) << k << " " << h;
        }
}

TEST(OpticalLengthTables, DownwardRaysUseTheTangentPoint) {
    Atmosphere a = atmosphere_preset("paper");
    a.table_rule = TableRule::Refined;
    const auto t = OpticalLengthTables::build(a, {256, 128});
    // From 20 km, rays just below the horizon pass above the ground.
    const double h = 20.0, r = a.planet_radius_km + h;
    const double mu_graze = -std::sqrt(1.0 - std::pow(a.planet_radius_km / r, 2));
    for (double f : {0.2, 0.5, 0.9}) {
        const double mu = f * mu_graze;
        const double e = optical_length_exact(a, 0, h, mu);
        EXPECT_NEAR(t.optical_length(0, h, mu), e, 0.01 * e) << mu;
    }
}

TEST(OpticalLengthTables, ShellTableIsTheFirstShell) {
    // S[row, c] is the seed's ρ_i s_i of the shell just outside the row.
    const Atmosphere a = atmosphere_preset("paper");
    const int n = 32, m = 8;
    const auto t = OpticalLengthTables::build(a, {n, m});
    const double R0 = a.planet_radius_km, H = 8.3;
    const int i = 20, j = 3;
    const double b = R0 - H * std::log(double(i) / n), ar = R0 - H * std::log(double(i - 1) / n);
    const double c = double(j) / m;
    const double s = std::sqrt(ar * ar - b * b * (1 - c * c)) - b * c;
    EXPECT_NEAR(t.shell_table(0)[std::size_t(i * (m + 1) + j)], double(i - 1) / n * s, 1e-5);
}
