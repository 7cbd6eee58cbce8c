// Brute-force Monte Carlo path tracing of a participating medium, backwards
// from the observer: the reference of the multiple-scattering methods.
//   Free flights: delta (Woodcock) tracking, Woodcock et al. 1965; see
//     Novák et al., "Monte Carlo methods for volumetric light transport
//     simulation", Computer Graphics Forum 37(2), 2018, section 4.
//   Next-event estimation of the sun at every scattering event, with the
//   exact transmittance (adaptive quadrature, as the single-scattering reference).
//   Directions from the phase functions: a one-sample mixture over components,
//   Henyey–Greenstein proposals for the Mie-like phases, weighted by p / pdf.
//   The albedo problem of the slab: Chandrasekhar, "Radiative Transfer" (1950), ch. V.
// One loop serves both media (the atmosphere and the slab): only their
// geometry, coefficients and sun transmittance differ.
#include "skybake/sky_path_tracer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "core/parallel.h"
#include "core/random.h"
#include "skybake/error.h"
#include "sky/internal.h"

namespace skybake {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kMaxComponents = 4;
// A path whose weight falls below this plays Russian roulette.
constexpr double kRouletteWeight = 0.25;
// Attempts of the forced first collision before giving up (1 / (1 − T) are expected).
constexpr std::uint64_t kMaxForcedAttempts = 1u << 24;

// [SECTION] Phase functions: values and proposals ----------------------------------

double henyey_greenstein(double g, double c) {
    const double d = 1.0 + g * g - 2.0 * g * c;
    return (1.0 - g * g) / (4.0 * kPi * d * std::sqrt(d));
}

// cos θ with density (3/8)(1 + cos²θ): the real root of c³ + 3c − (8u − 4) = 0 (Cardano).
double sample_rayleigh_cos(double u) {
    const double z = 4.0 * u - 2.0;
    const double s = std::sqrt(z * z + 1.0);
    return std::clamp(std::cbrt(z + s) + std::cbrt(z - s), -1.0, 1.0);
}

// cos θ with the Henyey–Greenstein density (inversion of its CDF).
double sample_hg_cos(double g, double u) {
    if (std::abs(g) < 1e-6)
        return 2.0 * u - 1.0;
    const double q = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
    return std::clamp((1.0 + g * g - q * q) / (2.0 * g), -1.0, 1.0);
}

enum class Lobe { Isotropic, Rayleigh, HenyeyGreenstein };

struct Phase {
    Lobe proposal = Lobe::Isotropic;
    PhaseFunction function = PhaseFunction::None; // Lobe::Isotropic: the constant 1/(4π)
    double g = 0.0;

    double value(double c) const {
        return proposal == Lobe::Isotropic && function == PhaseFunction::None ? 1.0 / (4.0 * kPi)
                                                                              : phase_function(function, g, c);
    }
    double pdf(double c) const {
        switch (proposal) {
        case Lobe::Isotropic: return 1.0 / (4.0 * kPi);
        case Lobe::Rayleigh: return 3.0 / (16.0 * kPi) * (1.0 + c * c);
        case Lobe::HenyeyGreenstein: return henyey_greenstein(g, c);
        }
        return 0.0;
    }
    double sample(double u) const {
        switch (proposal) {
        case Lobe::Isotropic: return 2.0 * u - 1.0;
        case Lobe::Rayleigh: return sample_rayleigh_cos(u);
        case Lobe::HenyeyGreenstein: return sample_hg_cos(g, u);
        }
        return 1.0;
    }
};

Phase proposal_for(PhaseFunction f, double g) {
    Phase p;
    p.function = f;
    p.g = g;
    p.proposal = f == PhaseFunction::Rayleigh ? Lobe::Rayleigh : Lobe::HenyeyGreenstein;
    return p;
}

// The unit vector at angle acos(c) from n, azimuth phi.
glm::dvec3 around(const glm::dvec3& n, double c, double phi) {
    const glm::dvec3 a = std::abs(n.x) > 0.9 ? glm::dvec3(0.0, 1.0, 0.0) : glm::dvec3(1.0, 0.0, 0.0);
    const glm::dvec3 t = glm::normalize(glm::cross(n, a));
    const glm::dvec3 b = glm::cross(n, t);
    const double s = std::sqrt(std::max(0.0, 1.0 - c * c));
    return glm::normalize(s * std::cos(phi) * t + s * std::sin(phi) * b + c * n);
}

double free_path(double majorant, SplitMix64& rng) { return -std::log1p(-rng.uniform()) / majorant; }

// [SECTION] The media ---------------------------------------------------------------
//
// A medium answers: the segment of a ray inside it (and whether it ends on a
// ground), a majorant of σt, σt and the per-component σs at a point, the phase
// of each component, the sun's direction and transmittance to a point, and
// the ground's albedo.

struct AtmosphereMedium {
    const Atmosphere* atm = nullptr;
    int channel = 0;
    glm::dvec3 sun{0.0, 0.0, 1.0};
    int count = 0;
    std::array<double, kMaxComponents> sigma_s{}, sigma_t{};
    std::array<Phase, kMaxComponents> phase{};
    double majorant = 0.0, ground_albedo = 0.0;

