// The GLSL side of code written once in the common subset of C++ and GLSL
// (core/shared_source.h is the C++ side): put before the shared files'
// text (render::shaders::tone_curve, ...).
#define SKYBAKE_HD_INLINE
#define SB_IN(T) in T
#define SB_OUT(T) out T
#define SB_INOUT(T) inout T
#define SB_INIT(x)
#define expf exp
#define logf log
#define sqrtf sqrt
#define fabsf abs
#define fminf min
#define fmaxf max
#define powf pow
#define sinf sin
#define cosf cos
#define atan2f atan
