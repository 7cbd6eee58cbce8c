// GLSL twin of src/sky/sky_hd.h and src/sky/render_hd.h (the sky model's
// per-sample maths and the per-ray shading of src/neural/render_hd.h),
// function for function and in the same order of operations; the tests
// compare its images with the C++ renderer's. Still kept by hand: the tone
// curve has moved to core/tone_curve.h, one source for C++ and GLSL, and
// these functions are to follow it (CONTRIBUTING.md, "Layout").
//
// Nishita T. et al. Display of the Earth Taking into Account Atmospheric
// Scattering. SIGGRAPH 1993. Pietras & Rudnicki (seed 000), sections I
// (optical-length tables), II (the marching sum), III (the network), IV
// (the colour of the surface), V (components).
//
// Expects, before it: the #version line, SKYBAKE_SKY_NETWORK or
// SKYBAKE_SKY_REFERENCE, and (network) vec3 skybake_sky(float, float, float, float).

#define SKYBAKE_PI 3.14159265358979
#define SKYBAKE_MAX_COMPONENTS 4

uniform int u_count;             // atmosphere components
uniform float u_R0;              // planet radius, km
uniform float u_Rtop;            // top of the atmosphere, km
uniform int u_profile[SKYBAKE_MAX_COMPONENTS];
uniform float u_inv_scale_height[SKYBAKE_MAX_COMPONENTS];
uniform float u_tent_center[SKYBAKE_MAX_COMPONENTS];
uniform float u_inv_tent_half_width[SKYBAKE_MAX_COMPONENTS];
uniform vec3 u_sca[SKYBAKE_MAX_COMPONENTS];
uniform vec3 u_ext[SKYBAKE_MAX_COMPONENTS];
uniform int u_phase[SKYBAKE_MAX_COMPONENTS];
uniform float u_g[SKYBAKE_MAX_COMPONENTS];
uniform int u_axis[SKYBAKE_MAX_COMPONENTS];
uniform sampler2D u_tables; // R32F: cols wide, rows * count high; component k at rows [k rows, (k+1) rows)
uniform int u_rows;
uniform int u_cols;

// The scene.
uniform float u_eye_r;           // observer radius, km
uniform float u_eye_h;           // observer altitude, km
uniform vec3 u_up;               // unit local vertical at the observer
uniform vec3 u_sun;              // unit direction to the sun
uniform vec3 u_albedo;
uniform int u_published_ground;
uniform vec3 u_irradiance;
uniform float u_sun_cos_radius;
uniform float u_sun_disc_radiance;
uniform int u_steps;             // reference sum only
uniform int u_spacing;           // 0 graded, 1 uniform

float sb_phase(int kind, float g, float mu) {
    float inv4pi = 0.25 / SKYBAKE_PI;
    if (kind == 1)
        return 3.0 / (16.0 * SKYBAKE_PI) * (1.0 + mu * mu);
    float d = 1.0 + g * g - 2.0 * g * mu;
    if (kind == 2)
        return inv4pi * (1.0 - g * g) / (d * sqrt(d));
    if (kind == 3)
        return 3.0 * (1.0 - g * g) * (1.0 + mu * mu) / (8.0 * SKYBAKE_PI * (2.0 + g * g) * d * sqrt(d));
    if (kind == 4)
        return (1.0 - g * g) / (16.0 * SKYBAKE_PI * d * sqrt(d));
    return 0.0;
}

float sb_density(int k, float altitude_km) {
    if (u_profile[k] == 0)
        return exp(-altitude_km * u_inv_scale_height[k]);
    if (u_profile[k] == 1) {
        float t = 1.0 - abs(altitude_km - u_tent_center[k]) * u_inv_tent_half_width[k];
        return t > 0.0 ? t : 0.0;
    }
    return 1.0;
}

float sb_table_coordinate(int k, float altitude_km, float rho) {
    if (u_axis[k] == 0)
        return rho;
    float u = altitude_km / (u_Rtop - u_R0);
    return clamp(u, 0.0, 1.0);
}

float sb_tangent_coordinate(int k, float rt) {
    float h = rt > u_R0 ? rt - u_R0 : 0.0;
    if (u_axis[k] == 0)
        return exp(-h * u_inv_scale_height[k]);
    float u = h / (u_Rtop - u_R0);
    return u > 1.0 ? 1.0 : u;
}

