// The GLSL side of the sky model's shared maths: src/sky/grid4_shared.h,
// src/sky/sky_shared.h and src/sky/shade_shared.h, written once in the common
// subset of C++ and GLSL, follow this text (planet_renderer.cpp puts them in
// that order). Here are what those files leave to each language: the data
// handles (texture rows and texel offsets instead of pointers), the texel
// reads, the sky function of the network, and the uniforms.
//
// Expects, before it: the #version line, shared_source.glsl, SKYBAKE_SKY_NETWORK
// or SKYBAKE_SKY_REFERENCE, and (network) vec3 skybake_sky(float, float, float, float).

// Optical lengths: R32F, cols wide, rows × components high; component k's
// table starts at row u_render.atm.comp[k].table.L.
uniform sampler2D u_tables;
// Multiple scattering: R32F, RGB triples; each MultipleHD handle is the index
// of its table's first triple (orders, ψms, sky irradiance).
uniform samplerBuffer u_ms;

#define SB_DATA int
#define SB_TABLE_TEXEL(t, i, j) texelFetch(u_tables, ivec2((j), (t).L + (i)), 0).r
#define SB_MS_RGB(p, i) vec3(texelFetch(u_ms, 3 * ((p) + (i))).r, texelFetch(u_ms, 3 * ((p) + (i)) + 1).r, texelFetch(u_ms, 3 * ((p) + (i)) + 2).r)
#define Real float
#define SB_REAL_SQRT sqrt
#define SB_REAL_LOG log
#define SB_REAL_EXP exp

#define SB_SKY_TEMPLATE
#define SB_SKY_PARAM int sky_fn
#define SB_SKY_ARG sky_fn
#ifdef SKYBAKE_SKY_NETWORK
#define SB_SKY(cv, cvs, cs, rho) skybake_sky(cv, cvs, cs, rho)
#else
#define SB_SKY(cv, cvs, cs, rho) vec3(0.0)
#endif
