// Per-sample maths of the sky model, written once in the common subset of
// C++ and GLSL (core/shared_source.h): the CPU and CUDA evaluators include it
// through sky/sky_hd.h, and the planet renderer's shaders embed its text
// after src/render/shaders/atmosphere.glsl. Everything works on plain structs
// in float.
//
// Nishita T., Sirai T., Tadamura K., Nakamae E. Display of the Earth Taking
// into Account Atmospheric Scattering. SIGGRAPH 1993 (single scattering).
// Pietras K., Rudnicki M. GPU-based multi-layer perceptron as efficient method
// for approximation complex light models in per-vertex lighting (seed 000),
// sections I (optical-length tables), II (the marching sum), V (components).
// Bruneton E., Neyret F. Precomputed Atmospheric Scattering. EGSR 2008 (the
// orders of multiple scattering; aerial perspective from the 4D grid).
// Hillaire S. A Scalable and Production Ready Sky and Atmosphere Rendering
// Technique. EGSR 2020 (the 2D table ψms of isotropic multiple scattering).
//
// What each language defines before this text (sky/sky_hd.h for C++,
// atmosphere.glsl for GLSL):
//   vec3                       glm::vec3, or GLSL's own;
//   SB_INIT(x)                 a member's default (" = x" in C++, nothing in GLSL);
//   SB_DATA                    a handle to a table's floats: a pointer in C++,
//                              the first row (optical lengths) or the first RGB
//                              triple (multiple scattering) of a texture in GLSL;
//   SB_TABLE_TEXEL(t, i, j)    row i, column j of optical-length table t;
//   SB_MS_RGB(p, i)            RGB triple i of the multiple-scattering data p;
//   and grid4_shared.h's functions on Real = float.
#ifndef SKYBAKE_SKY_SKY_SHARED_H
#define SKYBAKE_SKY_SKY_SHARED_H

const int kMaxComponents = 4;
const float kPi = 3.14159265358979f;

// Values of skybake::PhaseFunction / DensityProfile, kept as ints here.
const int kPhaseNone = 0;
const int kPhaseRayleigh = 1;
const int kPhaseHG = 2;
const int kPhaseCornetteShanks = 3;
const int kPhasePietrasRudnickiMie = 4;
const int kProfileExponential = 0;
const int kProfileTent = 1;
const int kProfileConstant = 2;
// Height coordinate of a table's rows.
const int kAxisDensity = 0;
const int kAxisAltitude = 1;
// Multiple scattering: none, Bruneton's orders (4D grid), Hillaire's ψms (2D table).
const int kMultipleNone = 0;
const int kMultipleOrders = 1;
const int kMultipleHillaire = 2;
// Step spacing of the marching sum (see plan_view_ray).
const int kStepsGraded = 0;
const int kStepsUniform = 1;

// One optical-length table L[row][col]; rows u_i = i/(rows-1), columns c_j = j/(cols-1).
struct TableHD {
    SB_DATA L SB_INIT(0);
    int rows SB_INIT(0);
    int cols SB_INIT(0);
};

struct ComponentHD {
    int profile SB_INIT(kProfileExponential);
    float inv_scale_height SB_INIT(1.0f);    // 1/km (Exponential)
    float tent_center SB_INIT(25.0f);        // km (Tent)
    float inv_tent_half_width SB_INIT(1.0f); // 1/km (Tent)
    vec3 sca SB_INIT(vec3(0.0f));            // 1/km at ρ = 1
    vec3 ext SB_INIT(vec3(0.0f));            // 1/km at ρ = 1
    int phase SB_INIT(kPhaseNone);
    float g SB_INIT(0.0f);
    int axis SB_INIT(kAxisDensity);
    TableHD table;
};