float sb_fetch(int k, int i, int j) { return texelFetch(u_tables, ivec2(j, k * u_rows + i), 0).r; }

// Bilinear lookup, as sky::table_bilinear (texel fetches, no filtering hardware).
float sb_table_bilinear(int k, float u, float c) {
    float x = u * float(u_rows - 1);
    float y = c * float(u_cols - 1);
    x = x < 0.0 ? 0.0 : x;
    y = y < 0.0 ? 0.0 : y;
    int i = int(x);
    int j = int(y);
    i = i > u_rows - 2 ? u_rows - 2 : i;
    j = j > u_cols - 2 ? u_cols - 2 : j;
    float fx = x - float(i);
    float fy = y - float(j);
    fx = fx > 1.0 ? 1.0 : fx;
    fy = fy > 1.0 ? 1.0 : fy;
    float p00 = sb_fetch(k, i, j), p01 = sb_fetch(k, i, j + 1);
    float p10 = sb_fetch(k, i + 1, j), p11 = sb_fetch(k, i + 1, j + 1);
    float a = p00 + (p01 - p00) * fy;
    float b = p10 + (p11 - p10) * fy;
    return a + (b - a) * fx;
}

float sb_optical_length(int k, float r, float u, float cz) {
    if (cz >= 0.0)
        return sb_table_bilinear(k, u, cz);
    float s2 = 1.0 - cz * cz;
    float rt = r * sqrt(s2 > 0.0 ? s2 : 0.0);
    float ux = sb_tangent_coordinate(k, rt);
    return 2.0 * sb_table_bilinear(k, ux, 0.0) - sb_table_bilinear(k, u, -cz);
}

float sb_distance_to_sphere_exit(float r, float mu, float R) {
    float d = R * R - r * r * (1.0 - mu * mu);
    float s = -r * mu + sqrt(d > 0.0 ? d : 0.0);
    return s > 0.0 ? s : 0.0;
}

float sb_distance_to_ground(float r, float mu, float R0) {
    if (mu >= 0.0)
        return -1.0;
    float d = R0 * R0 - r * r * (1.0 - mu * mu);
    if (d < 0.0)
        return -1.0;
    float s = -r * mu - sqrt(d);
    return s > 0.0 ? s : 0.0;
}

bool sb_in_planet_shadow(float r, float cos_sun_zenith, float R0) {
    return cos_sun_zenith < 0.0 && r * r * (1.0 - cos_sun_zenith * cos_sun_zenith) < R0 * R0;
}

struct SbObserver {
    float r;   // km from the planet centre
    float h;   // km above the ground
    float cv;  // cos α0
    float cvs; // cos β0
    float cs;  // cos θ0
};

bool sb_enter_atmosphere(inout SbObserver o) {
    if (o.r <= u_Rtop)
        return true;
    float b = o.r * o.cv;
    float disc = b * b - (o.r - u_Rtop) * (o.r + u_Rtop);
    if (b >= 0.0 || disc <= 0.0)
        return false;
    float v = -b - sqrt(disc);
    float r = u_Rtop;
    o.cv = (o.r * o.cv + v) / r;
    o.cs = (o.r * o.cs + v * o.cvs) / r;
    o.cv = clamp(o.cv, -1.0, 1.0);
    o.cs = clamp(o.cs, -1.0, 1.0);
    o.r = r;
    o.h = u_Rtop - u_R0;
    return true;
}

vec3 sb_exp3(vec3 t) { return vec3(exp(-t.x), exp(-t.y), exp(-t.z)); }

vec3 sb_segment_transmittance(float ra, float ha, float ca, float rb, float hb, float cb) {
    vec3 tau = vec3(0.0);
    for (int k = 0; k < u_count; ++k) {
        float la = sb_optical_length(k, ra, sb_table_coordinate(k, ha, sb_density(k, ha)), ca);
        float lb = sb_optical_length(k, rb, sb_table_coordinate(k, hb, sb_density(k, hb)), cb);
        float t = la - lb;
        tau += u_ext[k] * (t > 0.0 ? t : 0.0);
    }
    return sb_exp3(tau);
}

