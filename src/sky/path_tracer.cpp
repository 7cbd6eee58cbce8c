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
#include "sky/planet_shadow_hd.h"
#include "sky/quadrature.h"

namespace skybake {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kMaxComponents = 4;
// A path whose weight falls below this plays Russian roulette.
constexpr double kRouletteWeight = 0.25;
// Attempts of the forced first collision before giving up (1 / (1 − T) are expected).
constexpr std::uint64_t kMaxForcedAttempts = 1u << 24;
// NextEvent::SunlitAir: the twilight
// guide's band (half its azimuth span, how far below the horizon's dip and how
// far above the horizontal it reaches) and its share of the direction samples.
constexpr double kGuideAzimuth = 1.0471975511965976; // 60°
constexpr double kGuideBelow = 0.03490658503988659;  // 2°
constexpr double kGuideTop = 0.10471975511965977;    // 6°
constexpr double kGuideShare = 0.5;
// ... and the share of first collisions drawn uniformly along the view segment.
constexpr double kUniformShare = 0.5;
// Beyond this optical depth a ray's remaining light is below e^-60: not integrated.
constexpr double kDarkDepth = 60.0;
// 8-point Gauss–Legendre on [0, 1]: (node, weight).
const std::array<std::pair<double, double>, 8> kGauss = [] {
    std::vector<double> x, w;
    sky::gauss_legendre_unit(8, x, w);
    std::array<std::pair<double, double>, 8> g{};
    for (std::size_t i = 0; i < 8; ++i)
        g[i] = {x[i], w[i]};
    return g;
}();

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
    double majorant = 0.0, ground_albedo = 0.0, scale = 1.0;

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
        scale = sky::profile_scale(a);
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
    // The light arriving at x from direction d after one scattering in the
    // air along that ray or, with `ground_too`, one reflection of the sun
    // where the ray ends on the ground. Only the ray's sunlit part is
    // integrated (the planet's shadow in closed form), by Gauss–Legendre on
    // panels graded around its ends, the tangent point and the shadow's
    // edges, with the view's optical depth carried from panel to panel and
    // the sun's by the same rule: this channel only, a few hundred
    // microseconds, within 1.5e-4 of the adaptive quadrature
    // (PathTracerSunlitAir tests).
    double sunlit_air(const glm::dvec3& x, const glm::dvec3& d, bool ground_too) const {
        double enter, exit;
        bool ground;
        if (!segment(x, d, enter, exit, ground))
            return 0.0;
        const glm::dvec3 o = x + enter * d;
        const double len = exit - enter, r = glm::length(o);
        const glm::dvec3 up = o / r;
        const double nu = glm::dot(d, sun);
        const sky::ShadowInterval<double> sh =
            sky::planet_shadow_interval(r, atm->planet_radius_km, glm::dot(up, d), nu, glm::dot(up, sun));
        const bool shadowed = sh.t0 <= sh.t1;
        const bool with_ground = ground && ground_too && ground_albedo > 0.0;
        if (shadowed && sh.t0 <= 0.0 && sh.t1 >= len && !with_ground)
            return 0.0; // all of it in the shadow
        std::array<double, kMaxComponents> scatter{};
        for (int k = 0; k < count; ++k)
            scatter[std::size_t(k)] = sigma_s[std::size_t(k)] * phase[std::size_t(k)].value(nu);
        const sky::RayAltitude alt(atm->planet_radius_km, o, d);
        std::vector<double> centres{0.0, len, alt.tangent()}, edges;
        if (shadowed)
            for (const double e : {sh.t0, sh.t1})
                if (e > 0.0 && e < len) {
                    centres.push_back(e);
                    edges.push_back(e);
                }
        const std::vector<double> pts = sky::graded_breakpoints(0.0, len, centres, scale, edges);
        double tau = 0.0, sum = 0.0;
        for (std::size_t i = 0; i + 1 < pts.size() && tau < kDarkDepth; ++i) {
            const double a = pts[i], b = pts[i + 1], mid = 0.5 * (a + b);
            if (!(shadowed && mid > sh.t0 && mid < sh.t1)) {
                for (std::size_t j = 0; j < kGauss.size(); ++j) {
                    const double v = a + (b - a) * kGauss[j].first;
                    const double h = alt(v);
                    double w = 0.0;
                    for (int k = 0; k < count; ++k)
                        w += scatter[std::size_t(k)] * relative_density(atm->components[std::size_t(k)], h);
                    if (w > 0.0)
                        sum += (b - a) * kGauss[j].second * w * std::exp(-tau - depth(alt, a, v)) *
                               sun_transmittance_graded(o + v * d);
                }
            }
            tau += depth(alt, a, b);
        }
        if (with_ground && tau < kDarkDepth) {
            glm::dvec3 g = o + len * d, n;
            on_ground(g, n);
            const double cs = glm::dot(n, sun);
            if (cs > 0.0)
                sum += std::exp(-tau) * (ground_albedo / kPi) * cs * sun_transmittance_graded(g);
        }
        return sum;
    }
    // This channel's optical depth over [a, b] of the ray whose altitude is
    // alt: one Gauss–Legendre panel (b − a within a graded panel).
    double depth(const sky::RayAltitude& alt, double a, double b) const {
        double s = 0.0;
        for (const auto& [u, w] : kGauss) {
            const double h = alt(a + (b - a) * u);
            double e = 0.0;
            for (int k = 0; k < count; ++k)
                e += sigma_t[std::size_t(k)] * relative_density(atm->components[std::size_t(k)], h);
            s += w * e;
        }
        return (b - a) * s;
    }
    // This channel's optical depth over [a, b] of origin + t d, by the graded rule.
    double optical_depth(const glm::dvec3& origin, const glm::dvec3& d, double a, double b) const {
        const sky::RayAltitude alt(atm->planet_radius_km, origin, d);
        const std::vector<double> pts = sky::graded_breakpoints(a, b, {a, b, alt.tangent()}, scale);
        double tau = 0.0;
        for (std::size_t i = 0; i + 1 < pts.size(); ++i)
            tau += depth(alt, pts[i], pts[i + 1]);
        return tau;
    }
    // The sun's transmittance to p by the graded Gauss–Legendre rule.
    double sun_transmittance_graded(const glm::dvec3& p) const {
        double enter, exit;
        bool ground;
        if (!segment(p, sun, enter, exit, ground))
            return 1.0;
        if (ground)
            return 0.0;
        return std::exp(-optical_depth(p, sun, enter, exit));
    }
    // Twilight guide: where the sun is below x's horizon, the lit air lies
    // near the horizon towards the sun. The band: azimuths within
    // kGuideAzimuth of the sun's, elevations from 2° below the geometric
    // horizon's dip to kGuideTop, uniform in solid angle.
    struct Band {
        glm::dvec3 up, toward, side;
        double sin_low = 0.0, sin_high = 0.0;
        double pdf() const { return 1.0 / (2.0 * kGuideAzimuth * (sin_high - sin_low)); }
    };
    bool guide(const glm::dvec3& x, Band& b) const {
        b.up = glm::normalize(x);
        if (glm::dot(b.up, sun) >= 0.0)
            return false;
        const glm::dvec3 h = sun - glm::dot(sun, b.up) * b.up;
        if (glm::dot(h, h) < 1e-20)
            return false; // the sun at the nadir: no azimuth to favour
        b.toward = glm::normalize(h);
        b.side = glm::cross(b.up, b.toward);
        const double dip = std::acos(std::min(1.0, atm->planet_radius_km / glm::length(x)));
        b.sin_low = std::sin(-dip - kGuideBelow);
        b.sin_high = std::sin(kGuideTop);
        return true;
    }
    static glm::dvec3 band_sample(const Band& b, double u1, double u2) {
        const double se = b.sin_low + u1 * (b.sin_high - b.sin_low);
        const double ce = std::sqrt(std::max(0.0, 1.0 - se * se));
        const double phi = (2.0 * u2 - 1.0) * kGuideAzimuth;
        return glm::normalize(ce * (std::cos(phi) * b.toward + std::sin(phi) * b.side) + se * b.up);
    }
    static double band_pdf(const Band& b, const glm::dvec3& d) {
        const double se = glm::dot(d, b.up);
        if (se < b.sin_low || se > b.sin_high)
            return 0.0;
        const double phi = std::atan2(glm::dot(d, b.side), glm::dot(d, b.toward));
        return std::abs(phi) <= kGuideAzimuth ? b.pdf() : 0.0;
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
    // ∫ e^{−t} (ϖ/4π) e^{z(t)/μ0} dt from x along d until it leaves the slab: closed form.
    double sunlit_air(const glm::dvec3& x, const glm::dvec3& d, bool) const {
        const double z0 = std::min(0.0, x.z);
        const double a = 1.0 - d.z / sun.z;
        double integral = 0.0;
        if (d.z > 0.0) {
            const double t_max = -z0 / d.z;
            integral = std::abs(a) * t_max < 1e-12 ? t_max : -std::expm1(-a * t_max) / a;
        } else {
            integral = 1.0 / a;
        }
        return albedo / (4.0 * kPi) * std::exp(z0 / sun.z) * integral;
    }
    double optical_depth(const glm::dvec3&, const glm::dvec3&, double a, double b) const { return b - a; }
    struct Band {
        double pdf() const { return 0.0; }
    };
    bool guide(const glm::dvec3&, Band&) const { return false; }
    static glm::dvec3 band_sample(const Band&, double, double) { return glm::dvec3(0.0, 0.0, 1.0); }
    static double band_pdf(const Band&, const glm::dvec3&) { return 0.0; }
};

// [SECTION] The path ---------------------------------------------------------------

struct PrimaryRay {
    glm::dvec3 origin{0.0}, dir{0.0, 0.0, 1.0};
    double enter = 0.0, exit = 0.0;
    double collision_probability = 0.0; // 1 − T over [enter, exit], exact
    double first_order = 0.0;           // NextEvent::SunlitAir: the view ray's own single scattering
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

// Survives with probability β / (kRouletteWeight β0) when β is below
// kRouletteWeight β0, β0 the weight the path started with: the forced first
// collision in a thin view ray starts paths at its collision probability
// (1e-3 for the zenith from 50 km), and a roulette against an absolute
// weight ended all but a few of them there.
bool roulette(double& beta, double beta0, SplitMix64& rng) {
    const double floor = kRouletteWeight * beta0;
    if (beta >= floor)
        return true;
    if (!(beta > 0.0))
        return false;
    if (rng.uniform() * floor >= beta)
        return false;
    beta = floor;
    return true;
}

// One path's estimate of orders min_order..max_order.
template <class M>
double trace_path(const M& m, const PrimaryRay& ray, const PathTracerOptions& opt, SplitMix64& rng) {
    const bool sunlit = opt.next_event == NextEvent::SunlitAir;
    // In sunlit-air mode the view ray's own first order is its quadrature,
    // the same for every path; each event then adds the order after it.
    double L = sunlit && opt.min_order <= 1 ? ray.first_order : 0.0;
    if (!(ray.collision_probability > 0.0))
        return L;
    const auto counted = [&](int order) { return order >= opt.min_order && order <= opt.max_order; };
    // The first collision, forced onto the view segment by rejection: its
    // distribution is the analog one conditioned on colliding there. In
    // sunlit-air mode, on a finite segment, half the first collisions are
    // uniform along it instead: at twilight the light comes to the view ray
    // high up, where the analog collisions are few.
    const bool mix_uniform = sunlit && std::isfinite(ray.exit) && ray.exit > ray.enter;
    double t = kInf;
    if (mix_uniform && rng.uniform() < kUniformShare) {
        t = ray.enter + rng.uniform() * (ray.exit - ray.enter);
    } else {
        for (std::uint64_t attempt = 0; !(t < kInf); ++attempt) {
            if (attempt == kMaxForcedAttempts)
                throw Error("the view ray is too thin to force a collision in it", "path tracer");
            t = track(m, ray.origin, ray.dir, ray.enter, ray.exit, rng);
        }
    }
    glm::dvec3 x = ray.origin + t * ray.dir, d = ray.dir;
    double beta = ray.collision_probability;
    double ws[kMaxComponents] = {};
    if (mix_uniform) {
        // β = σt T / q, q the mixture's density at t (the analog one is σt T / P).
        const double analog = m.at(x, ws) * std::exp(-m.optical_depth(ray.origin, ray.dir, ray.enter, t));
        const double q = (1.0 - kUniformShare) * analog / ray.collision_probability +
                         kUniformShare / (ray.exit - ray.enter);
        beta = analog / q;
    }
    const double beta0 = beta;
    int order = 0;
    for (;;) {
        // A real collision at x, arriving along d.
        ++order;
        const double st = m.at(x, ws);
        double ss = 0.0;
        for (int k = 0; k < m.count; ++k)
            ss += ws[k];
        if (!(ss > 0.0) || !(st > 0.0))
            return L;
        if (!sunlit && counted(order)) {
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
        // A new direction: from the phase mixture, or (in the shadow, sunlit-air
        // mode) from the twilight band with probability kGuideShare.
        typename M::Band band;
        const bool guided = sunlit && m.guide(x, band);
        glm::dvec3 next;
        double c = 0.0;
        if (guided && rng.uniform() < kGuideShare) {
            const double u1 = rng.uniform();
            next = M::band_sample(band, u1, rng.uniform());
        } else {
            double u = rng.uniform() * ss;
            int pick = m.count - 1;
            for (int k = 0; k < m.count; ++k) {
                if (u < ws[k]) {
                    pick = k;
                    break;
                }
                u -= ws[k];
            }
            c = m.phase[std::size_t(pick)].sample(rng.uniform());
            next = around(d, c, 2.0 * kPi * rng.uniform());
        }
        if (guided)
            c = std::clamp(glm::dot(d, next), -1.0, 1.0);
        double value = 0.0, pdf = 0.0;
        for (int k = 0; k < m.count; ++k) {
            value += ws[k] * m.phase[std::size_t(k)].value(c);
            pdf += ws[k] * m.phase[std::size_t(k)].pdf(c);
        }
        if (guided)
            pdf = (1.0 - kGuideShare) * pdf + kGuideShare * ss * M::band_pdf(band, next);
        beta *= value / pdf;
        d = next;
        if (sunlit && counted(order + 1))
            L += beta * m.sunlit_air(x, d, true);
        if (!roulette(beta, beta0, rng))
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
            if (!sunlit && counted(order) && cs > 0.0)
                L += beta * (m.ground_albedo / kPi) * cs * m.sun_transmittance(x);
            if (order >= opt.max_order)
                return L;
            beta *= m.ground_albedo;
            // Cosine-weighted: BRDF · cos / pdf = albedo.
            const double u1 = rng.uniform();
            d = around(n, std::sqrt(u1), 2.0 * kPi * rng.uniform());
            if (sunlit && counted(order + 1) && beta > 0.0)
                L += beta * m.sunlit_air(x, d, true);
            if (!roulette(beta, beta0, rng))
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
        AtmosphereMedium m(atm, c, L);
        if (opt.next_event == NextEvent::SunlitAir)
            r.first_order = m.sunlit_air(O, V, false);
        return std::make_pair(m, r);
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
        if (opt.next_event == NextEvent::SunlitAir)
            r.first_order = m.sunlit_air(r.origin, r.dir, false);
        return std::make_pair(m, r);
    });
}

} // namespace skybake