// The multiple-scattering state of an atmosphere. Every table holds RGB
// floats, node-centred: coordinate x in [0, 1] maps to index x (n − 1).
struct MultipleHD {
    int method SB_INIT(kMultipleNone);
    float mu_s_min SB_INIT(-0.5f); // the orders grid's lowest sun cosine; below it, values are those at mu_s_min
    // grid4_mus_coordinate of μs = 0 for this grid (set with mu_s_min): its
    // cells below it blend geometrically (grid4_mus_cell_below_horizon).
    float x_horizon SB_INIT(0.0f);
    // Orders ≥ 2 of scattered radiance (1/sr per unit sun irradiance) over the
    // grid nr × (2 nmu) × nmus × nnu (see grid4_index).
    SB_DATA orders SB_INIT(0);
    int nr SB_INIT(0);
    int nmu SB_INIT(0);
    int nmus SB_INIT(0);
    int nnu SB_INIT(0);
    // Hillaire's ψms (1/sr per unit sun irradiance, isotropic phase included)
    // over psi_nr altitudes (uniform, ground to top) × psi_nmus sun cosines (uniform in [−1, 1]).
    SB_DATA psi SB_INIT(0);
    int psi_nr SB_INIT(0);
    int psi_nmus SB_INIT(0);
    // Irradiance of the scattered sky light on a horizontal surface (per unit
    // sun irradiance; the direct sun excluded) over irr_nr altitudes × irr_nmus
    // sun cosines; irr_nr = 0: none.
    SB_DATA irradiance SB_INIT(0);
    int irr_nr SB_INIT(0);
    int irr_nmus SB_INIT(0);
};

struct AtmosphereHD {
    float R0 SB_INIT(6360.0f);   // planet radius, km
    float Rtop SB_INIT(6420.0f); // top of the atmosphere, km
    int count SB_INIT(0);
    ComponentHD comp[kMaxComponents];
    MultipleHD ms; // multiple scattering (method kMultipleNone: single scattering only)
};

// Observer state for the sum: radius, altitude and the three cosines.
struct ObserverHD {
    float r;   // km from the planet centre
    float h;   // km above the ground (precise even where r is large)
    float cv;  // cos α0
    float cvs; // cos β0
    float cs;  // cos θ0
};

SKYBAKE_HD_INLINE ObserverHD observer_hd(float r, float h, float cv, float cvs, float cs) {
    ObserverHD o;
    o.r = r;
    o.h = h;
    o.cv = cv;
    o.cvs = cvs;
    o.cs = cs;
    return o;
}

SKYBAKE_HD_INLINE vec3 exp_neg(vec3 tau) { return vec3(expf(-tau.x), expf(-tau.y), expf(-tau.z)); }

// ---- phase functions (1/sr), mu = cos(angle between V and L) ------------------
SKYBAKE_HD_INLINE float phase_value(int kind, float g, float mu) {
    float inv4pi = 0.25f / kPi;
    float d = 1.0f + g * g - 2.0f * g * mu;
    switch (kind) {
    case kPhaseRayleigh:
        return 3.0f / (16.0f * kPi) * (1.0f + mu * mu);
    case kPhaseHG:
        return inv4pi * (1.0f - g * g) / (d * sqrtf(d));
    case kPhaseCornetteShanks:
        return 3.0f * (1.0f - g * g) * (1.0f + mu * mu) / (8.0f * kPi * (2.0f + g * g) * d * sqrtf(d));
    case kPhasePietrasRudnickiMie:
        return (1.0f - g * g) / (16.0f * kPi * d * sqrtf(d));
    default:
        return 0.0f;
    }
}

// ---- density profiles -----------------------------------------------------------
SKYBAKE_HD_INLINE float component_density(SB_IN(ComponentHD) c, float altitude_km) {
    if (c.profile == kProfileExponential)
        return expf(-altitude_km * c.inv_scale_height);
    if (c.profile == kProfileTent) {
        float t = 1.0f - fabsf(altitude_km - c.tent_center) * c.inv_tent_half_width;
        return t > 0.0f ? t : 0.0f;
    }
    return 1.0f;
}

// Table row coordinate u in [0, 1] of a point at altitude_km with density rho.
SKYBAKE_HD_INLINE float table_coordinate(SB_IN(AtmosphereHD) a, SB_IN(ComponentHD) c, float altitude_km, float rho) {
    if (c.axis == kAxisDensity)
        return rho;
    float u = altitude_km / (a.Rtop - a.R0);
    return u < 0.0f ? 0.0f : (u > 1.0f ? 1.0f : u);
}

