// Bruneton E., Neyret F. Precomputed Atmospheric Scattering. EGSR 2008.
// Bruneton E. A Qualitative and Quantitative Evaluation of 8 Clear Sky
// Models. IEEE TVCG 2017, and its reference implementation (functions.glsl:
// ComputeSingleScattering, ComputeScatteringDensity,
// ComputeIndirectIrradiance, ComputeMultipleScattering), here in double
// precision on the CPU, over every component of the atmosphere.
//
// Order 1, per component k and without its phase:
//   S_k(x, ω) = ∫_0^d σs,k(y) T(x, y) T_sun(y) dt,       y = x + t ω.
// Order n ≥ 2, from the radiance L_{n−1} and the ground irradiance E_{n−1} of
// the light scattered n − 2 times (E_1: the direct sun):
//   J_n(x, ω)  = Σ_k σs,k(x) ∫_4π p_k(ω·ω_i) [L_{n−1}(x, ω_i)
//                 + T(x, g) (albedo / π) E_{n−1}(g)] dω_i   (g: where ω_i meets the ground)
//   L_n(x, ω)  = ∫_0^d T(x, y) J_n(y, ω) dt
//   E_n(μs)    = ∫_{2π} L_{n−1}(ground, ω_i) (ω_i·n) dω_i
// A ground reflection counts as one scattering event, as in the path tracer.
// The planet's shadow is hard (no penumbra of the sun disc).
#include "sky/scattering_orders.h"

#include <algorithm>
#include <cassert>
#include <cmath>

#include <glm/geometric.hpp>

#include "core/parallel.h"
#include "core/progress.h"
#include "sky/quadrature.h"
#include "sky/transmittance_table.h"

