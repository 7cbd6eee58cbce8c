// Stage bodies of the planet renderer, one per SKYBAKE_STAGE_* define:
//   SKY_VS / SKY_FS       sky shell: per-vertex dome and shell, or (FS) the per-pixel pass,
//   PLANET_VS / PLANET_FS the planet mesh (camera-relative positions, km),
//   FLAT_VS / FLAT_FS     a flat-shaded baseline over the same mesh,
// SKYBAKE_PER_PIXEL selects where the sky function runs; per pixel, the sky
// program's vertex stage is screen_stages.glsl's FULL_SCREEN_VS, as is the
// tone pass's, whose TONE_FS is there too.

uniform RenderHD u_render;    // the scene and its atmosphere (sky/shade_shared.h)
uniform mat4 u_view_proj;     // camera-relative world -> clip (rotation and projection only)
uniform vec3 u_forward;       // camera basis (pinhole of sky::pixel_direction)
uniform vec3 u_right;
uniform vec3 u_cam_up;
uniform float u_tan_half_fov; // horizontal
uniform vec2 u_viewport;      // pixels
uniform int u_relief;         // 1: surface heights from the mesh

// Everything but the sun disc along d; sun_t: the transmittance towards the
// sun disc, 0 where the ray meets the ground.
vec3 sb_shade_ray(vec3 d, out vec3 sun_t) {
#ifdef SKYBAKE_SKY_REFERENCE
    return shade_sky(u_render, d, true, sun_t);
#else
    return shade_sky_approximate(u_render, 0, d, true, sun_t);
#endif
}

// The terrain seen along d at g (planet-centred, km): shade_surface.
vec3 sb_shade_ground(vec3 d, vec3 g, vec3 nrm, float h_g, float dist) {
#ifdef SKYBAKE_SKY_REFERENCE
    return shade_surface(u_render, d, g, nrm, h_g, dist);
#else
    return shade_surface_approximate(u_render, 0, d, g, nrm, h_g);
#endif
}

vec3 sb_add_sun(vec3 d, vec3 sun_t) {
    return sees_sun_disc(u_render, d) ? sun_t * u_render.sun_disc_radiance : vec3(0.0);
}

#if defined(SKYBAKE_STAGE_SKY_VS)
// Per vertex, two shells. Inside the atmosphere: a sphere of directions
// around the eye (a_pos is a unit direction). Outside: the top of the
// atmosphere as a mesh (a_pos relative to the eye, km), whose vertices crowd
// where it is seen edge-on, at the limb. In both, directions that meet the
// ground take the sky's colour just above the horizon (the limb): the planet
// mesh covers them, and ground colours would bleed past its edge.
uniform int u_shell;
layout(location = 0) in vec3 a_pos;
out vec3 v_dir;
out vec3 v_colour;
out vec3 v_sun_t;
void main() {
    vec3 d = normalize(a_pos);
    v_dir = d;
    vec3 ds = d;
    {
        float cos_h = -sqrt(max(0.0, 1.0 - (u_render.atm.R0 / u_render.eye_r) * (u_render.atm.R0 / u_render.eye_r)));
        float cz = dot(d, u_render.zenith);
        if (cz < cos_h + 1e-4) {
            vec3 hz = d - cz * u_render.zenith;
            float lh = length(hz);
            hz = lh > 1e-6 ? hz / lh : normalize(cross(u_render.zenith, vec3(0.3, 0.5, 0.8)));
            float c = cos_h + 1e-4;
            ds = c * u_render.zenith + sqrt(max(0.0, 1.0 - c * c)) * hz;
        }
    }
    vec3 sun_t;
    v_colour = sb_shade_ray(ds, sun_t);
    v_sun_t = sun_t;
    vec4 c = u_view_proj * vec4(a_pos, u_shell == 0 ? 0.0 : 1.0);
    gl_Position = vec4(c.xy, 0.0, c.w);
}
#elif defined(SKYBAKE_STAGE_SKY_FS)
out vec4 o_colour;
#ifdef SKYBAKE_PER_PIXEL
void main() {
    float px = (2.0 * gl_FragCoord.x / u_viewport.x - 1.0) * u_tan_half_fov;
    float py = (2.0 * gl_FragCoord.y / u_viewport.y - 1.0) * u_tan_half_fov * u_viewport.y / u_viewport.x;
    vec3 d = normalize(u_forward + px * u_right + py * u_cam_up);
    vec3 sun_t;
    vec3 c = sb_shade_ray(d, sun_t);
    o_colour = vec4((c + sb_add_sun(d, sun_t)) * u_render.irradiance, 1.0);
}
#else
in vec3 v_dir;
in vec3 v_colour;
in vec3 v_sun_t;
void main() {
    vec3 d = normalize(v_dir);
    o_colour = vec4((v_colour + sb_add_sun(d, v_sun_t)) * u_render.irradiance, 1.0);
}
#endif