vec3 sb_sun_transmittance(float r, float h, float cos_sun_zenith) {
    if (sb_in_planet_shadow(r, cos_sun_zenith, u_R0))
        return vec3(0.0);
    vec3 tau = vec3(0.0);
    for (int k = 0; k < u_count; ++k) {
        float u = sb_table_coordinate(k, h, sb_density(k, h));
        tau += u_ext[k] * sb_optical_length(k, r, u, cos_sun_zenith);
    }
    return sb_exp3(tau);
}

// ---- multiple scattering (sky/multiple_hd.h) ----------------------------------------------
uniform int u_ms_method;        // 0 none, 1 orders, 2 hillaire (sky::kMultiple*)
uniform samplerBuffer u_ms;     // R32F, RGB triples: the orders grid, then ψms, then the sky irradiance
uniform ivec4 u_ms_grid;        // orders: nr, nmu (per half), nmus, nnu
uniform float u_ms_mu_s_min;
uniform ivec3 u_ms_psi;         // ψms: first triple, nr, nmus
uniform ivec3 u_ms_irr;         // sky irradiance: first triple, nr, nmus (nr 0: none)

vec3 sb_ms_fetch(int i) {
    return vec3(texelFetch(u_ms, 3 * i).r, texelFetch(u_ms, 3 * i + 1).r, texelFetch(u_ms, 3 * i + 2).r);
}

float sb_distance_to_top(float r, float mu, float Rt) {
    return -r * mu + sqrt(max(r * r * (mu * mu - 1.0) + Rt * Rt, 0.0));
}

// grid_axis: cell index and fraction of x in [0, 1] over n nodes.
int sb_grid_axis(float x, int n, out float f) {
    float s = max(x * float(n - 1), 0.0);
    int i = min(int(s), n - 2);
    f = min(s - float(i), 1.0);
    return i;
}

// orders_lookup(): grid4_coordinates, then the quadrilinear grid4_lookup.
vec3 sb_orders_lookup(float r, float mu, float mu_s, float nu) {
    float R0 = u_R0, Rt = u_Rtop;
    float H = sqrt(max(Rt * Rt - R0 * R0, 0.0));
    r = clamp(r, R0, Rt);
    float rho = sqrt(max(r * r - R0 * R0, 0.0));
    float xr = rho / H, xmu;
    float rmu = r * mu;
    float disc = rmu * rmu - r * r + R0 * R0;
    int ground = mu < 0.0 && disc >= 0.0 ? 1 : 0;
    if (ground == 1) {
        float d = -rmu - sqrt(max(disc, 0.0));
        float dmin = r - R0, dmax = rho;
        xmu = dmax > dmin ? clamp((d - dmin) / (dmax - dmin), 0.0, 1.0) : 0.0;
    } else {
        float d = -rmu + sqrt(max(disc + H * H, 0.0));
        float dmin = Rt - r, dmax = rho + H;
        xmu = clamp((d - dmin) / (dmax - dmin), 0.0, 1.0);
    }
    float dmin = Rt - R0, dmax = H;
    float a = (sb_distance_to_top(R0, mu_s, Rt) - dmin) / (dmax - dmin);
    float A = (sb_distance_to_top(R0, u_ms_mu_s_min, Rt) - dmin) / (dmax - dmin);
    float x = 1.0 - a / A;
    float xmus = clamp((x > 0.0 ? x : 0.0) / (1.0 + a), 0.0, 1.0);
    float xnu = clamp((nu + 1.0) * 0.5, 0.0, 1.0);
    int nr = u_ms_grid.x, nmu = u_ms_grid.y, nmus = u_ms_grid.z, nnu = u_ms_grid.w;
    float fr, fm, fs, fn;
    int ir = sb_grid_axis(xr, nr, fr), im = sb_grid_axis(xmu, nmu, fm), is = sb_grid_axis(xmus, nmus, fs),
        in_ = sb_grid_axis(xnu, nnu, fn);
    vec3 sum = vec3(0.0);
    for (int ia = 0; ia < 2; ++ia)
        for (int ib = 0; ib < 2; ++ib)
            for (int isu = 0; isu < 2; ++isu)
                for (int inu = 0; inu < 2; ++inu) {
                    float w = (ia == 1 ? fr : 1.0 - fr) * (ib == 1 ? fm : 1.0 - fm) * (isu == 1 ? fs : 1.0 - fs) *
                              (inu == 1 ? fn : 1.0 - fn);
                    int idx = ((((ir + ia) * 2 + ground) * nmu + im + ib) * nmus + is + isu) * nnu + in_ + inu;
                    sum += w * sb_ms_fetch(idx);
                }
    return sum;
}