namespace skybake::sky {

namespace {

constexpr double kPiD = 3.14159265358979323846;
constexpr int kIrradianceNodes = 65; // μs uniform in [−1, 1]
constexpr int kSinglePoints = 64;    // ray quadrature of order 1
constexpr int kMultiplePoints = 48;  // ray quadrature of orders ≥ 2

// Midpoint product rule on the sphere: θ in n bands, φ in 2n, weight sin θ Δθ Δφ.
struct SphereRule {
    std::vector<glm::dvec3> dir;
    std::vector<double> weight;
};

// The sphere integrals' rule at radius r: n polar nodes, Gauss–Legendre in
// cos θ on each interval between the nadir, the geometric horizon
// μh = −√(1 − (R0/r)²), the horizontal and the zenith (n/3 each above the
// ground, n/2 on each side of the horizon at r = R0, where μh = 0), × 2n
// azimuths. The nodes crowd towards the horizon, where a point's incoming
// light steps from the lit sky to the ground, and towards the horizontal,
// where a shadowed point high up sees the lit air beyond the terminator at
// twilight. Split at the horizontal alone (and with 16 samples), the rule
// saw the band between a point 50 km up and its horizon 7° below through
// two nodes, and the zenith there 8° after sunset came out 2.3–2.6× too
// bright; split at the horizon alone, the second order at the ground's
// zenith 16° after sunset was 3.7× too dark in blue (docs/sky.md, "At night").
SphereRule sphere_rule(int n, double mu_horizon) {
    SphereRule s;
    // Intervals of cos θ, each with its Gauss–Legendre nodes: the ground
    // [−1, μh], then the sky below the horizontal [μh, 0] where there is
    // one, then [0, 1].
    struct Span {
        double lo, hi;
        int nodes;
    };
    // Both forms hold 2·⌊n/2⌋ polar nodes (an odd n loses one), so that every
    // radius's rule has as many directions as the ground's.
    std::vector<Span> spans;
    const int half = std::max(1, n / 2); // n ≥ 4 (validated): 2·half − 2·third ≥ 2
    if (mu_horizon < -1e-9) {
        const int third = std::max(1, n / 3);
        spans = {{-1.0, mu_horizon, third}, {mu_horizon, 0.0, third}, {0.0, 1.0, 2 * half - 2 * third}};
    } else {
        spans = {{-1.0, mu_horizon, half}, {mu_horizon, 1.0, half}};
    }
    const double d = kPiD / double(n);
    for (const Span& sp : spans) {
        std::vector<double> x, w;
        gauss_legendre_unit(sp.nodes, x, w);
        const double span = sp.hi - sp.lo;
        for (int i = 0; i < sp.nodes; ++i) {
            const double c = sp.lo + span * x[std::size_t(i)];
            const double sn = std::sqrt(std::max(0.0, 1.0 - c * c));
            for (int j = 0; j < 2 * n; ++j) {
                const double ph = (double(j) + 0.5) * d;
                s.dir.emplace_back(std::cos(ph) * sn, std::sin(ph) * sn, c);
                s.weight.push_back(span * w[std::size_t(i)] * d);
            }
        }
    }
    return s;
}

// The 16 nodes and weights of a quadrilinear look-up.
// The 16 nodes of a quadrilinear look-up: weights over (r, μ, ν) for each of
// the two μs nodes (s = bit 1 of the tap), blended along μs by grid4_mus_blend.
struct Taps {
    std::size_t index[16];
    double weight[16];
    double fs = 0.0;
    int below_horizon = 0;
};

// One axis of a look-up: the lower node and the fraction.
struct Axis {
    int i = 0;
    double f = 0.0;
};

Axis axis(double x, int n) {
    Axis a;
    a.i = grid_axis(x, n, a.f);
    return a;
}

Taps taps(const Grid4Shape& g, int ground, Axis r, Axis m, Axis s_, Axis n_) {
    const int ir = r.i, im = m.i, is = s_.i, in = n_.i;
    const double fr = r.f, fm = m.f, fs = s_.f, fn = n_.f;
    Taps t;
    int q = 0;
    for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b)
            for (int s = 0; s < 2; ++s)
                for (int n = 0; n < 2; ++n, ++q) {
                    t.weight[q] = (a ? fr : 1.0 - fr) * (b ? fm : 1.0 - fm) * (n ? fn : 1.0 - fn);
                    t.index[q] = std::size_t(grid4_index(g.nmu, g.nmus, g.nnu, ir + a, ground, im + b, is + s, in + n));
                }
    t.fs = fs;
    t.below_horizon = grid4_mus_cell_below_horizon(g.x_horizon, g.nmus, is);
    return t;
}

Taps taps(const Grid4Shape& g, const Grid4Coord<double>& c) {
    return taps(g, c.ground, axis(c.xr, g.nr), axis(c.xmu, g.nmu), axis(c.xmus, g.nmus), axis(c.xnu, g.nnu));
}

glm::dvec3 apply_taps(const Taps& t, const std::vector<glm::dvec3>& v, std::size_t stride = 1, std::size_t j = 0) {
    glm::dvec3 at[2] = {glm::dvec3(0.0), glm::dvec3(0.0)};
    for (int q = 0; q < 16; ++q)
        at[(q >> 1) & 1] += t.weight[q] * v[t.index[q] * stride + j];
    glm::dvec3 s;
    for (int c = 0; c < 3; ++c)
        s[c] = grid4_mus_blend(at[0][c], at[1][c], t.fs, t.below_horizon);
    return s;
}

glm::dvec3 irradiance_lookup(const std::vector<glm::dvec3>& e, double mu_s) {
    const double x = std::clamp(0.5 * (mu_s + 1.0), 0.0, 1.0) * double(kIrradianceNodes - 1);
    const int i = std::min(int(x), kIrradianceNodes - 2);
    const double f = x - double(i);
    return (1.0 - f) * e[std::size_t(i)] + f * e[std::size_t(i) + 1];
}

} // namespace

double orders_scale(const Atmosphere& atm, double r, double mu) {
    const double R0 = atm.planet_radius_km;
    r = std::clamp(r, R0, atm.top_radius_km);
    if (mu < 0.0 && r * r * (mu * mu - 1.0) + R0 * R0 >= 0.0)
        return 1.0; // the ray meets the ground
    const double lowest = mu >= 0.0 ? r - R0 : std::max(0.0, r * std::sqrt(std::max(0.0, 1.0 - mu * mu)) - R0);
    double at = 0.0, ground = 0.0;
    for (const AtmosphereComponent& c : atm.components) {
        const double w = c.scattering_per_km.x + c.scattering_per_km.y + c.scattering_per_km.z;
        at += w * relative_density(c, lowest);
        ground += w * relative_density(c, 0.0);
    }
    return ground > 0.0 ? std::max(at / ground, 1e-30) : 1.0;
}