#elif defined(SKYBAKE_STAGE_PLANET_VS)
layout(location = 0) in vec3 a_pos;    // relative to the camera, km
layout(location = 1) in vec3 a_normal; // unit
out vec3 v_rel;
out vec3 v_normal;
out vec3 v_colour;
vec3 sb_ground(vec3 rel, vec3 nrm) {
    float dist = length(rel);
    vec3 d = rel / dist;
    vec3 g = u_render.eye_r * u_render.zenith + rel;
    float h_g = u_relief != 0 ? max(length(g) - u_render.atm.R0, 0.0) : 0.0;
    return sb_shade_ground(d, g, u_relief != 0 ? nrm : g / length(g), h_g, dist);
}
void main() {
    v_rel = a_pos;
    v_normal = a_normal;
#ifndef SKYBAKE_PER_PIXEL
    v_colour = sb_ground(a_pos, a_normal);
#else
    v_colour = vec3(0.0);
#endif
    gl_Position = u_view_proj * vec4(a_pos, 1.0);
}
#elif defined(SKYBAKE_STAGE_PLANET_FS)
in vec3 v_rel;
in vec3 v_normal;
in vec3 v_colour;
out vec4 o_colour;
vec3 sb_ground(vec3 rel, vec3 nrm) {
    float dist = length(rel);
    vec3 d = rel / dist;
    vec3 g = u_render.eye_r * u_render.zenith + rel;
    float h_g = u_relief != 0 ? max(length(g) - u_render.atm.R0, 0.0) : 0.0;
    return sb_shade_ground(d, g, u_relief != 0 ? normalize(nrm) : g / length(g), h_g, dist);
}
void main() {
#ifdef SKYBAKE_PER_PIXEL
    // Smooth planet: the ray meets the sphere itself just before the inscribed
    // mesh; shading that point (as the CPU renderer does) keeps grazing rays
    // at the limb from seeing a chord's slightly different angles.
    vec3 sun_t;
    vec3 c = u_relief != 0 ? sb_ground(v_rel, v_normal) : sb_shade_ray(normalize(v_rel), sun_t);
    o_colour = vec4(c * u_render.irradiance, 1.0);
#else
    o_colour = vec4(v_colour * u_render.irradiance, 1.0);
#endif
}

#elif defined(SKYBAKE_STAGE_FLAT_VS)
layout(location = 0) in vec3 a_pos;
layout(location = 1) in vec3 a_normal;
out vec3 v_normal;
void main() {
    v_normal = a_normal;
    gl_Position = u_view_proj * vec4(a_pos, 1.0);
}
#elif defined(SKYBAKE_STAGE_FLAT_FS)
in vec3 v_normal;
out vec4 o_colour;
void main() { o_colour = vec4(vec3(max(dot(normalize(v_normal), u_render.sun), 0.0)), 1.0); }

#endif
