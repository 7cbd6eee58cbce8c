// Stage bodies of the model viewer, one per SKYBAKE_STAGE_* define:
//   BACKGROUND_VS / BACKGROUND_FS  the sky network per pixel (full-screen triangle),
//   MODEL_VS / MODEL_FS            the model: relight() of skybake/prt.h per vertex,
//   FLAT_VS / FLAT_FS              the same mesh in one constant colour (baseline).
// Before this text: the network's GLSL (skybake_sky) with SKYBAKE_NETWORK, and
// export_prt_glsl()'s skybake_prt_diffuse with SKYBAKE_PRT_ATTRIBUTES and
// SKYBAKE_SH_COUNT defined.

#if defined(SKYBAKE_STAGE_BACKGROUND_VS)
void main() {
    vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
#elif defined(SKYBAKE_STAGE_BACKGROUND_FS)
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
#elif defined(SKYBAKE_STAGE_MODEL_VS)
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec3 a_albedo;
layout(location = 3) in float a_sun_visible;
layout(location = 4) in vec4 a_prt[SKYBAKE_PRT_ATTRIBUTES];
uniform mat4 u_clip_from_world;
uniform vec3 u_light[SKYBAKE_SH_COUNT];
uniform vec3 u_sun;            // unit, towards the sun
uniform vec3 u_sun_irradiance; // transmitted, on a surface facing the sun
out vec3 v_radiance;
void main() {
    // relight(): B = ρ Σ L_lm T_lm + ρ (1/π) (n·s)+ E_sun V_sun.
    vec4 prt[SKYBAKE_PRT_ATTRIBUTES];
    for (int i = 0; i < SKYBAKE_PRT_ATTRIBUTES; ++i)
        prt[i] = a_prt[i];
    vec3 b = skybake_prt_diffuse(prt, u_light, a_albedo);
    b += a_albedo * (0.318309886 * max(dot(a_normal, u_sun), 0.0) * a_sun_visible) * u_sun_irradiance;
    v_radiance = b;
    gl_Position = u_clip_from_world * vec4(a_position, 1.0);
}
#elif defined(SKYBAKE_STAGE_MODEL_FS)
in vec3 v_radiance;
out vec4 o_colour;
void main() {
    o_colour = vec4(v_radiance, 1.0);
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
#endif