// altitude_sun_lookup(): bilinear over (h / (Rt − R0), (μs + 1) / 2).
vec3 sb_altitude_sun_lookup(ivec3 t, float h, float mu_s) {
    float fr, fs;
    int i = sb_grid_axis(clamp(h / (u_Rtop - u_R0), 0.0, 1.0), t.y, fr);
    int j = sb_grid_axis(clamp(0.5 * (mu_s + 1.0), 0.0, 1.0), t.z, fs);
    vec3 v = vec3(0.0);
    for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b) {
            float w = (a == 1 ? fr : 1.0 - fr) * (b == 1 ? fs : 1.0 - fs);
            v += w * sb_ms_fetch(t.x + (i + a) * t.z + (j + b));
        }
    return v;
}

// The scattered sky light on a horizontal surface (0 without multiple scattering).
vec3 sb_sky_irradiance(float h, float mu_s) {
    return u_ms_irr.y > 0 ? sb_altitude_sun_lookup(u_ms_irr, h, mu_s) : vec3(0.0);
}

#ifdef SKYBAKE_SKY_REFERENCE
// ---- the seed's marching sum (sky::seed_sky_sum) -----------------------------------
vec3 sb_scatter[SKYBAKE_MAX_COMPONENTS];
float sb_l_obs[SKYBAKE_MAX_COMPONENTS];
float sb_base;
vec3 sb_ms_result; // Hillaire's part of the current sum

void sb_sum_point(SbObserver o, float v, float dv, inout vec3 result) {
    float d2 = sb_base + v * (v + 2.0 * o.r * o.cv);
    d2 = d2 > 0.0 ? d2 : 0.0;
    float rv = sqrt(u_R0 * u_R0 + d2);
    float hv = d2 / (rv + u_R0);
    float inv_r = 1.0 / rv;
    float cav = min(max((o.r * o.cv + v) * inv_r, -1.0), 1.0);
    float cth = min(max((o.r * o.cs + v * o.cvs) * inv_r, -1.0), 1.0);
    if (u_ms_method == 2) { // Hillaire's march (sky::HillairePoint), shadowed or not
        vec3 tau_v = vec3(0.0), sigma_s = vec3(0.0);
        for (int k = 0; k < u_count; ++k) {
            float rho = sb_density(k, hv);
            float u = sb_table_coordinate(k, hv, rho);
            tau_v += u_ext[k] * (sb_l_obs[k] - sb_optical_length(k, rv, u, cav));
            sigma_s += u_sca[k] * rho;
        }
        sb_ms_result += sigma_s * sb_altitude_sun_lookup(u_ms_psi, hv, cth) * (dv * sb_exp3(tau_v));
    }
    if (sb_in_planet_shadow(rv, cth, u_R0))
        return;
    vec3 tau = vec3(0.0), weight = vec3(0.0);
    for (int k = 0; k < u_count; ++k) {
        float rho = sb_density(k, hv);
        float u = sb_table_coordinate(k, hv, rho);
        float t = sb_l_obs[k] - sb_optical_length(k, rv, u, cav) + sb_optical_length(k, rv, u, cth);
        tau += u_ext[k] * t;
        weight += sb_scatter[k] * rho;
    }
    result += weight * (dv * sb_exp3(tau));
}

void sb_sum_graded(SbObserver o, float v0, float D, float dir, float s, int n, inout vec3 result) {
    if (n <= 0 || D <= 0.0)
        return;
    float w = log(1.0 + D / s);
    for (int j = 0; j < n; ++j) {
        float t = (float(j) + 0.5) / float(n);
        float e = exp(w * t);
        sb_sum_point(o, v0 + dir * s * (e - 1.0), s * w * e / float(n), result);
    }
}