namespace {

// The sun direction in the frame where the view ω = (sin, 0, μ).
glm::dvec3 sun_in_view_frame(double mu, double mu_s, double nu) {
    const double s = std::sqrt(std::max(0.0, 1.0 - mu * mu));
    const double sx = s > 1e-9 ? std::clamp((nu - mu * mu_s) / s, -1.0, 1.0) : 0.0;
    return glm::dvec3(sx, std::sqrt(std::max(0.0, 1.0 - mu_s * mu_s - sx * sx)), mu_s);
}

} // namespace

void Grid4Shape::node(std::size_t index, double& r, double& mu, double& mu_s, double& nu, bool& ground) const {
    std::size_t k = index;
    const int inu = int(k % std::size_t(nnu));
    k /= std::size_t(nnu);
    const int imus = int(k % std::size_t(nmus));
    k /= std::size_t(nmus);
    const int imu = int(k % std::size_t(nmu));
    k /= std::size_t(nmu);
    const int half = int(k % 2u);
    const int ir = int(k / 2u);
    const double H = std::sqrt(Rt * Rt - R0 * R0);
    const double rho = H * double(ir) / double(nr - 1);
    r = std::sqrt(rho * rho + R0 * R0);
    const double xm = double(imu) / double(nmu - 1);
    ground = half == 1;
    if (ground) {
        const double dmin = r - R0, dmax = rho;
        const double d = dmin + xm * (dmax - dmin);
        mu = d <= 0.0 ? -1.0 : std::clamp(-(rho * rho + d * d) / (2.0 * r * d), -1.0, 1.0);
    } else {
        const double dmin = Rt - r, dmax = rho + H;
        const double d = dmin + xm * (dmax - dmin);
        mu = d <= 0.0 ? 1.0 : std::clamp((H * H - rho * rho - d * d) / (2.0 * r * d), -1.0, 1.0);
    }
    const double xs = double(imus) / double(nmus - 1);
    const double dmin = Rt - R0, dmax = H;
    const double A = (distance_to_top(R0, mu_s_min, Rt) - dmin) / (dmax - dmin);
    const double a = A * (1.0 - xs) / (1.0 + xs * A);
    const double d = dmin + std::min(a, A) * (dmax - dmin);
    mu_s = d <= 0.0 ? 1.0 : std::clamp((H * H - d * d) / (2.0 * R0 * d), -1.0, 1.0);
    nu = 2.0 * double(inu) / double(nnu - 1) - 1.0;
    const double spread = std::sqrt(std::max(0.0, (1.0 - mu * mu) * (1.0 - mu_s * mu_s)));
    nu = std::clamp(nu, mu * mu_s - spread, mu * mu_s + spread);
}

std::uint64_t ScatteringOrders::progress_units(const MultipleScatteringResolution& res, int orders) {
    const std::uint64_t n = std::uint64_t(res.r) * 2u * std::uint64_t(res.mu) * std::uint64_t(res.mu_s) *
                            std::uint64_t(res.nu);
    return n + 2u * n * std::uint64_t(orders - 1);
}