    AtmosphereMedium(const Atmosphere& a, int c, const glm::dvec3& sun_dir) : atm(&a), channel(c), sun(sun_dir) {
        count = int(a.components.size());
        for (int k = 0; k < count; ++k) {
            const AtmosphereComponent& comp = a.components[std::size_t(k)];
            sigma_s[std::size_t(k)] = comp.phase == PhaseFunction::None ? 0.0 : comp.scattering_per_km[c];
            sigma_t[std::size_t(k)] = comp.extinction_per_km[c];
            phase[std::size_t(k)] = proposal_for(comp.phase, comp.phase_g);
            majorant += sigma_t[std::size_t(k)]; // every profile peaks at relative density 1
        }
        ground_albedo = a.ground_albedo[c];
    }
    bool segment(const glm::dvec3& x, const glm::dvec3& d, double& enter, double& exit, bool& ground) const {
        return sky::atmosphere_segment(*atm, x, d, enter, exit, ground);
    }
    // σt at x; ws[k] = σs of component k at x.
    double at(const glm::dvec3& x, double* ws) const {
        const double h = glm::length(x) - atm->planet_radius_km;
        double st = 0.0;
        for (int k = 0; k < count; ++k) {
            const double rho = relative_density(atm->components[std::size_t(k)], h);
            ws[k] = sigma_s[std::size_t(k)] * rho;
            st += sigma_t[std::size_t(k)] * rho;
        }
        return st;
    }
    double sun_transmittance(const glm::dvec3& x) const {
        double enter, exit;
        bool ground;
        if (!segment(x, sun, enter, exit, ground))
            return 1.0;
        if (ground)
            return 0.0;
        return std::exp(-sky::optical_depth_exact(*atm, x, sun, enter, exit, 1e-7)[channel]);
    }
    // A point where the ray met the ground, put back on it, and its normal.
    void on_ground(glm::dvec3& x, glm::dvec3& n) const {
        n = glm::normalize(x);
        x = n * (atm->planet_radius_km * (1.0 + 1e-12));
    }
};

// z ≤ 0 holds a constant medium, σt = 1 (lengths in optical depth), σs = ϖ, isotropic.
struct SlabMediumImpl {
    glm::dvec3 sun{0.0, 0.0, 1.0};
    int count = 1;
    std::array<Phase, 1> phase{Phase{}};
    double albedo = 0.9, majorant = 1.0, ground_albedo = 0.0;