// Table coordinate of the lowest point of a ray with impact radius rt (the
// tangent point). A ray that meets the ground uses the ground (seed: ρ_x ≤ 1).
SKYBAKE_HD_INLINE float tangent_coordinate(SB_IN(AtmosphereHD) a, SB_IN(ComponentHD) c, float rt) {
    float h = rt > a.R0 ? rt - a.R0 : 0.0f;
    if (c.axis == kAxisDensity)
        return expf(-h * c.inv_scale_height);
    float u = h / (a.Rtop - a.R0);
    return u > 1.0f ? 1.0f : u;
}

// Bilinear lookup in a table, u and c in [0, 1] (clamped), by texel fetches.
SKYBAKE_HD_INLINE float table_bilinear(SB_IN(TableHD) t, float u, float c) {
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
    float p00 = SB_TABLE_TEXEL(t, i, j);
    float p01 = SB_TABLE_TEXEL(t, i, j + 1);
    float p10 = SB_TABLE_TEXEL(t, i + 1, j);
    float p11 = SB_TABLE_TEXEL(t, i + 1, j + 1);
    float lo = p00 + (p01 - p00) * fy;
    float hi = p10 + (p11 - p10) * fy;
    return lo + (hi - lo) * fx;
}

// Optical length L[u, c] of component c from a point at radius r (km), table
// coordinate u, towards a direction with cosine cz to the local vertical.
// Seed section I: the table holds c ≥ 0; for c < 0,
//   L[ρ, c] = 2 L[ρ_x, 0] − L[ρ, −c],  ρ_x = min(exp((R0 − r sin α)/H0), 1).
SKYBAKE_HD_INLINE float optical_length_lookup(SB_IN(AtmosphereHD) a, SB_IN(ComponentHD) c, float r, float u, float cz) {
    if (cz >= 0.0f)
        return table_bilinear(c.table, u, cz);
    float s2 = 1.0f - cz * cz;
    float rt = r * sqrtf(s2 > 0.0f ? s2 : 0.0f);
    float ux = tangent_coordinate(a, c, rt);
    return 2.0f * table_bilinear(c.table, ux, 0.0f) - table_bilinear(c.table, u, -cz);
}

// ---- geometry -------------------------------------------------------------------
// Distance along a ray from radius r with cosine mu (to the vertical) to the
// sphere of radius R, the far intersection (r ≤ R). Returns ≥ 0.
SKYBAKE_HD_INLINE float distance_to_sphere_exit(float r, float mu, float R) {
    float d = R * R - r * r * (1.0f - mu * mu);
    float s = -r * mu + sqrtf(d > 0.0f ? d : 0.0f);
    return s > 0.0f ? s : 0.0f;
}

// Distance to the ground (sphere R0) if the ray meets it, else a negative value.
SKYBAKE_HD_INLINE float distance_to_ground(float r, float mu, float R0) {
    if (mu >= 0.0f)
        return -1.0f;
    float d = R0 * R0 - r * r * (1.0f - mu * mu);
    if (d < 0.0f)
        return -1.0f;
    float s = -r * mu - sqrtf(d);
    return s > 0.0f ? s : 0.0f;
}

// Seed section II, planet shadow: the sun ray from radius r with cos θ meets the planet.
SKYBAKE_HD_INLINE bool in_planet_shadow(float r, float cos_sun_zenith, float R0) {
    return cos_sun_zenith < 0.0f && r * r * (1.0f - cos_sun_zenith * cos_sun_zenith) < R0 * R0;
}

