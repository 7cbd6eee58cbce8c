// Stages shared by the planet and model renderers, one per SKYBAKE_STAGE_* define:
//   FULL_SCREEN_VS  one triangle covering the viewport (glDrawArrays(GL_TRIANGLES, 0, 3),
//                   no attributes), for the per-pixel passes,
//   TONE_FS         exposure, a tone curve and the sRGB encoding of a linear float
//                   target (the window): skybake::tone_map_value and linear_to_srgb.
// Before this text: shared_source.glsl, then tone_curve (core/tone_curve.h, the
// curves' one source, compiled as C++ by core/image.cpp).

#if defined(SKYBAKE_STAGE_FULL_SCREEN_VS)
void main() {
    vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
#elif defined(SKYBAKE_STAGE_TONE_FS)
uniform sampler2D u_image;
uniform float u_exposure_scale; // 2^exposure_ev
uniform int u_tone;             // skybake::ToneCurve: 0 clamp, 1 reinhard, 2 aces
uniform ivec2 u_offset;         // of the image in the window, pixels
out vec4 o_colour;
// tone_map_value() then linear_to_srgb() (0 for values that are not > 0).
float sb_tone(float v) {
    return v > 0.0 ? srgb_encode(tone_curve(u_tone, v * u_exposure_scale)) : 0.0;
}
void main() {
    vec3 c = texelFetch(u_image, ivec2(gl_FragCoord.xy) - u_offset, 0).rgb;
    o_colour = vec4(sb_tone(c.r), sb_tone(c.g), sb_tone(c.b), 1.0);
}
#endif