    bool segment(const glm::dvec3& x, const glm::dvec3& d, double& enter, double& exit, bool& ground) const {
        ground = false;
        enter = 0.0;
        if (x.z > 0.0) {
            if (d.z >= 0.0)
                return false;
            enter = -x.z / d.z;
        }
        exit = d.z > 0.0 ? -x.z / d.z : kInf;
        return exit > enter;
    }
    double at(const glm::dvec3&, double* ws) const {
        ws[0] = albedo;
        return 1.0;
    }
    double sun_transmittance(const glm::dvec3& x) const { return std::exp(std::min(0.0, x.z) / sun.z); }
    void on_ground(glm::dvec3&, glm::dvec3& n) const { n = glm::dvec3(0.0, 0.0, 1.0); }
};

// [SECTION] The path ---------------------------------------------------------------

struct PrimaryRay {
    glm::dvec3 origin{0.0}, dir{0.0, 0.0, 1.0};
    double enter = 0.0, exit = 0.0;
    double collision_probability = 0.0; // 1 − T over [enter, exit], exact
};

// Delta tracking from x along d over [t0, t1): the distance of the first real
// collision, or +inf when the flight leaves the segment.
template <class M>
double track(const M& m, const glm::dvec3& x, const glm::dvec3& d, double t0, double t1, SplitMix64& rng) {
    double ws[kMaxComponents] = {};
    double t = t0;
    for (;;) {
        t += free_path(m.majorant, rng);
        if (!(t < t1))
            return kInf;
        const double st = m.at(x + t * d, ws);
        if (rng.uniform() * m.majorant < st)
            return t;
    }
}

// Survives with probability β / kRouletteWeight when β is below it.
bool roulette(double& beta, SplitMix64& rng) {
    if (beta >= kRouletteWeight)
        return true;
    if (!(beta > 0.0))
        return false;
    if (rng.uniform() * kRouletteWeight >= beta)
        return false;
    beta = kRouletteWeight;
    return true;
}

// One path's estimate of orders min_order..max_order.
template <class M>
double trace_path(const M& m, const PrimaryRay& ray, const PathTracerOptions& opt, SplitMix64& rng) {
    if (!(ray.collision_probability > 0.0))
        return 0.0;
    // The first collision, forced onto the view segment by rejection: its
    // distribution is the analog one conditioned on colliding there.
    double t = kInf;
    for (std::uint64_t attempt = 0; !(t < kInf); ++attempt) {
        if (attempt == kMaxForcedAttempts)
            throw Error("the view ray is too thin to force a collision in it", "path tracer");
        t = track(m, ray.origin, ray.dir, ray.enter, ray.exit, rng);
    }
    glm::dvec3 x = ray.origin + t * ray.dir, d = ray.dir;
    double beta = ray.collision_probability;
    double L = 0.0;
    int order = 0;
    double ws[kMaxComponents] = {};
    for (;;) {
        // A real collision at x, arriving along d.
        ++order;
        const double st = m.at(x, ws);
        double ss = 0.0;
        for (int k = 0; k < m.count; ++k)
            ss += ws[k];
        if (!(ss > 0.0) || !(st > 0.0))
            return L;
        if (order >= opt.min_order) {
            const double c = glm::dot(d, m.sun);
            double p = 0.0;
            for (int k = 0; k < m.count; ++k)
                p += ws[k] * m.phase[std::size_t(k)].value(c);
            const double ts = p > 0.0 ? m.sun_transmittance(x) : 0.0;
            L += beta * (p / st) * ts; // β ϖ Σ (σs_k/σs) p_k T_sun
        }
        if (order >= opt.max_order)
            return L;
        beta *= ss / st;
        // A new direction from the phase mixture.
        double u = rng.uniform() * ss;
        int pick = m.count - 1;
        for (int k = 0; k < m.count; ++k) {
            if (u < ws[k]) {
                pick = k;
                break;
            }
            u -= ws[k];
        }
        const double c = m.phase[std::size_t(pick)].sample(rng.uniform());
        double value = 0.0, pdf = 0.0;
        for (int k = 0; k < m.count; ++k) {
            value += ws[k] * m.phase[std::size_t(k)].value(c);
            pdf += ws[k] * m.phase[std::size_t(k)].pdf(c);
        }
        beta *= value / pdf;
        d = around(d, c, 2.0 * kPi * rng.uniform());
        if (!roulette(beta, rng))
            return L;

        // Flights (and ground bounces) until the next collision in the medium.
        for (;;) {
            double enter, exit;
            bool ground;
            if (!m.segment(x, d, enter, exit, ground))
                return L;
            const double tc = track(m, x, d, enter, exit, rng);
            if (tc < kInf) {
                x += tc * d;
                break;
            }
            if (!ground)
                return L; // escaped to space
            x += exit * d;
            glm::dvec3 n;
            m.on_ground(x, n);
            ++order;
            const double cs = glm::dot(n, m.sun);
            if (order >= opt.min_order && cs > 0.0)
                L += beta * (m.ground_albedo / kPi) * cs * m.sun_transmittance(x);
            if (order >= opt.max_order)
                return L;
            beta *= m.ground_albedo;
            // Cosine-weighted: BRDF · cos / pdf = albedo.
            const double u1 = rng.uniform();
            d = around(n, std::sqrt(u1), 2.0 * kPi * rng.uniform());
            if (!roulette(beta, rng))
                return L;
        }
    }
}

struct Moments {
    std::array<double, 3> sum{}, sum_sq{};
};

void check_options(const PathTracerOptions& o) {
    if (o.paths < 2)
        throw Error("paths must be at least 2", "path tracer");
    if (o.min_order < 1)
        throw Error("min_order must be at least 1", "path tracer");
    if (o.max_order < o.min_order)
        throw Error("max_order must be at least min_order", "path tracer");
}

// Runs make(channel) -> (medium, primary ray) paths for every channel in parallel.
template <class MakeMedium>
PathTracedRadiance run_paths(const PathTracerOptions& opt, int channels, MakeMedium make) {
    using Medium = decltype(make(0).first);
    std::vector<std::pair<Medium, PrimaryRay>> setup;
    for (int c = 0; c < channels; ++c)
        setup.push_back(make(c));
    const std::uint64_t base = splitmix64(opt.seed);
    const Moments m = parallel_reduce_chunks(
        std::size_t(opt.paths), 256, Moments{},
        [&](std::size_t b, std::size_t e) {
            Moments part;
            for (std::size_t i = b; i < e; ++i) {
                for (int c = 0; c < channels; ++c) {
                    SplitMix64 rng{splitmix64(base + std::uint64_t(i) * 3u + std::uint64_t(c))};
                    const double v = trace_path(setup[std::size_t(c)].first, setup[std::size_t(c)].second, opt, rng);
                    part.sum[std::size_t(c)] += v;
                    part.sum_sq[std::size_t(c)] += v * v;
                }
            }
            return part;
        },
        [](Moments a, const Moments& b) {
            for (std::size_t c = 0; c < 3; ++c) {
                a.sum[c] += b.sum[c];
                a.sum_sq[c] += b.sum_sq[c];
            }
            return a;
        });
    PathTracedRadiance out;
    out.paths = opt.paths;
    const double n = double(opt.paths);
    for (int c = 0; c < 3; ++c) {
        const int src = channels == 1 ? 0 : c;
        const double mean = m.sum[std::size_t(src)] / n;
        const double var = std::max(0.0, (m.sum_sq[std::size_t(src)] - n * mean * mean) / (n - 1.0));
        out.mean[c] = mean;
        out.standard_error[c] = std::sqrt(var / n);
    }
    return out;
}

bool in_unit(double v) { return std::isfinite(v) && v >= -1.0 && v <= 1.0; }

} // namespace