// Moves an observer above the top of the atmosphere to where its view ray
// enters it. Returns false when the ray misses the atmosphere.
SKYBAKE_HD_INLINE bool enter_atmosphere(SB_IN(AtmosphereHD) a, SB_INOUT(ObserverHD) o) {
    if (o.r <= a.Rtop)
        return true;
    float b = o.r * o.cv;
    float disc = b * b - (o.r - a.Rtop) * (o.r + a.Rtop);
    if (b >= 0.0f || disc <= 0.0f)
        return false;
    float v = -b - sqrtf(disc);
    float r = a.Rtop;
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

// cos α_v and cos θ_v at distance v (km) along the view ray, where the radius
// is 1/inv_rv: the projections of p = r0 U0 + v V on V and on L, clamped to
// [−1, 1] against rounding.
struct StepCosines {
    float view_zenith; // cos α_v
    float sun_zenith;  // cos θ_v
};
SKYBAKE_HD_INLINE StepCosines step_cosines(SB_IN(ObserverHD) o, float v, float inv_rv) {
    StepCosines s;
    s.view_zenith = fminf(fmaxf((o.r * o.cv + v) * inv_rv, -1.0f), 1.0f);
    s.sun_zenith = fminf(fmaxf((o.r * o.cs + v * o.cvs) * inv_rv, -1.0f), 1.0f);
    return s;
}

// A point of the view ray at distance v: radius, altitude and cosines.
struct RayPoint {
    float r;
    float h;
    StepCosines c;
};
// base = r0² − R0²: r_v² − R0² = base + v² + 2 r0 v cos α0, kept as a difference for precision.
SKYBAKE_HD_INLINE RayPoint ray_point(SB_IN(AtmosphereHD) a, SB_IN(ObserverHD) o, float base, float v) {
    float d2 = base + v * (v + 2.0f * o.r * o.cv);
    d2 = d2 > 0.0f ? d2 : 0.0f;
    RayPoint p;
    p.r = sqrtf(a.R0 * a.R0 + d2);
    p.h = d2 / (p.r + a.R0);
    p.c = step_cosines(o, v, 1.0f / p.r);
    return p;
}

// Steps: the seed uses a uniform Δv (kStepsUniform). The default spacing
// (kStepsGraded) puts the same number of midpoints on a grid graded
// geometrically away from the ray's lowest point (start, end or tangent
// point), where the density peaks: v = s((1 + D/s)^t − 1) with t uniform and
// s about one scale height of the first component along the ray. With 16
// steps it is ~10x more accurate than uniform steps at the same cost.
// A march is planned once per ray (plan_view_ray) and its midpoints read one
// by one (march_point), so that each sum is a plain loop in both languages.
struct MarchPlan {
    int steps;
    int spacing;
    float len;    // km
    float v_low;  // the lowest point of the segment
    float s;      // the grading scale, km
    float before; // length before and after v_low
    float after;
    float wb; // log(1 + before/s), log(1 + after/s)
    float wa;
    int nb; // midpoints before v_low
};

// The march of a view ray of `len` km from an observer inside the
// atmosphere (base = r0² − R0²): uniform, or graded away from the lowest point.
SKYBAKE_HD_INLINE MarchPlan plan_view_ray(SB_IN(AtmosphereHD) a, SB_IN(ObserverHD) o, float base, float len,
                                          int steps, int spacing) {
    MarchPlan m;
    m.steps = steps;
    m.spacing = spacing;
    m.len = len;
    m.v_low = 0.0f;
    m.s = 1.0f;
    m.before = 0.0f;
    m.after = len;
    m.wb = 0.0f;
    m.wa = 0.0f;
    m.nb = 0;
    if (spacing == kStepsUniform)
        return m;
    // The lowest point of the segment and the cosine to the vertical there.
    float v_low = -o.r * o.cv;
    v_low = v_low < 0.0f ? 0.0f : (v_low > len ? len : v_low);
    float d2 = base + v_low * (v_low + 2.0f * o.r * o.cv);
    float r_low = sqrtf(a.R0 * a.R0 + (d2 > 0.0f ? d2 : 0.0f));
    float mu_low = fabsf(o.r * o.cv + v_low) / r_low;
    float H = 1.0f / a.comp[0].inv_scale_height;
    m.v_low = v_low;
    m.s = H / (mu_low + sqrtf(2.0f * H / r_low));
    m.before = v_low;
    m.after = len - v_low;
    m.wb = logf(1.0f + m.before / m.s);
    m.wa = logf(1.0f + m.after / m.s);
    int nb = int(float(steps) * m.wb / (m.wb + m.wa) + 0.5f);
    nb = m.before > 0.0f && nb < 1 ? 1 : nb;
    nb = m.after > 0.0f && nb > steps - 1 ? steps - 1 : nb;
    m.nb = nb;
    return m;
}

// Midpoint j (0 ≤ j < m.steps) of a march: its distance v and length dv.
// False where the graded half it falls in is empty (no point to add).
SKYBAKE_HD_INLINE bool march_point(SB_IN(MarchPlan) m, int j, SB_OUT(float) v, SB_OUT(float) dv) {
    v = 0.0f;
    dv = 0.0f;
    if (m.spacing == kStepsUniform) {
        dv = m.len / float(m.steps);
        v = (float(j) + 0.5f) * dv;
        return true;
    }
    bool first = j < m.nb; // towards the start of the ray, from v_low
    int n = first ? m.nb : m.steps - m.nb;
    float D = first ? m.before : m.after;
    if (n <= 0 || D <= 0.0f)
        return false;
    float w = first ? m.wb : m.wa;
    float dir = first ? -1.0f : 1.0f;
    float t = (float(first ? j : j - m.nb) + 0.5f) / float(n);
    float e = expf(w * t);
    v = m.v_low + dir * m.s * (e - 1.0f);
    dv = m.s * w * e / float(n);
    return true;
}

// The length of the view ray inside the atmosphere from an observer already
// in it, to the ground or the top (0: nothing to march).
SKYBAKE_HD_INLINE float view_ray_length(SB_IN(AtmosphereHD) a, SB_IN(ObserverHD) o) {
    float ground = distance_to_ground(o.r, o.cv, a.R0);
    return ground >= 0.0f ? ground : distance_to_sphere_exit(o.r, o.cv, a.Rtop);
}

// Per component, the phase-weighted scattering coefficient and the optical
// length from the observer along the view ray.
struct SumState {
    vec3 scatter[kMaxComponents];
    float l_obs[kMaxComponents];
    float base; // r0² − R0²
};

// with_phase false: scatter[k] is b_k alone (seed_sky_sum_split).
SKYBAKE_HD_INLINE SumState sum_state(SB_IN(AtmosphereHD) a, SB_IN(ObserverHD) o, bool with_phase) {
    SumState st;
    for (int k = 0; k < kMaxComponents; ++k) {
        st.scatter[k] = vec3(0.0f);
        st.l_obs[k] = 0.0f;
    }
    for (int k = 0; k < a.count; ++k) {
        st.scatter[k] = with_phase ? a.comp[k].sca * phase_value(a.comp[k].phase, a.comp[k].g, o.cvs) : a.comp[k].sca;
        float rho = component_density(a.comp[k], o.h);
        st.l_obs[k] = optical_length_lookup(a, a.comp[k], o.r, table_coordinate(a, a.comp[k], o.h, rho), o.cv);
    }
    st.base = o.h * (2.0f * a.R0 + o.h);
    return st;
}

// One midpoint of the single-scattering sum.
SKYBAKE_HD_INLINE vec3 single_point(SB_IN(AtmosphereHD) a, SB_IN(ObserverHD) o, SB_IN(SumState) st, float v, float dv) {
    RayPoint p = ray_point(a, o, st.base, v);
    if (in_planet_shadow(p.r, p.c.sun_zenith, a.R0))
        return vec3(0.0f);
    vec3 tau = vec3(0.0f);
    vec3 weight = vec3(0.0f);
    for (int k = 0; k < a.count; ++k) {
        float rho = component_density(a.comp[k], p.h);
        float u = table_coordinate(a, a.comp[k], p.h, rho);
        float t = st.l_obs[k] - optical_length_lookup(a, a.comp[k], p.r, u, p.c.view_zenith) +
                  optical_length_lookup(a, a.comp[k], p.r, u, p.c.sun_zenith);
        tau += a.comp[k].ext * t;
        weight += st.scatter[k] * rho;
    }
    return weight * (dv * exp_neg(tau));
}

// The distance from the observer to where its view ray enters the atmosphere
// (0 inside it).
SKYBAKE_HD_INLINE float distance_to_atmosphere(SB_IN(AtmosphereHD) a, SB_IN(ObserverHD) o) {
    if (o.r <= a.Rtop)
        return 0.0f;
    float b = o.r * o.cv;
    return -b - sqrtf(fmaxf(b * b - (o.r - a.Rtop) * (o.r + a.Rtop), 0.0f));
}

// The seed's sum up to a surface at distance `limit` from the observer
// (limit < 0: none; the ray ends at the ground or the top).
SKYBAKE_HD_INLINE vec3 seed_sky_sum_to(SB_IN(AtmosphereHD) a, ObserverHD o, int steps, int spacing, float limit) {
    vec3 result = vec3(0.0f);
    float v_enter = distance_to_atmosphere(a, o);
    if (!enter_atmosphere(a, o))
        return result;
    float len = view_ray_length(a, o);
    if (limit >= 0.0f)
        len = fminf(len, limit - v_enter);
    if (len <= 0.0f || steps <= 0)
        return result;
    SumState st = sum_state(a, o, true);
    MarchPlan m = plan_view_ray(a, o, st.base, len, steps, spacing);
    for (int j = 0; j < steps; ++j) {
        float v;
        float dv;
        if (march_point(m, j, v, dv))
            result += single_point(a, o, st, v, dv);
    }
    return result;
}

SKYBAKE_HD_INLINE vec3 seed_sky_sum(SB_IN(AtmosphereHD) a, ObserverHD o, int steps, int spacing) {
    return seed_sky_sum_to(a, o, steps, spacing, -1.0f);
}

// Transmittance along a ray segment from a point A to a point B on the same
// line, A nearer the observer, from the tables: exp(−Σ b_k (L_k[A] − L_k[B])),
// both lookups in the view direction (cosines ca, cb to the local verticals).
SKYBAKE_HD_INLINE vec3 segment_transmittance(SB_IN(AtmosphereHD) a, float ra, float ha, float ca, float rb, float hb,
                                             float cb) {
    vec3 tau = vec3(0.0f);
    for (int k = 0; k < a.count; ++k) {
        float la = optical_length_lookup(a, a.comp[k], ra,
                                         table_coordinate(a, a.comp[k], ha, component_density(a.comp[k], ha)), ca);
        float lb = optical_length_lookup(a, a.comp[k], rb,
                                         table_coordinate(a, a.comp[k], hb, component_density(a.comp[k], hb)), cb);
        float t = la - lb;
        tau += a.comp[k].ext * (t > 0.0f ? t : 0.0f);
    }
    return exp_neg(tau);
}

// Transmittance of sunlight reaching a point at radius r (altitude h) with
// cos θ; zero in the planet's shadow.
SKYBAKE_HD_INLINE vec3 sun_transmittance(SB_IN(AtmosphereHD) a, float r, float h, float cos_sun_zenith) {
    if (in_planet_shadow(r, cos_sun_zenith, a.R0))
        return vec3(0.0f);
    vec3 tau = vec3(0.0f);
    for (int k = 0; k < a.count; ++k) {
        float u = table_coordinate(a, a.comp[k], h, component_density(a.comp[k], h));
        tau += a.comp[k].ext * optical_length_lookup(a, a.comp[k], r, u, cos_sun_zenith);
    }
    return exp_neg(tau);
}

// ---- multiple scattering ---------------------------------------------------------------

// Orders ≥ 2 at a point inside the atmosphere (r ≤ Rt), per unit sun
// irradiance: the quadrilinear look-up in the 4D grid, the three channels at once.
SKYBAKE_HD_INLINE vec3 orders_lookup(SB_IN(MultipleHD) m, float R0, float Rt, float r, float mu, float mu_s, float nu) {
    float xr;
    float xmu;
    float xmus;
    float xnu;
    int lower;
    grid4_coordinates(R0, Rt, m.mu_s_min, r, mu, mu_s, nu, xr, xmu, xmus, xnu, lower);
    float fr;
    float fm;
    float fs;
    float fn;
    int ir = grid_axis(xr, m.nr, fr);
    int im = grid_axis(xmu, m.nmu, fm);
    int is = grid_axis(xmus, m.nmus, fs);
    int inu = grid_axis(xnu, m.nnu, fn);
    // Trilinear in (r, μ, ν) at the two μs nodes, then blended along μs
    // (geometrically below the horizon: grid4_mus_blend).
    vec3 at[2];
    for (int s = 0; s < 2; ++s) {
        vec3 sum = vec3(0.0f);
        for (int a = 0; a < 2; ++a)
            for (int b = 0; b < 2; ++b)
                for (int n = 0; n < 2; ++n) {
                    float w = (a == 1 ? fr : 1.0f - fr) * (b == 1 ? fm : 1.0f - fm) * (n == 1 ? fn : 1.0f - fn);
                    sum += w * SB_MS_RGB(m.orders, grid4_index(m.nmu, m.nmus, m.nnu, ir + a, lower, im + b, is + s,
                                                               inu + n));
                }
        at[s] = sum;
    }
    int below = grid4_mus_cell_below_horizon(m.x_horizon, m.nmus, is);
    return vec3(grid4_mus_blend(at[0].x, at[1].x, fs, below), grid4_mus_blend(at[0].y, at[1].y, fs, below),
                grid4_mus_blend(at[0].z, at[1].z, fs, below));
}

// What the orders grid is stored per unit of (the twin of
// sky::orders_scale in scattering_orders.h): the air's scattering, summed
// over the channels, at the lowest point of a ray that does not meet the
// ground, relative to the ground's; 1 for a ray that meets it.
SKYBAKE_HD_INLINE float orders_scale(SB_IN(AtmosphereHD) a, float r, float mu) {
    r = hd_clamp(r, a.R0, a.Rtop);
    if (mu < 0.0f && r * r * (mu * mu - 1.0f) + a.R0 * a.R0 >= 0.0f)
        return 1.0f;
    float lowest = mu >= 0.0f ? r - a.R0 : fmaxf(r * hd_sqrt(1.0f - mu * mu) - a.R0, 0.0f);
    float at = 0.0f;
    float ground = 0.0f;
    for (int k = 0; k < a.count; ++k) {
        float w = a.comp[k].sca.x + a.comp[k].sca.y + a.comp[k].sca.z;
        at += w * component_density(a.comp[k], lowest);
        ground += w * component_density(a.comp[k], 0.0f);
    }
    return ground > 0.0f ? fmaxf(at / ground, 1e-30f) : 1.0f;
}

// The light of orders ≥ 2 from the grid (orders_lookup) at radius r along (μ, μs, ν).
SKYBAKE_HD_INLINE vec3 orders_radiance(SB_IN(AtmosphereHD) a, float r, float mu, float mu_s, float nu) {
    return orders_scale(a, r, mu) * orders_lookup(a.ms, a.R0, a.Rtop, r, mu, mu_s, nu);
}

// Bilinear look-up in an RGB table over altitude (uniform, ground to top) and
// sun cosine (uniform in [−1, 1]).
SKYBAKE_HD_INLINE vec3 altitude_sun_lookup(SB_DATA t, int nr, int nmus, float R0, float Rt, float h, float mu_s) {
    float fr;
    float fs;
    int i = grid_axis(hd_clamp(h / (Rt - R0), 0.0f, 1.0f), nr, fr);
    int j = grid_axis(hd_clamp(0.5f * (mu_s + 1.0f), 0.0f, 1.0f), nmus, fs);
    vec3 v = vec3(0.0f);
    for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b) {
            float w = (a == 1 ? fr : 1.0f - fr) * (b == 1 ? fs : 1.0f - fs);
            v += w * SB_MS_RGB(t, (i + a) * nmus + (j + b));
        }
    return v;
}

