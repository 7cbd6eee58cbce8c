// Stage bodies of the model viewer, one per SKYBAKE_STAGE_* define:
//   BACKGROUND_FS                  the sky network per pixel,
//   BACKGROUND_MAP_FS              the reference sky's map (relative azimuth × zenith angle) per pixel,
//   MODEL_VS / MODEL_FS            the model: relight() of skybake/prt.h per vertex,
//                                  the sun per pixel (shadow map) and the DPRT glossy layer,
//   FLAT_VS / FLAT_FS              the same mesh in one constant colour (baseline),
//   DEPTH_FS                       depth only (the shadow map, with FLAT_VS),
// The backgrounds' vertex stage and the window's tone pass are screen_stages.glsl's.
// Before this text: the network's GLSL (skybake_sky) with SKYBAKE_NETWORK, and
// export_prt_glsl()'s skybake_prt_diffuse with SKYBAKE_PRT_ATTRIBUTES and
// SKYBAKE_SH_COUNT defined.

// The equirectangular layout of equirect_direction() in model_renderer.cpp:
// u = φ / 2π + ½ with φ = atan2(x, z), v = θ / π from the zenith (+y).
vec2 sb_equirect_uv(vec3 d) {
    return vec2(atan(d.x, d.z) * 0.159154943 + 0.5, acos(clamp(d.y, -1.0, 1.0)) * 0.318309886);
}

#if defined(SKYBAKE_STAGE_BACKGROUND_FS)
uniform vec3 u_forward; // camera basis of preview_camera()
uniform vec3 u_right;
uniform vec3 u_up;
uniform float u_tan_half_fov_y;
uniform float u_aspect;
uniform vec2 u_viewport; // pixels
uniform vec3 u_sun;      // unit, towards the sun, +y up
uniform float u_density; // SkySample::density of the observer
out vec4 o_colour;
void main() {
    // gl_FragCoord.y counts from the bottom row: cy = (1 − 2 py) tan with py from the top.
    float cx = (2.0 * gl_FragCoord.x / u_viewport.x - 1.0) * u_tan_half_fov_y * u_aspect;
    float cy = (2.0 * gl_FragCoord.y / u_viewport.y - 1.0) * u_tan_half_fov_y;
    vec3 d = normalize(u_forward + cx * u_right + cy * u_up);
    vec3 l = skybake_sky(clamp(d.y, -1.0, 1.0), clamp(dot(d, u_sun), -1.0, 1.0), clamp(u_sun.y, -1.0, 1.0), u_density);
    o_colour = vec4(max(l, vec3(0.0)), 0.0);
}
#elif defined(SKYBAKE_STAGE_BACKGROUND_MAP_FS)
uniform vec3 u_forward; // camera basis of preview_camera()
uniform vec3 u_right;
uniform vec3 u_up;
uniform float u_tan_half_fov_y;
uniform float u_aspect;
uniform vec2 u_viewport;      // pixels
uniform vec3 u_sun;            // unit, towards the sun, +y up
uniform sampler2D u_sky_map;  // the reference sky by (relative azimuth ψ / π, zenith angle θ / π)
out vec4 o_colour;
void main() {
    float cx = (2.0 * gl_FragCoord.x / u_viewport.x - 1.0) * u_tan_half_fov_y * u_aspect;
    float cy = (2.0 * gl_FragCoord.y / u_viewport.y - 1.0) * u_tan_half_fov_y;
    vec3 d = normalize(u_forward + cx * u_right + cy * u_up);
    // ψ: the angle between the horizontal parts of the view and the sun (0 with the sun at the zenith).
    vec2 dh = d.xz, sh = u_sun.xz;
    float psi = dot(sh, sh) > 1e-12 ? atan(abs(dh.x * sh.y - dh.y * sh.x), dot(dh, sh)) : 0.0;
    vec2 uv = vec2(psi * 0.318309886, acos(clamp(d.y, -1.0, 1.0)) * 0.318309886);
    o_colour = vec4(max(texture(u_sky_map, uv).rgb, vec3(0.0)), 0.0);
}
#elif defined(SKYBAKE_STAGE_MODEL_VS)
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec3 a_albedo;
layout(location = 3) in vec4 a_extra; // (visibility of the sun or of one direction, shading coefficient A, UV)
layout(location = 4) in vec4 a_prt[SKYBAKE_PRT_ATTRIBUTES];
uniform mat4 u_clip_from_world;
uniform vec3 u_light[SKYBAKE_SH_COUNT];
uniform vec3 u_sun;            // unit, towards the sun
uniform vec3 u_sun_irradiance; // transmitted, on a surface facing the sun
out vec3 v_sky;        // ρ Σ L_lm T_lm
out vec3 v_sun_vertex; // ρ (1/π) (n·s)+ E_sun V_sun with the per-vertex V_sun
out vec3 v_albedo;
out vec3 v_normal;
out vec3 v_world;
out float v_visible;
out float v_a;
out vec2 v_uv;
void main() {
    // relight(): B = ρ Σ L_lm T_lm + ρ (1/π) (n·s)+ E_sun V_sun.
    vec4 prt[SKYBAKE_PRT_ATTRIBUTES];
    for (int i = 0; i < SKYBAKE_PRT_ATTRIBUTES; ++i)
        prt[i] = a_prt[i];
    v_sky = skybake_prt_diffuse(prt, u_light, a_albedo);
    v_sun_vertex = a_albedo * (0.318309886 * max(dot(a_normal, u_sun), 0.0) * a_extra.x) * u_sun_irradiance;
    v_albedo = a_albedo;
    v_normal = a_normal;
    v_world = a_position;
    v_visible = a_extra.x;
    v_a = a_extra.y;
    v_uv = a_extra.zw;
    gl_Position = u_clip_from_world * vec4(a_position, 1.0);
}
#elif defined(SKYBAKE_STAGE_MODEL_FS)
in vec3 v_sky;
in vec3 v_sun_vertex;
in vec3 v_albedo;
in vec3 v_normal;
in vec3 v_world;
in float v_visible;
in float v_a;
in vec2 v_uv;
uniform sampler2D u_base_color;      // the material's base colour image (linear), white if none
uniform int u_mode;   // 0: diffuse, 1: diffuse + DPRT glossy, 2: visibility of one direction
uniform int u_shadow; // the sun's shadow: 0 shadow map, 1 per vertex, 2 none
uniform vec3 u_sun;
uniform vec3 u_sun_irradiance;
uniform vec3 u_eye;                  // world space
uniform sampler2DShadow u_shadow_map;
uniform mat4 u_shadow_from_world;    // to [0, 1]³ of the shadow map
uniform float u_shadow_offset;       // normal offset, world units (1.5 texels)
uniform float u_shadow_texel;        // 1 / the map's size
uniform sampler2D u_glossy;          // Σ_k λ_k L(g_r x_k) by mirror direction r (sb_equirect_uv)
uniform float u_specular;
out vec4 o_colour;