// limit: distance from the observer to a surface above the sphere R0 where
// the ray ends (< 0: none).
vec3 sb_seed_sky_sum(SbObserver o, float limit) {
    vec3 result = vec3(0.0);
    float v_enter = 0.0; // distance from the observer to where the ray enters the atmosphere
    if (o.r > u_Rtop) {
        float b = o.r * o.cv;
        v_enter = -b - sqrt(max(b * b - (o.r - u_Rtop) * (o.r + u_Rtop), 0.0));
    }
    if (!sb_enter_atmosphere(o))
        return result;
    float ground = sb_distance_to_ground(o.r, o.cv, u_R0);
    float len = ground >= 0.0 ? ground : sb_distance_to_sphere_exit(o.r, o.cv, u_Rtop);
    if (limit >= 0.0)
        len = min(len, limit - v_enter);
    if (len <= 0.0 || u_steps <= 0)
        return result;
    for (int k = 0; k < u_count; ++k) {
        sb_scatter[k] = u_sca[k] * sb_phase(u_phase[k], u_g[k], o.cvs);
        float rho = sb_density(k, o.h);
        sb_l_obs[k] = sb_optical_length(k, o.r, sb_table_coordinate(k, o.h, rho), o.cv);
    }
    sb_base = o.h * (2.0 * u_R0 + o.h);
    if (u_spacing == 1) {
        float dv = len / float(u_steps);
        for (int j = 0; j < u_steps; ++j)
            sb_sum_point(o, (float(j) + 0.5) * dv, dv, result);
        return result;
    }
    float v_low = -o.r * o.cv;
    v_low = clamp(v_low, 0.0, len);
    float d2 = sb_base + v_low * (v_low + 2.0 * o.r * o.cv);
    float r_low = sqrt(u_R0 * u_R0 + (d2 > 0.0 ? d2 : 0.0));
    float mu_low = abs(o.r * o.cv + v_low) / r_low;
    float H = 1.0 / u_inv_scale_height[0];
    float s = H / (mu_low + sqrt(2.0 * H / r_low));
    float before = v_low, after = len - v_low;
    float wb = log(1.0 + before / s), wa = log(1.0 + after / s);
    int nb = int(float(u_steps) * wb / (wb + wa) + 0.5);
    nb = before > 0.0 && nb < 1 ? 1 : nb;
    nb = after > 0.0 && nb > u_steps - 1 ? u_steps - 1 : nb;
    sb_sum_graded(o, v_low, before, -1.0, s, nb, result);
    sb_sum_graded(o, v_low, after, 1.0, s, u_steps - nb, result);
    return result;
}

// sky::sky_sum(): the seed's sum plus the multiple-scattering part. limit as
// sb_seed_sky_sum; with the orders grid, the part beyond a surface at `limit`
// is the grid there times the transmittance in between (Bruneton's aerial perspective).
vec3 sb_sky_sum(SbObserver o, float limit) {
    sb_ms_result = vec3(0.0);
    vec3 c = sb_seed_sky_sum(o, limit);
    if (u_ms_method == 2)
        c += sb_ms_result;
    SbObserver e = o;
    if (u_ms_method == 1 && sb_enter_atmosphere(e)) {
        vec3 ms = sb_orders_lookup(e.r, e.cv, e.cs, e.cvs);
        if (limit >= 0.0) {
            float rp = sqrt(max(o.r * o.r + limit * limit + 2.0 * o.r * limit * o.cv, 0.0));
            float mup = clamp((o.r * o.cv + limit) / rp, -1.0, 1.0);
            float musp = clamp((o.r * o.cs + limit * o.cvs) / rp, -1.0, 1.0);
            vec3 t = sb_segment_transmittance(e.r, e.h, e.cv, rp, rp - u_R0, mup);
            ms = max(ms - t * sb_orders_lookup(rp, mup, musp, o.cvs), vec3(0.0));
        }
        c += ms;
    }
    return c;
}
#endif