// Hillaire's ψms at altitude h (km) and sun cosine mu_s.
SKYBAKE_HD_INLINE vec3 psi_lookup(SB_IN(MultipleHD) m, float R0, float Rt, float h, float mu_s) {
    return altitude_sun_lookup(m.psi, m.psi_nr, m.psi_nmus, R0, Rt, h, mu_s);
}

// Sky irradiance on a horizontal surface at altitude h (km) with sun cosine mu_s.
SKYBAKE_HD_INLINE vec3 sky_irradiance_lookup(SB_IN(MultipleHD) m, float R0, float Rt, float h, float mu_s) {
    if (m.irr_nr <= 0)
        return vec3(0.0f);
    return altitude_sun_lookup(m.irradiance, m.irr_nr, m.irr_nmus, R0, Rt, h, mu_s);
}

// Hillaire 2020, eq. (10): along the view ray, every point adds σs(x) ψms(h, μs)
// times the transmittance back to the observer (the seed's table difference
// L[ρ0, cos α0] − L[ρv, cos αv]), shadowed or not.
SKYBAKE_HD_INLINE vec3 hillaire_point(SB_IN(AtmosphereHD) a, SB_IN(ObserverHD) o, SB_IN(SumState) st, float v, float dv) {
    RayPoint p = ray_point(a, o, st.base, v);
    vec3 tau = vec3(0.0f);
    vec3 sigma_s = vec3(0.0f);
    for (int k = 0; k < a.count; ++k) {
        float rho = component_density(a.comp[k], p.h);
        float u = table_coordinate(a, a.comp[k], p.h, rho);
        tau += a.comp[k].ext * (st.l_obs[k] - optical_length_lookup(a, a.comp[k], p.r, u, p.c.view_zenith));
        sigma_s += a.comp[k].sca * rho;
    }
    vec3 psi = psi_lookup(a.ms, a.R0, a.Rtop, p.h, p.c.sun_zenith);
    return sigma_s * psi * (dv * exp_neg(tau));
}