PathTracedRadiance path_trace_sky(const Atmosphere& atm, double radius_km, double cv, double cvs, double cs,
                                  const PathTracerOptions& opt) {
    atm.validate();
    check_options(opt);
    if (int(atm.components.size()) > kMaxComponents)
        throw Error(fmt::format("at most {} components", kMaxComponents), "path tracer");
    if (!std::isfinite(radius_km) || radius_km < atm.planet_radius_km)
        throw Error("radius_km must be finite and on or above the ground", "path tracer");
    if (!in_unit(cv) || !in_unit(cvs) || !in_unit(cs) || !is_valid_cosine_triple(cv, cvs, cs))
        throw Error("the view, view–sun and sun cosines are not a valid triple", "path tracer");

    // The frame of SkyModel's exact reference: vertical z, V in the x–z plane.
    const double sv = std::sqrt(std::max(0.0, 1.0 - cv * cv));
    const double ss = std::sqrt(std::max(0.0, 1.0 - cs * cs));
    double cphi = 1.0;
    if (sv * ss > 1e-12)
        cphi = std::clamp((cvs - cv * cs) / (sv * ss), -1.0, 1.0);
    const glm::dvec3 V(sv, 0.0, cv);
    const glm::dvec3 L(ss * cphi, ss * std::sqrt(std::max(0.0, 1.0 - cphi * cphi)), cs);
    const glm::dvec3 O(0.0, 0.0, radius_km);

    PrimaryRay ray;
    ray.origin = O;
    ray.dir = V;
    bool ground = false;
    glm::dvec3 p(0.0);
    if (sky::atmosphere_segment(atm, O, V, ray.enter, ray.exit, ground))
        p = glm::dvec3(1.0) - glm::exp(-sky::optical_depth_exact(atm, O, V, ray.enter, ray.exit, 1e-12));
    for (int c = 0; c < 3; ++c)
        if (p[c] > 0.0 && p[c] < 1e-6)
            throw Error("the view ray's optical depth is below 1e-6: too thin to trace a collision in it",
                        "path tracer");
    return run_paths(opt, 3, [&](int c) {
        PrimaryRay r = ray;
        r.collision_probability = p[c];
        return std::make_pair(AtmosphereMedium(atm, c, L), r);
    });
}

PathTracedRadiance path_trace_slab_reflection(const SlabMedium& slab, double mu_view, double mu_sun,
                                              const PathTracerOptions& opt) {
    check_options(opt);
    const double w = slab.single_scattering_albedo;
    if (!std::isfinite(w) || w <= 0.0 || w > 1.0)
        throw Error("single_scattering_albedo must be in (0, 1]", "slab");
    if (!std::isfinite(mu_view) || mu_view <= 0.0 || mu_view > 1.0)
        throw Error("mu_view must be in (0, 1]", "slab");
    if (!std::isfinite(mu_sun) || mu_sun <= 0.0 || mu_sun > 1.0)
        throw Error("mu_sun must be in (0, 1]", "slab");
    if (w == 1.0 && opt.max_order > 100000)
        throw Error("a conservative slab (albedo 1) needs max_order ≤ 100000", "slab");
    return run_paths(opt, 1, [&](int) {
        SlabMediumImpl m;
        m.albedo = w;
        m.sun = glm::dvec3(std::sqrt(std::max(0.0, 1.0 - mu_sun * mu_sun)), 0.0, mu_sun);
        PrimaryRay r;
        r.origin = glm::dvec3(0.0);
        r.dir = glm::dvec3(std::sqrt(std::max(0.0, 1.0 - mu_view * mu_view)), 0.0, -mu_view);
        r.enter = 0.0;
        r.exit = kInf;
        r.collision_probability = 1.0;
        return std::make_pair(m, r);
    });
}

} // namespace skybake