// ---- per-ray shading (sky::shade_ray / neural::shade_ray_neural) ---------------------
// Everything but the sun disc: the sky (or the light in front of the ground and
// the lit ground), per unit irradiance. d: unit view direction. sun_t: the
// transmittance towards the sun disc, 0 where the disc cannot be seen.
vec3 sb_shade_ray(vec3 d, out vec3 sun_t) {
    SbObserver o = SbObserver(u_eye_r, u_eye_h, dot(d, u_up), dot(d, u_sun), dot(u_up, u_sun));
    SbObserver e = o;
    bool inside = sb_enter_atmosphere(e);
    vec3 c = vec3(0.0);
#ifdef SKYBAKE_SKY_REFERENCE
    c = sb_sky_sum(o, -1.0);
#else
    if (inside)
        c = skybake_sky(e.cv, e.cvs, e.cs, sb_density(0, e.h));
#endif
    float b = o.r * o.cv;
    float disc = b * b - o.h * (2.0 * u_R0 + o.h);
    bool ground = b < 0.0 && disc >= 0.0;
    sun_t = vec3(0.0);
    if (ground) {
        float t = -b - sqrt(disc);
        vec3 g = u_eye_r * u_up + t * d;
        vec3 n = g / length(g);
        float cos_sun = dot(n, u_sun);
#ifndef SKYBAKE_SKY_REFERENCE
        if (inside)
            c = max(c - skybake_sky(dot(n, d), o.cvs, cos_sun, 1.0), vec3(0.0));
#endif
        if (cos_sun > 0.0 || u_ms_irr.y > 0) {
            vec3 reflected = vec3(0.0);
            if (cos_sun > 0.0)
                reflected = u_albedo * (cos_sun / SKYBAKE_PI) * sb_sun_transmittance(u_R0, 0.0, cos_sun);
            reflected += u_albedo * (1.0 / SKYBAKE_PI) * sb_sky_irradiance(0.0, cos_sun); // multiple scattering
            if (u_published_ground != 0) {
                vec3 bs = vec3(0.0);
                for (int k = 0; k < u_count; ++k)
                    bs += u_sca[k] * sb_density(k, 0.0);
                reflected *= bs;
            }
            if (inside)
                reflected *= sb_segment_transmittance(e.r, e.h, e.cv, u_R0, 0.0, dot(n, d));
            c += reflected;
        }
    } else {
        sun_t = inside ? sb_sun_transmittance(e.r, e.h, e.cv) : vec3(1.0);
    }
    return c;
}

// The ground seen along d at the surface point g (planet-centred, km) with
// unit shading normal nrm and altitude h_g (0 on the smooth sphere).
vec3 sb_shade_ground(vec3 d, vec3 g, vec3 nrm, float h_g, float dist) {
    SbObserver o = SbObserver(u_eye_r, u_eye_h, dot(d, u_up), dot(d, u_sun), dot(u_up, u_sun));
    SbObserver e = o;
    bool inside = sb_enter_atmosphere(e);
    vec3 up_g = g / length(g);
    float r_g = u_R0 + h_g;
    float cos_sun_g = dot(up_g, u_sun);
    vec3 c = vec3(0.0);
#ifdef SKYBAKE_SKY_REFERENCE
    c = sb_sky_sum(o, h_g > 0.0 ? dist : -1.0);
#else
    if (inside) {
        c = skybake_sky(e.cv, e.cvs, e.cs, sb_density(0, e.h));
        c = max(c - skybake_sky(dot(up_g, d), o.cvs, cos_sun_g, sb_density(0, h_g)), vec3(0.0));
    }
#endif
    float cos_sun = dot(nrm, u_sun);
    if (cos_sun > 0.0 || u_ms_irr.y > 0) {
        vec3 reflected = vec3(0.0);
        if (cos_sun > 0.0)
            reflected = u_albedo * (cos_sun / SKYBAKE_PI) * sb_sun_transmittance(r_g, h_g, cos_sun_g);
        reflected += u_albedo * (1.0 / SKYBAKE_PI) * sb_sky_irradiance(h_g, cos_sun_g); // multiple scattering
        if (u_published_ground != 0) {
            vec3 bs = vec3(0.0);
            for (int k = 0; k < u_count; ++k)
                bs += u_sca[k] * sb_density(k, h_g);
            reflected *= bs;
        }
        if (inside)
            reflected *= sb_segment_transmittance(e.r, e.h, e.cv, r_g, h_g, dot(up_g, d));
        c += reflected;
    }
    return c;
}

