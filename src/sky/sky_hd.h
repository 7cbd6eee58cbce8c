// Per-sample maths of the sky model, shared by the CPU and a CUDA evaluator.
//
// Nishita T., Sirai T., Tadamura K., Nakamae E. Display of the Earth Taking
// into Account Atmospheric Scattering. SIGGRAPH 1993 (single scattering).
// Pietras K., Rudnicki M. GPU-based multi-layer perceptron as efficient method
// for approximation complex light models in per-vertex lighting (seed 000),
// sections I (optical-length tables), II (the marching sum), V (components).
//
// Everything here works on plain structs and flat float arrays, in float,
// so that it compiles unchanged under nvcc (SKYBAKE_HD).
#pragma once

#include <cmath>

#include <glm/vec3.hpp>

#include "core/hd.h"
#include "sky/multiple_hd.h"

namespace skybake::sky {

constexpr int kMaxComponents = 4;
constexpr float kPi = 3.14159265358979f;

// Values of skybake::PhaseFunction / DensityProfile, kept as ints here.
enum : int { kPhaseNone = 0, kPhaseRayleigh = 1, kPhaseHG = 2, kPhaseCornetteShanks = 3, kPhasePietrasRudnickiMie = 4 };
enum : int { kProfileExponential = 0, kProfileTent = 1, kProfileConstant = 2 };
// Height coordinate of a table's rows.
enum : int { kAxisDensity = 0, kAxisAltitude = 1 };

// One optical-length table L[row][col]; rows u_i = i/(rows-1), columns c_j = j/(cols-1).
struct TableHD {
    const float* L = nullptr;
    int rows = 0;
    int cols = 0;
};

struct ComponentHD {
    int profile = kProfileExponential;
    float inv_scale_height = 1.0f;   // 1/km (Exponential)
    float tent_center = 25.0f;       // km (Tent)
    float inv_tent_half_width = 1.0f; // 1/km (Tent)
    glm::vec3 sca{0.0f};             // 1/km at ρ = 1
    glm::vec3 ext{0.0f};             // 1/km at ρ = 1
    int phase = kPhaseNone;
    float g = 0.0f;
    int axis = kAxisDensity;
    TableHD table;
};

struct AtmosphereHD {
    float R0 = 6360.0f;   // planet radius, km
    float Rtop = 6420.0f; // top of the atmosphere, km
    int count = 0;
    ComponentHD comp[kMaxComponents];
    MultipleHD ms; // multiple scattering (method kMultipleNone: single scattering only)
};

// ---- phase functions (1/sr), mu = cos(angle between V and L) ------------------
SKYBAKE_HD_INLINE float phase_value(int kind, float g, float mu) {
    const float inv4pi = 0.25f / kPi;
    switch (kind) {
    case kPhaseRayleigh:
        return 3.0f / (16.0f * kPi) * (1.0f + mu * mu);
    case kPhaseHG: {
        const float d = 1.0f + g * g - 2.0f * g * mu;
        return inv4pi * (1.0f - g * g) / (d * sqrtf(d));
    }
    case kPhaseCornetteShanks: {
        const float d = 1.0f + g * g - 2.0f * g * mu;
        return 3.0f * (1.0f - g * g) * (1.0f + mu * mu) / (8.0f * kPi * (2.0f + g * g) * d * sqrtf(d));
    }
    case kPhasePietrasRudnickiMie: {
        const float d = 1.0f + g * g - 2.0f * g * mu;
        return (1.0f - g * g) / (16.0f * kPi * d * sqrtf(d));
    }
    default:
        return 0.0f;
    }
}

// ---- density profiles -----------------------------------------------------------
SKYBAKE_HD_INLINE float component_density(const ComponentHD& c, float altitude_km) {
    switch (c.profile) {
    case kProfileExponential:
        return expf(-altitude_km * c.inv_scale_height);
    case kProfileTent: {
        const float t = 1.0f - fabsf(altitude_km - c.tent_center) * c.inv_tent_half_width;
        return t > 0.0f ? t : 0.0f;
    }
    default:
        return 1.0f;
    }
}

// Table row coordinate u in [0, 1] of a point at altitude_km with density rho.
SKYBAKE_HD_INLINE float table_coordinate(const AtmosphereHD& a, const ComponentHD& c, float altitude_km, float rho) {
    if (c.axis == kAxisDensity)
        return rho;
    const float u = altitude_km / (a.Rtop - a.R0);
    return u < 0.0f ? 0.0f : (u > 1.0f ? 1.0f : u);
}

// Table coordinate of the lowest point of a ray with impact radius rt (the
// tangent point). A ray that meets the ground uses the ground (seed: ρ_x ≤ 1).
SKYBAKE_HD_INLINE float tangent_coordinate(const AtmosphereHD& a, const ComponentHD& c, float rt) {
    const float h = rt > a.R0 ? rt - a.R0 : 0.0f;
    if (c.axis == kAxisDensity)
        return expf(-h * c.inv_scale_height);
    const float u = h / (a.Rtop - a.R0);
    return u > 1.0f ? 1.0f : u;
}

// Bilinear lookup in a table, u and c in [0, 1] (clamped).
SKYBAKE_HD_INLINE float table_bilinear(const TableHD& t, float u, float c) {
    float x = u * float(t.rows - 1);
    float y = c * float(t.cols - 1);
    x = x < 0.0f ? 0.0f : x;
    y = y < 0.0f ? 0.0f : y;
    int i = int(x);
    int j = int(y);
    i = i > t.rows - 2 ? t.rows - 2 : i;
    j = j > t.cols - 2 ? t.cols - 2 : j;
    float fx = x - float(i);
    float fy = y - float(j);
    fx = fx > 1.0f ? 1.0f : fx;
    fy = fy > 1.0f ? 1.0f : fy;
    const float* p = t.L + i * t.cols + j;
    const float a = p[0] + (p[1] - p[0]) * fy;
    const float b = p[t.cols] + (p[t.cols + 1] - p[t.cols]) * fy;
    return a + (b - a) * fx;
}

// Optical length L[u, c] of component c from a point at radius r (km), table
// coordinate u, towards a direction with cosine cz to the local vertical.
// Seed section I: the table holds c ≥ 0; for c < 0,
//   L[ρ, c] = 2 L[ρ_x, 0] − L[ρ, −c],  ρ_x = min(exp((R0 − r sin α)/H0), 1).
SKYBAKE_HD_INLINE float optical_length_lookup(const AtmosphereHD& a, const ComponentHD& c, float r, float u, float cz) {
    if (cz >= 0.0f)
        return table_bilinear(c.table, u, cz);
    const float s2 = 1.0f - cz * cz;
    const float rt = r * sqrtf(s2 > 0.0f ? s2 : 0.0f);
    const float ux = tangent_coordinate(a, c, rt);
    return 2.0f * table_bilinear(c.table, ux, 0.0f) - table_bilinear(c.table, u, -cz);
}

// ---- geometry -------------------------------------------------------------------
// Distance along a ray from radius r with cosine mu (to the vertical) to the
// sphere of radius R, the far intersection (r ≤ R). Returns ≥ 0.
SKYBAKE_HD_INLINE float distance_to_sphere_exit(float r, float mu, float R) {
    const float d = R * R - r * r * (1.0f - mu * mu);
    const float s = -r * mu + sqrtf(d > 0.0f ? d : 0.0f);
    return s > 0.0f ? s : 0.0f;
}

// Distance to the ground (sphere R0) if the ray meets it, else a negative value.
SKYBAKE_HD_INLINE float distance_to_ground(float r, float mu, float R0) {
    if (mu >= 0.0f)
        return -1.0f;
    const float d = R0 * R0 - r * r * (1.0f - mu * mu);
    if (d < 0.0f)
        return -1.0f;
    const float s = -r * mu - sqrtf(d);
    return s > 0.0f ? s : 0.0f;
}

// Seed section II, planet shadow: the sun ray from radius r with cos θ meets the planet.
SKYBAKE_HD_INLINE bool in_planet_shadow(float r, float cos_sun_zenith, float R0) {
    return cos_sun_zenith < 0.0f && r * r * (1.0f - cos_sun_zenith * cos_sun_zenith) < R0 * R0;
}

// Observer state for the sum: radius, altitude and the three cosines.
struct ObserverHD {
    float r;   // km from the planet centre
    float h;   // km above the ground (precise even where r is large)
    float cv;  // cos α0
    float cvs; // cos β0
    float cs;  // cos θ0
};

// Moves an observer above the top of the atmosphere to where its view ray
// enters it. Returns false when the ray misses the atmosphere.
SKYBAKE_HD_INLINE bool enter_atmosphere(const AtmosphereHD& a, ObserverHD& o) {
    if (o.r <= a.Rtop)
        return true;
    const float b = o.r * o.cv;
    const float disc = b * b - (o.r - a.Rtop) * (o.r + a.Rtop);
    if (b >= 0.0f || disc <= 0.0f)
        return false;
    const float v = -b - sqrtf(disc);
    const float r = a.Rtop;
    o.cv = (o.r * o.cv + v) / r;
    o.cs = (o.r * o.cs + v * o.cvs) / r;
    o.cv = o.cv < -1.0f ? -1.0f : (o.cv > 1.0f ? 1.0f : o.cv);
    o.cs = o.cs < -1.0f ? -1.0f : (o.cs > 1.0f ? 1.0f : o.cs);
    o.r = r;
    o.h = a.Rtop - a.R0;
    return true;
}

// ---- the seed's marching sum (section II, with section V's components) ------------
//
//   I = Σ_v Σ_k b_k F_k(β0) ρ_k,v exp(−Σ_k b_k (L_k[ρ0, cos α0] − L_k[ρ_v, cos α_v]
//                                            + L_k[ρ_v, cos θ_v])) Δv
//
// from the observer to where the view ray leaves the atmosphere or meets the
// ground. Points in the planet's shadow are skipped. Along the ray (position
// p = r0 U0 + v V):
//   r_v = sqrt(r0² + v² + 2 r0 v cos α0),  cos α_v = (r0 cos α0 + v)/r_v,
//   cos θ_v = (r0 cos θ0 + v cos β0)/r_v.
// The seed derives cos θ_v with the dihedral angle Λ between the planes U–V
// and L–V (cos θ_v = cos α_v cos β0 + sin α_v sin β0 cos Λ); projecting p on L
// gives the same value without the division by sin α0 sin β0, which is
// singular at the zenith and at the sun (tested in sky_model_test.cpp).
// Multiple components (section V): each has its own density ρ_k = profile(h)
// and table; the seed's printed rescaling ρ2 = ρ1 H2/H1 is not the density of
// the second component (that is ρ1^(H1/H2)), so each density is recomputed
// from the altitude instead.
//
// Steps: the seed uses a uniform Δv (kStepsUniform). The default spacing
// (kStepsGraded) puts the same number of midpoints on a grid graded
// geometrically away from the ray's lowest point (start, end or tangent
// point), where the density peaks: v = s((1 + D/s)^t − 1) with t uniform and
// s about one scale height of the first component along the ray. With 16
// steps it is ~10x more accurate than uniform steps at the same cost.
enum : int { kStepsGraded = 0, kStepsUniform = 1 };

// cos α_v and cos θ_v at distance v (km) along the view ray, where the radius
// is 1/inv_rv: the projections of p = r0 U0 + v V on V and on L, clamped to
// [−1, 1] against rounding.
struct StepCosines {
    float view_zenith; // cos α_v
    float sun_zenith;  // cos θ_v
};
SKYBAKE_HD_INLINE StepCosines step_cosines(const ObserverHD& o, float v, float inv_rv) {
    return {fminf(fmaxf((o.r * o.cv + v) * inv_rv, -1.0f), 1.0f),
            fminf(fmaxf((o.r * o.cs + v * o.cvs) * inv_rv, -1.0f), 1.0f)};
}

struct SumState {
    glm::vec3 scatter[kMaxComponents];
    float l_obs[kMaxComponents];
    float base; // r0² − R0²
};

SKYBAKE_HD_INLINE void sum_point(const AtmosphereHD& a, const ObserverHD& o, const SumState& st, float v, float dv,
                                 glm::vec3& result) {
    float d2 = st.base + v * (v + 2.0f * o.r * o.cv);
    d2 = d2 > 0.0f ? d2 : 0.0f;
    const float rv = sqrtf(a.R0 * a.R0 + d2);
    const float hv = d2 / (rv + a.R0);
    const float inv_r = 1.0f / rv;
    const StepCosines c_v = step_cosines(o, v, inv_r);
    const float cav = c_v.view_zenith, cth = c_v.sun_zenith;
    if (in_planet_shadow(rv, cth, a.R0))
        return;
    glm::vec3 tau(0.0f), weight(0.0f);
    for (int k = 0; k < a.count; ++k) {
        const ComponentHD& c = a.comp[k];
        const float rho = component_density(c, hv);
        const float u = table_coordinate(a, c, hv, rho);
        const float t = st.l_obs[k] - optical_length_lookup(a, c, rv, u, cav) + optical_length_lookup(a, c, rv, u, cth);
        tau += c.ext * t;
        weight += st.scatter[k] * rho;
    }
    result += weight * (dv * glm::vec3(expf(-tau.x), expf(-tau.y), expf(-tau.z)));
}

// One midpoint of the single-scattering sum (sum_point), as a functor.
struct SinglePoint {
    const AtmosphereHD& a;
    const ObserverHD& o;
    const SumState& st;
    glm::vec3& result;
    SKYBAKE_HD_INLINE void operator()(float v, float dv) const { sum_point(a, o, st, v, dv, result); }
};

// n midpoints on [v0, v0 ± D] graded from v0 with scale s (dir = ±1); point(v, Δv) for each.
template <class Point>
SKYBAKE_HD_INLINE void march_graded(float v0, float D, float dir, float s, int n, const Point& point) {
    if (n <= 0 || D <= 0.0f)
        return;
    const float w = logf(1.0f + D / s);
    for (int j = 0; j < n; ++j) {
        const float t = (float(j) + 0.5f) / float(n);
        const float e = expf(w * t);
        point(v0 + dir * s * (e - 1.0f), s * w * e / float(n));
    }
}

// The midpoints of a view ray of `length` km from an observer inside the
// atmosphere (base = r0² − R0²): uniform, or graded away from the lowest point.
template <class Point>
SKYBAKE_HD_INLINE void march_view_ray(const AtmosphereHD& a, const ObserverHD& o, float base, float length, int steps,
                                      int spacing, const Point& point) {
    if (spacing == kStepsUniform) {
        const float dv = length / float(steps);
        for (int j = 0; j < steps; ++j)
            point((float(j) + 0.5f) * dv, dv);
        return;
    }
    // The lowest point of the segment and the cosine to the vertical there.
    float v_low = -o.r * o.cv;
    v_low = v_low < 0.0f ? 0.0f : (v_low > length ? length : v_low);
    float d2 = base + v_low * (v_low + 2.0f * o.r * o.cv);
    const float r_low = sqrtf(a.R0 * a.R0 + (d2 > 0.0f ? d2 : 0.0f));
    const float mu_low = fabsf(o.r * o.cv + v_low) / r_low;
    const float H = 1.0f / a.comp[0].inv_scale_height;
    const float s = H / (mu_low + sqrtf(2.0f * H / r_low));
    const float before = v_low, after = length - v_low;
    const float wb = logf(1.0f + before / s), wa = logf(1.0f + after / s);
    int nb = int(float(steps) * wb / (wb + wa) + 0.5f);
    nb = before > 0.0f && nb < 1 ? 1 : nb;
    nb = after > 0.0f && nb > steps - 1 ? steps - 1 : nb;
    march_graded(v_low, before, -1.0f, s, nb, point);
    march_graded(v_low, after, 1.0f, s, steps - nb, point);
}

SKYBAKE_HD_INLINE glm::vec3 seed_sky_sum(const AtmosphereHD& a, ObserverHD o, int steps, int spacing = kStepsGraded) {
    glm::vec3 result(0.0f);
    if (!enter_atmosphere(a, o))
        return result;
    const float ground = distance_to_ground(o.r, o.cv, a.R0);
    const float length = ground >= 0.0f ? ground : distance_to_sphere_exit(o.r, o.cv, a.Rtop);
    if (length <= 0.0f || steps <= 0)
        return result;

    SumState st;
    for (int k = 0; k < a.count; ++k) {
        const ComponentHD& c = a.comp[k];
        st.scatter[k] = c.sca * phase_value(c.phase, c.g, o.cvs);
        const float rho = component_density(c, o.h);
        st.l_obs[k] = optical_length_lookup(a, c, o.r, table_coordinate(a, c, o.h, rho), o.cv);
    }
    // r_v² − R0² = (r0² − R0²) + v² + 2 r0 v cos α0, kept as a difference for precision.
    st.base = o.h * (2.0f * a.R0 + o.h);
    march_view_ray(a, o, st.base, length, steps, spacing, SinglePoint{a, o, st, result});
    return result;
}

// The single-scattering sum split by component and without the phase
// functions: out[k] = Σ b_k ρ_k T Δv, so that seed_sky_sum = Σ_k P_k(cos β0)
// out[k] (to rounding). With a parallel sun, cos β is the same at every point
// of the view ray, which is what lets a network learn the phase-free parts
// and apply the exact phase functions outside (docs/neural.md).
struct SplitPoint {
    const AtmosphereHD& a;
    const ObserverHD& o;
    const SumState& st;
    glm::vec3* out;
    SKYBAKE_HD_INLINE void operator()(float v, float dv) const {
        float d2 = st.base + v * (v + 2.0f * o.r * o.cv);
        d2 = d2 > 0.0f ? d2 : 0.0f;
        const float rv = sqrtf(a.R0 * a.R0 + d2);
        const float hv = d2 / (rv + a.R0);
        const StepCosines c_v = step_cosines(o, v, 1.0f / rv);
        if (in_planet_shadow(rv, c_v.sun_zenith, a.R0))
            return;
        glm::vec3 tau(0.0f), weight[kMaxComponents];
        for (int k = 0; k < a.count; ++k) {
            const ComponentHD& c = a.comp[k];
            const float rho = component_density(c, hv);
            const float u = table_coordinate(a, c, hv, rho);
            const float t = st.l_obs[k] - optical_length_lookup(a, c, rv, u, c_v.view_zenith) +
                            optical_length_lookup(a, c, rv, u, c_v.sun_zenith);
            tau += c.ext * t;
            weight[k] = c.sca * rho;
        }
        const glm::vec3 T = dv * glm::vec3(expf(-tau.x), expf(-tau.y), expf(-tau.z));
        for (int k = 0; k < a.count; ++k)
            out[k] += weight[k] * T;
    }
};

SKYBAKE_HD_INLINE void seed_sky_sum_split(const AtmosphereHD& a, ObserverHD o, int steps, int spacing,
                                          glm::vec3 out[kMaxComponents]) {
    for (int k = 0; k < kMaxComponents; ++k)
        out[k] = glm::vec3(0.0f);
    if (!enter_atmosphere(a, o))
        return;
    const float ground = distance_to_ground(o.r, o.cv, a.R0);
    const float length = ground >= 0.0f ? ground : distance_to_sphere_exit(o.r, o.cv, a.Rtop);
    if (length <= 0.0f || steps <= 0)
        return;
    SumState st;
    for (int k = 0; k < a.count; ++k) {
        const ComponentHD& c = a.comp[k];
        st.scatter[k] = c.sca;
        const float rho = component_density(c, o.h);
        st.l_obs[k] = optical_length_lookup(a, c, o.r, table_coordinate(a, c, o.h, rho), o.cv);
    }
    st.base = o.h * (2.0f * a.R0 + o.h);
    march_view_ray(a, o, st.base, length, steps, spacing, SplitPoint{a, o, st, out});
}

// Transmittance along a ray segment from a point A to a point B on the same
// line, A nearer the observer, from the tables: exp(−Σ b_k (L_k[A] − L_k[B])),
// both lookups in the view direction (cosines ca, cb to the local verticals).
SKYBAKE_HD_INLINE glm::vec3 segment_transmittance(const AtmosphereHD& a, float ra, float ha, float ca, float rb, float hb,
                                                  float cb) {
    glm::vec3 tau(0.0f);
    for (int k = 0; k < a.count; ++k) {
        const ComponentHD& c = a.comp[k];
        const float la = optical_length_lookup(a, c, ra, table_coordinate(a, c, ha, component_density(c, ha)), ca);
        const float lb = optical_length_lookup(a, c, rb, table_coordinate(a, c, hb, component_density(c, hb)), cb);
        const float t = la - lb;
        tau += c.ext * (t > 0.0f ? t : 0.0f);
    }
    return glm::vec3(expf(-tau.x), expf(-tau.y), expf(-tau.z));
}

// Transmittance of sunlight reaching a point at radius r (altitude h) with
// cos θ; zero in the planet's shadow.
SKYBAKE_HD_INLINE glm::vec3 sun_transmittance(const AtmosphereHD& a, float r, float h, float cos_sun_zenith) {
    if (in_planet_shadow(r, cos_sun_zenith, a.R0))
        return glm::vec3(0.0f);
    glm::vec3 tau(0.0f);
    for (int k = 0; k < a.count; ++k) {
        const ComponentHD& c = a.comp[k];
        const float u = table_coordinate(a, c, h, component_density(c, h));
        tau += c.ext * optical_length_lookup(a, c, r, u, cos_sun_zenith);
    }
    return glm::vec3(expf(-tau.x), expf(-tau.y), expf(-tau.z));
}

// ---- multiple scattering ---------------------------------------------------------------
//
// Hillaire 2020, eq. (10): along the view ray, every point adds
// σs(x) ψms(h, μs) times the transmittance back to the observer (the seed's
// table difference L[ρ0, cos α0] − L[ρv, cos αv]).
struct HillairePoint {
    const AtmosphereHD& a;
    const ObserverHD& o;
    const float* l_obs;
    float base;
    glm::vec3& result;
    SKYBAKE_HD_INLINE void operator()(float v, float dv) const {
        float d2 = base + v * (v + 2.0f * o.r * o.cv);
        d2 = d2 > 0.0f ? d2 : 0.0f;
        const float rv = sqrtf(a.R0 * a.R0 + d2);
        const float hv = d2 / (rv + a.R0);
        const StepCosines c_v = step_cosines(o, v, 1.0f / rv);
        glm::vec3 tau(0.0f), sigma_s(0.0f);
        for (int k = 0; k < a.count; ++k) {
            const ComponentHD& c = a.comp[k];
            const float rho = component_density(c, hv);
            const float u = table_coordinate(a, c, hv, rho);
            tau += c.ext * (l_obs[k] - optical_length_lookup(a, c, rv, u, c_v.view_zenith));
            sigma_s += c.sca * rho;
        }
        const glm::vec3 psi = psi_lookup(a.ms, a.R0, a.Rtop, hv, c_v.sun_zenith);
        result += sigma_s * psi * (dv * glm::vec3(expf(-tau.x), expf(-tau.y), expf(-tau.z)));
    }
};

// The light scattered more than once that reaches the observer along V
// (1/sr per unit sun irradiance): the orders grid at the point where the view
// ray starts inside the atmosphere, or Hillaire's march; zero for single scattering.
SKYBAKE_HD_INLINE glm::vec3 multiple_residual(const AtmosphereHD& a, ObserverHD o, int steps, int spacing = kStepsGraded) {
    glm::vec3 result(0.0f);
    if (a.ms.method == kMultipleNone || !enter_atmosphere(a, o))
        return result;
    if (a.ms.method == kMultipleOrders)
        return orders_lookup(a.ms, a.R0, a.Rtop, o.r, o.cv, o.cs, o.cvs);
    const float ground = distance_to_ground(o.r, o.cv, a.R0);
    const float length = ground >= 0.0f ? ground : distance_to_sphere_exit(o.r, o.cv, a.Rtop);
    if (length <= 0.0f || steps <= 0)
        return result;
    float l_obs[kMaxComponents];
    for (int k = 0; k < a.count; ++k) {
        const ComponentHD& c = a.comp[k];
        l_obs[k] = optical_length_lookup(a, c, o.r, table_coordinate(a, c, o.h, component_density(c, o.h)), o.cv);
    }
    const float base = o.h * (2.0f * a.R0 + o.h);
    march_view_ray(a, o, base, length, steps, spacing, HillairePoint{a, o, l_obs, base, result});
    return result;
}

// The sky colour of the model: the seed's single-scattering sum plus, when the
// atmosphere has them, the orders of multiple scattering.
SKYBAKE_HD_INLINE glm::vec3 sky_sum(const AtmosphereHD& a, const ObserverHD& o, int steps, int spacing = kStepsGraded) {
    glm::vec3 c = seed_sky_sum(a, o, steps, spacing);
    if (a.ms.method != kMultipleNone)
        c += multiple_residual(a, o, steps, spacing);
    return c;
}

} // namespace skybake::sky