ScatteringOrders ScatteringOrders::compute(const Atmosphere& atm, const MultipleScatteringResolution& res, int orders,
                                           bool keep_orders, Progress* progress) {
    assert(orders >= 2);
    ScatteringOrders out;
    out.atmosphere_ = atm;
    out.orders_ = orders;
    Grid4Shape& g = out.shape_;
    g.nr = res.r;
    g.nmu = res.mu;
    g.nmus = res.mu_s;
    g.nnu = res.nu;
    g.R0 = atm.planet_radius_km;
    g.Rt = atm.top_radius_km;
    g.mu_s_min = res.mu_s_min;
    g.x_horizon = grid4_mus_coordinate(g.R0, g.Rt, g.mu_s_min, 0.0);

    const TransmittanceTable T(atm);
    const std::size_t N = g.nodes();
    const std::size_t K = atm.components.size();
    const double R0 = g.R0, scale = sharpest_scale_height(atm);
    const glm::dvec3 albedo_over_pi = atm.ground_albedo / kPiD;
    const SphereRule ground_rule = sphere_rule(res.sphere, 0.0); // at r = R0
    const std::size_t D = ground_rule.dir.size();
    // Each radius node's rule, split at its own horizon (the same for all its rays).
    std::vector<SphereRule> radius_rules;
    for (int ir = 0; ir < g.nr; ++ir) {
        double r, mu, mu_s, nu;
        bool ground;
        g.node(std::size_t(ir) * 2u * std::size_t(g.nmu) * std::size_t(g.nmus) * std::size_t(g.nnu), r, mu, mu_s, nu,
               ground);
        radius_rules.push_back(sphere_rule(res.sphere, -std::sqrt(std::max(0.0, 1.0 - (R0 / r) * (R0 / r)))));
        assert(radius_rules.back().dir.size() == D);
    }
    const auto phase = [&](std::size_t k, double c) {
        const AtmosphereComponent& a = atm.components[k];
        return phase_function(a.phase, a.phase_g, c);
    };
    const auto advance = [progress](std::size_t n) {
        if (progress)
            progress->advance(n);
    };
    const auto ray_length = [&](double r, double mu, bool ground) {
        return ground ? std::max(0.0, ray_ground_distance(R0, r, mu)) : ray_top_distance(g.Rt, r, mu);
    };

    // Order 1, per component, without phase.
    std::vector<glm::dvec3> single(N * K, glm::dvec3(0.0));
    parallel_for(N, 64, [&](std::size_t b, std::size_t e) {
        for (std::size_t idx = b; idx < e; ++idx) {
            double r, mu, mu_s, nu;
            bool ground;
            g.node(idx, r, mu, mu_s, nu, ground);
            for_each_ray_midpoint(R0, scale, r, mu, ray_length(r, mu, ground), kSinglePoints, [&](double t, double dt) {
                const double rt = std::max(R0, ray_radius(r, mu, t));
                const glm::dvec3 ts = T.sun(rt, std::clamp((r * mu_s + t * nu) / rt, -1.0, 1.0));
                if (ts == glm::dvec3(0.0))
                    return;
                const glm::dvec3 w = T.between(r, mu, t, ground) * ts * dt;
                for (std::size_t k = 0; k < K; ++k)
                    single[idx * K + k] += atm.components[k].scattering_per_km * relative_density(atm.components[k], rt - R0) * w;
            });
            const double f = orders_scale(atm, r, mu);
            for (std::size_t k = 0; k < K; ++k)
                single[idx * K + k] /= f;
        }
        advance(e - b);
    });

    // Radiance and ground irradiance of the previous order.
    std::vector<glm::dvec3> prev;      // order n − 1 ≥ 2
    std::vector<glm::dvec3> prev_irr;  // E_{n−1} for n − 1 ≥ 2
    // The grids hold radiance per unit of orders_scale(r, μ) (scale: its value
    // where the look-up is).
    const auto incident = [&](int order, const Taps& tp, double nu_i, double scale) {
        if (order == 1) {
            glm::dvec3 s(0.0);
            for (std::size_t k = 0; k < K; ++k)
                if (atm.components[k].phase != PhaseFunction::None)
                    s += phase(k, nu_i) * apply_taps(tp, single, K, k);
            return s * scale;
        }
        return apply_taps(tp, prev) * scale;
    };
    const auto ground_irradiance = [&](int order, double mu_s) {
        if (order == 1)
            return std::max(0.0, mu_s) * T.sun(R0, mu_s);
        return irradiance_lookup(prev_irr, mu_s);
    };

    // The air's scattering coefficient at radius r (per channel), floored:
    // J is stored per unit of it (J / σs), which is smooth in altitude where
    // J itself falls with the density, e-fold by e-fold between the radius
    // nodes (7 km apart at the top, about one scale height): interpolated
    // linearly, J was too large between them (alone, 4% of the light at
    // the 50 km zenith 8° after sunset).
    const auto scattering_at = [&](double r) {
        glm::dvec3 s(0.0);
        for (std::size_t k = 0; k < K; ++k)
            s += atm.components[k].scattering_per_km * relative_density(atm.components[k], r - R0);
        return glm::max(s, glm::dvec3(1e-30));
    };
    std::vector<float> residual(N * 3, 0.0f);
    std::vector<glm::dvec3> sum(N, glm::dvec3(0.0));
    if (keep_orders) {
        out.single_ = single;
        out.irradiance_.emplace_back(); // E_1 is not tabulated
    }
    const std::size_t rays = std::size_t(g.nr) * 2u * std::size_t(g.nmu);
    const std::size_t per_ray = std::size_t(g.nmus) * std::size_t(g.nnu);
    for (int n = 2; n <= orders; ++n) {
        // Scattering density J_n, ray by ray: the directions' geometry depends on (r, μ) only.
        std::vector<glm::dvec3> J(N, glm::dvec3(0.0));
        parallel_for(rays, 1, [&](std::size_t b, std::size_t e) {
            std::vector<glm::dvec3> weight(D), to_ground(D), ground_point(D);
            std::vector<char> hits(D);
            std::vector<Grid4Coord<double>> at(D); // the (r, μ_i) axes of each direction
            std::vector<Axis> ar(D), am(D);
            std::vector<double> scale_i(D);
            for (std::size_t ray = b; ray < e; ++ray) {
                double r, mu, mu_s, nu;
                bool ground;
                g.node(ray * per_ray, r, mu, mu_s, nu, ground);
                const SphereRule& sphere = radius_rules[ray / (2u * std::size_t(g.nmu))];
                const glm::dvec3 view(std::sqrt(std::max(0.0, 1.0 - mu * mu)), 0.0, mu);
                bool any = false;
                for (std::size_t i = 0; i < D; ++i) {
                    const glm::dvec3& wi = sphere.dir[i];
                    glm::dvec3 w(0.0);
                    for (std::size_t k = 0; k < K; ++k)
                        w += atm.components[k].scattering_per_km * relative_density(atm.components[k], r - R0) *
                             phase(k, glm::dot(view, wi));
                    weight[i] = w * sphere.weight[i];
                    any = any || w != glm::dvec3(0.0);
                    at[i] = g.coordinates(r, wi.z, 1.0, 0.0);
                    ar[i] = axis(at[i].xr, g.nr);
                    am[i] = axis(at[i].xmu, g.nmu);
                    scale_i[i] = orders_scale(atm, r, wi.z);
                    const double dg = ray_ground_distance(R0, r, wi.z);
                    hits[i] = dg >= 0.0;
                    if (hits[i]) {
                        to_ground[i] = T.between(r, wi.z, dg, true) * albedo_over_pi;
                        ground_point[i] = (glm::dvec3(0.0, 0.0, r) + dg * wi) / R0;
                    }
                }
                advance(per_ray);
                if (!any)
                    continue;
                for (std::size_t q = 0; q < per_ray; ++q) {
                    const std::size_t idx = ray * per_ray + q;
                    g.node(idx, r, mu, mu_s, nu, ground);
                    const glm::dvec3 sun = sun_in_view_frame(mu, mu_s, nu);
                    const Axis as = axis(g.coordinates(r, mu, mu_s, nu).xmus, g.nmus);
                    glm::dvec3 j(0.0);
                    for (std::size_t i = 0; i < D; ++i) {
                        const glm::dvec3& wi = sphere.dir[i];
                        const double nu_i = glm::dot(sun, wi);
                        const Axis an = axis(hd_clamp((nu_i + 1.0) * 0.5, 0.0, 1.0), g.nnu);
                        glm::dvec3 L = incident(n - 1, taps(g, at[i].ground, ar[i], am[i], as, an), nu_i, scale_i[i]);
                        if (hits[i])
                            L += to_ground[i] * ground_irradiance(n - 1, glm::dot(ground_point[i], sun));
                        j += weight[i] * L;
                    }
                    J[idx] = j / scattering_at(r);
                }
            }
        });
        // Ground irradiance E_n of the order n − 1 light.
        std::vector<glm::dvec3> irr(kIrradianceNodes, glm::dvec3(0.0));
        for (int m = 0; m < kIrradianceNodes; ++m) {
            const double mu_s = -1.0 + 2.0 * double(m) / double(kIrradianceNodes - 1);
            const glm::dvec3 sun(std::sqrt(std::max(0.0, 1.0 - mu_s * mu_s)), 0.0, mu_s);
            glm::dvec3 e(0.0);
            for (std::size_t i = 0; i < D; ++i) {
                const glm::dvec3& wi = ground_rule.dir[i];
                if (wi.z <= 0.0)
                    continue;
                const double nu_i = glm::dot(sun, wi);
                e += incident(n - 1, taps(g, g.coordinates(R0, wi.z, mu_s, nu_i)), nu_i, orders_scale(atm, R0, wi.z)) *
                     (wi.z * ground_rule.weight[i]);
            }
            irr[std::size_t(m)] = e;
        }
        // Order n: J_n along every ray.
        std::vector<glm::dvec3> cur(N, glm::dvec3(0.0));
        parallel_for(N, 64, [&](std::size_t b, std::size_t e) {
            for (std::size_t idx = b; idx < e; ++idx) {
                double r, mu, mu_s, nu;
                bool ground;
                g.node(idx, r, mu, mu_s, nu, ground);
                glm::dvec3 s(0.0);
                for_each_ray_midpoint(R0, scale, r, mu, ray_length(r, mu, ground), kMultiplePoints, [&](double t, double dt) {
                    const double rt = std::max(R0, ray_radius(r, mu, t));
                    const double mut = std::clamp((r * mu + t) / rt, -1.0, 1.0);
                    const double must = std::clamp((r * mu_s + t * nu) / rt, -1.0, 1.0);
                    s += T.between(r, mu, t, ground) * scattering_at(rt) *
                         apply_taps(taps(g, g.coordinates(rt, mut, must, nu)), J) * dt;
                });
                s /= orders_scale(atm, r, mu);
                cur[idx] = s;
                sum[idx] += s;
            }
            advance(e - b);
        });
        if (keep_orders) {
            out.multiple_.push_back(cur);
            out.irradiance_.push_back(irr);
        }
        prev = std::move(cur);
        prev_irr = std::move(irr);
    }
    for (std::size_t idx = 0; idx < N; ++idx)
        for (int c = 0; c < 3; ++c)
            residual[idx * 3 + std::size_t(c)] = float(sum[idx][c]);
    out.residual_ = std::move(residual);
    return out;
}

glm::dvec3 ScatteringOrders::order_radiance(int n, double r, double mu, double mu_s, double nu) const {
    assert(n >= 1 && n <= orders_ && !single_.empty());
    const Taps tp = taps(shape_, shape_.coordinates(r, mu, mu_s, nu));
    const double scale = orders_scale(atmosphere_, r, mu);
    if (n >= 2)
        return apply_taps(tp, multiple_[std::size_t(n - 2)]) * scale;
    const std::size_t K = atmosphere_.components.size();
    glm::dvec3 s(0.0);
    for (std::size_t k = 0; k < K; ++k) {
        const AtmosphereComponent& a = atmosphere_.components[k];
        if (a.phase != PhaseFunction::None)
            s += phase_function(a.phase, a.phase_g, nu) * apply_taps(tp, single_, K, k);
    }
    return s * scale;
}

glm::dvec3 ScatteringOrders::ground_irradiance(int n, double mu_s) const {
    assert(n >= 2 && n <= orders_ && std::size_t(n - 1) < irradiance_.size());
    return irradiance_lookup(irradiance_[std::size_t(n - 1)], mu_s);
}

} // namespace skybake::sky