// Percentage-closer filtering, 3×3 taps of the hardware's 2×2 comparison.
float sb_sun_shadow(vec3 p, vec3 n) {
    vec4 q = u_shadow_from_world * vec4(p + u_shadow_offset * n, 1.0);
    float lit = 0.0;
    for (int y = -1; y <= 1; ++y)
        for (int x = -1; x <= 1; ++x)
            lit += texture(u_shadow_map, vec3(q.xy + vec2(x, y) * u_shadow_texel, q.z));
    return lit / 9.0;
}

void main() {
    // The albedo is the vertex's (factor × colour) × the image at this pixel;
    // the vertex stage's terms carry the first factor.
    vec3 image = texture(u_base_color, v_uv).rgb;
    vec3 albedo = v_albedo * image;
    if (u_mode == 2) {
        o_colour = vec4(albedo * mix(0.04, 1.0, v_visible), 1.0);
        return;
    }
    vec3 b = v_sky * image;
    float len = length(v_normal);
    vec3 n = len > 0.0 ? v_normal / len : vec3(0.0, 1.0, 0.0);
    if (u_shadow == 1) {
        b += v_sun_vertex * image;
    } else if (any(greaterThan(u_sun_irradiance, vec3(0.0)))) {
        float ns = dot(n, u_sun);
        if (ns > 0.0) {
            float v = u_shadow == 0 ? sb_sun_shadow(v_world, n) : 1.0;
            b += albedo * (0.318309886 * ns * v) * u_sun_irradiance;
        }
    }
    if (u_mode == 1 && len > 0.0) {
        // render_prt_preview(): specular · A · Σ_k λ_k L(g_nv x_k), the normal turned towards the eye.
        vec3 view = normalize(u_eye - v_world);
        if (dot(n, view) < 0.0)
            n = -n;
        vec3 r = 2.0 * dot(n, view) * n - view;
        b += u_specular * v_a * texture(u_glossy, sb_equirect_uv(r)).rgb;
    }
    o_colour = vec4(b, 1.0);
}
#elif defined(SKYBAKE_STAGE_FLAT_VS)
layout(location = 0) in vec3 a_position;
uniform mat4 u_clip_from_world;
void main() {
    gl_Position = u_clip_from_world * vec4(a_position, 1.0);
}
#elif defined(SKYBAKE_STAGE_FLAT_FS)
out vec4 o_colour;
void main() {
    o_colour = vec4(0.5, 0.5, 0.5, 1.0);
}
#elif defined(SKYBAKE_STAGE_DEPTH_FS)
void main() {}
#endif