// The light scattered more than once that reaches the observer along V
// (1/sr per unit sun irradiance), up to a surface at distance `limit` (< 0:
// none); zero for single scattering. Orders: the 4D grid where the view ray
// starts inside the atmosphere, less the grid at the surface times the
// transmittance in between (Bruneton's aerial perspective). Hillaire: the march.
SKYBAKE_HD_INLINE vec3 multiple_residual_to(SB_IN(AtmosphereHD) a, ObserverHD o, int steps, int spacing, float limit) {
    vec3 result = vec3(0.0f);
    ObserverHD e = o;
    if (a.ms.method == kMultipleNone || !enter_atmosphere(a, e))
        return result;
    if (a.ms.method == kMultipleOrders) {
        result = orders_radiance(a, e.r, e.cv, e.cs, e.cvs);
        if (limit >= 0.0f) {
            float rp = sqrtf(fmaxf(o.r * o.r + limit * limit + 2.0f * o.r * limit * o.cv, 0.0f));
            float mup = hd_clamp((o.r * o.cv + limit) / rp, -1.0f, 1.0f);
            float musp = hd_clamp((o.r * o.cs + limit * o.cvs) / rp, -1.0f, 1.0f);
            vec3 t = segment_transmittance(a, e.r, e.h, e.cv, rp, rp - a.R0, mup);
            result = max(result - t * orders_radiance(a, rp, mup, musp, o.cvs), vec3(0.0f));
        }
        return result;
    }
    float len = view_ray_length(a, e);
    if (limit >= 0.0f)
        len = fminf(len, limit - distance_to_atmosphere(a, o));
    if (len <= 0.0f || steps <= 0)
        return result;
    SumState st = sum_state(a, e, false);
    MarchPlan m = plan_view_ray(a, e, st.base, len, steps, spacing);
    for (int j = 0; j < steps; ++j) {
        float v;
        float dv;
        if (march_point(m, j, v, dv))
            result += hillaire_point(a, e, st, v, dv);
    }
    return result;
}

SKYBAKE_HD_INLINE vec3 multiple_residual(SB_IN(AtmosphereHD) a, ObserverHD o, int steps, int spacing) {
    return multiple_residual_to(a, o, steps, spacing, -1.0f);
}

// The sky colour of the model: the seed's single-scattering sum plus, when
// the atmosphere has them, the orders of multiple scattering; up to a surface
// at distance `limit` (< 0: none).
SKYBAKE_HD_INLINE vec3 sky_sum_to(SB_IN(AtmosphereHD) a, SB_IN(ObserverHD) o, int steps, int spacing, float limit) {
    vec3 c = seed_sky_sum_to(a, o, steps, spacing, limit);
    if (a.ms.method != kMultipleNone)
        c += multiple_residual_to(a, o, steps, spacing, limit);
    return c;
}

SKYBAKE_HD_INLINE vec3 sky_sum(SB_IN(AtmosphereHD) a, SB_IN(ObserverHD) o, int steps, int spacing) {
    return sky_sum_to(a, o, steps, spacing, -1.0f);
}

#endif
