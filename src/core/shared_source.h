// The C++ side of code written once in the common subset of C++ and GLSL
// (Bruneton's habit in "Precomputed Atmospheric Scattering": functions.glsl
// compiles as GLSL and, after `#define IN(x) const x&`, as C++).
//
// A shared file (e.g. core/tone_curve.h) holds only functions and constants
// that both languages accept: float literals with the f suffix, switch,
// `const int` globals, structs passed by value, no pointers, references,
// templates, default arguments, `constexpr` or `const` locals. It includes
// nothing itself; C++ includes it after this header (inside a namespace),
// and skybake_embed_glsl (cmake/SkybakeShaders.cmake, SHARED) embeds its text
// for the shaders, which put src/render/shaders/shared_source.glsl, the GLSL
// side of these macros, before it.
#pragma once

#include <cmath>

#include "core/hd.h" // SKYBAKE_HD_INLINE: inline, __host__ __device__ under nvcc; empty in GLSL

// Parameters: SB_IN(T) x is read-only, SB_OUT(T) x written, SB_INOUT(T) x both.
#define SB_IN(T) const T&
#define SB_OUT(T) T&
#define SB_INOUT(T) T&
// A struct member's default value: SB_INIT(x) is " = x" in C++, nothing in GLSL.
#define SB_INIT(x) = x
// The C maths names (expf, sqrtf, powf, ...) are the shared spelling; GLSL maps them to its own.
