// skybake/sphere.h: quadrature rules on the unit sphere.
//
// The cubature part of Svistunov's shading-coefficient paper (seed 002): a rule
// Q f = Σ λ_k f(x_k) replaces an integral over the sphere by a weighted sum over
// directions. Spherical harmonics live in skybake/sh.h.
//
// [SECTION] Conventions
// [SECTION] Rules
// [SECTION] Rule specs
// [SECTION] Rule families
// [SECTION] Per-vertex random rotation
// [SECTION] Spherical designs and their cache
//
// See docs/sphere.md for the maths, the measured errors and examples.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

namespace skybake {

// [SECTION] Conventions ----------------------------------------------------------
//
// Points are unit vectors (x, y, z) in whatever frame the caller uses; a rule
// has no preferred axis except the Phong rules, whose lobe axis is +z.
//
// Weights are for the normalised measure dμ = dω / 4π (seed 002), so that
//     Σ_k w_k f(x_k) ≈ ∫_S² f dμ = (1/4π) ∫_S² f dω,   and   Σ_k w_k = 1.
// Multiply by 4π for an integral over solid angle in steradians.
//
// Phong rules integrate against a normalised lobe instead (see phong_rule()):
//     Σ_k w_k f(x_k) ≈ ∫_S² f(x) ρ_a(x) dμ,   ρ_a(x) = 2(a + 1) max(z, 0)^a,
// with ∫ ρ_a dμ = 1, so their weights also sum to 1.
//
// "Precision" is the algebraic degree: a rule of precision p integrates every
// polynomial in x, y, z of total degree ≤ p exactly (to rounding). Monte Carlo
// and Fibonacci rules have none (-1).

// [SECTION] Rules -------------------------------------------------------------------

enum class RuleKind : int {
    MonteCarlo = 0, // Marsaglia 1972 points, equal weights
    Fibonacci = 1,  // spherical Fibonacci lattice, equal weights
    Lebedev = 2,    // Lebedev–Laikov, octahedral symmetry, unequal weights
    Design = 3,     // spherical t-design, equal weights
    Phong = 4,      // Gauss–Jacobi in cos θ × uniform in φ, for the Phong lobe
    Horizon = 5,    // Gauss–Legendre in y on each side of y = 0 × uniform in φ
};

// "mc", "fibonacci", "lebedev", "design", "phong", "horizon".
const char* rule_kind_name(RuleKind kind);

struct SphereRule {
    std::string spec;                // canonical rule spec, e.g. "lebedev:5810"
    RuleKind kind = RuleKind::MonteCarlo;
    int precision = -1;              // algebraic degree; -1 when the rule has none
    std::vector<glm::dvec3> points;  // unit vectors
    std::vector<double> weights;     // one per point; they sum to 1 (may be negative: Lebedev 74/230/266)
    // Set by a "+rotate" spec: callers should turn the rule by vertex_rotation(vertex,
    // rotation_seed) at each vertex (see [SECTION] Per-vertex random rotation).
    bool rotate_per_vertex = false;
    std::uint64_t rotation_seed = 0;

    std::size_t size() const { return points.size(); }
    bool has_negative_weights() const;
    // Flat single-precision copies for GPU kernels: size() entries each.
    std::vector<glm::vec3> points_f32() const;
    std::vector<float> weights_f32() const;
};

// Σ_k w_k f(x_k), in double precision.
template <class F>
double integrate(const SphereRule& rule, F&& f) {
    double sum = 0.0;
    for (std::size_t k = 0; k < rule.points.size(); ++k)
        sum += rule.weights[k] * f(rule.points[k]);
    return sum;
}

// [SECTION] Rule specs --------------------------------------------------------------
//
// One string names a rule everywhere (CLI flags, config files, caches):
//
//   mc:N[,seed=S]       N Marsaglia points (Monte Carlo), seed S (default 1)
//   fibonacci:N         N-point spherical Fibonacci lattice
//   lebedev:N           the Lebedev–Laikov rule with N points (6 ... 5810)
//   lebedev:pP          ... or with precision P (3 ... 131)
//   design:tT           spherical T-design, 1 ≤ T ≤ 40 (computed once, then cached)
//   phong:a=A,n=N       Phong-lobe rule, exponent A ≥ 0, N nodes in cos θ (2N² points,
//                       precision 2N-1)
//   horizon:NxM         split at the horizon y = 0: N Gauss–Legendre nodes in y on
//                       each side times M azimuths (2NM points, precision
//                       min(2N - 1, M - 1)); for functions with a step there (skies)
//
// Any of them may end in "+rotate" or "+rotate=SEED": the rule is then meant to be
// turned by a random rotation at every vertex (SphereRule::rotate_per_vertex).
struct RuleSpec {
    RuleKind kind = RuleKind::MonteCarlo;
    int count = 0;                 // mc, fibonacci: number of points
    std::uint64_t seed = 1;        // mc: random seed
    int precision = 0;             // lebedev: precision; design: t
    double phong_exponent = 0.0;   // phong: a
    int phong_nodes = 0;           // phong: nodes in cos θ
    int horizon_nodes = 0;         // horizon: Gauss–Legendre nodes in y per side
    int horizon_azimuths = 0;      // horizon: azimuths
    bool rotate = false;           // "+rotate"
    std::uint64_t rotation_seed = 0;

    // The canonical text form, e.g. "lebedev:5810", "mc:1000,seed=7+rotate=3".
    std::string canonical() const;
};

// Parses a rule spec. Throws skybake::Error naming the problem and listing the
// valid forms (e.g. the available Lebedev point counts) on a bad spec.
RuleSpec parse_rule_spec(const std::string& text);

// Builds the rule a spec names. Designs come from the design cache (or are
// computed and stored there). Throws skybake::Error on a bad spec.
SphereRule make_rule(const RuleSpec& spec);
// parse_rule_spec() + make_rule().
SphereRule parse_rule(const std::string& text);

// [SECTION] Rule families -------------------------------------------------------------

// Marsaglia (1972), exactly as in seed 002: draw ξ1, ξ2 uniform on (−1, 1) until
// s = ξ1² + ξ2² < 1, then x = (2ξ1√(1−s), 2ξ2√(1−s), 1 − 2s). Weights 1/n.
// Deterministic for a given (n, seed), whatever the platform. n ≥ 1.
SphereRule marsaglia_rule(int n, std::uint64_t seed = 1);

// Spherical Fibonacci lattice: z_k = 1 − (2k + 1)/n, φ_k = 2π k / Φ (golden
// ratio Φ). Weights 1/n. n ≥ 1.
SphereRule fibonacci_rule(int n);

// The Lebedev–Laikov rules: precision 3 to 31 in steps of 2, then 35 to 131 in
// steps of 6; 6 to 5810 points.
struct LebedevInfo {
    int precision;
    int points;
};
const std::vector<LebedevInfo>& lebedev_rules();
// Throws skybake::Error when no rule has that precision / point count.
SphereRule lebedev_rule_by_precision(int precision);
SphereRule lebedev_rule_by_points(int points);

// Phong-lobe rule for DPRT: Gauss–Jacobi nodes in t = cos θ for the weight t^a on
// [0, 1] (n nodes) times 2n equally spaced azimuths. Points lie on the upper
// hemisphere (z > 0); Σ w_k f(x_k) = ∫ f ρ_a dμ exactly for every polynomial f
// of degree ≤ 2n − 1 (see [SECTION] Conventions). a ≥ 0 (any real), 1 ≤ n ≤ 512.
SphereRule phong_rule(double exponent_a, int n);

// A rule split at the horizon of the sky and PRT frames (+y up): n
// Gauss–Legendre nodes in y = cos θ on (0, 1) and n on (−1, 0), each times m
// equally spaced azimuths (φ = 2π (j + ½)/m from +x towards +z). No point lies
// on y = 0, and each side is integrated as a rule of its own, so a function
// with a step at the horizon (a sky over the dark ground) is integrated as
// well as the two smooth halves are: exact for polynomials of degree
// ≤ min(2n − 1, m − 1) on each side. 1 ≤ n ≤ 512, 1 ≤ m ≤ 4096.
SphereRule horizon_rule(int n, int m);

// [SECTION] Per-vertex random rotation -----------------------------------------------
//
// A uniformly distributed random rotation that depends only on (vertex, seed),
// so a bake is reproducible and independent of the thread count. The same maths
// is available to CUDA kernels as sphere::vertex_rotation_hd() in
// src/sphere/random_rotation.h. Apply it as x' = R x.
glm::dmat3 vertex_rotation(std::uint32_t vertex, std::uint64_t seed);

// [SECTION] Spherical designs and their cache -----------------------------------------
//
// A spherical t-design is an equal-weight rule with Σ_j Y_lm(x_j) = 0 for all
// 1 ≤ l ≤ t, i.e. precision t. skybake computes them itself, by Levenberg–Marquardt
// on those equations (Gräf & Potts 2011 style) from a Fibonacci start. Designs are
// antipodal ({±x_j}, Womersley's "symmetric" designs): the odd bands vanish by
// symmetry, a design for even t is also one for t + 1, and the point count is
// design_point_count(t) ≈ t²/2 + t/2 (234 for t = 21, where Hardin & Sloane list
// 240), or a few more if the optimiser needed slack to leave a local minimum.
//
// Computed designs are cached as text files in design_cache_dir(), which is
// skybake::cache_dir() (skybake/files.h): the folder in $SKYBAKE_CACHE_DIR if
// set ("off": no disk cache, designs are kept in memory only), else
// $XDG_CACHE_HOME/skybake, else ~/.cache/skybake.
// Files are written atomically, and checked again when read (a stale or damaged
// file is recomputed).
// The smallest point count the optimiser tries for strength t (even, 2 for t = 1).
int design_point_count(int t);
std::filesystem::path design_cache_dir();
// Cached design (memory, then disk, then computed and stored). 1 ≤ t ≤ 40.
SphereRule design_rule(int t);

struct DesignReport {
    int t = 0;
    int points = 0;
    int iterations = 0;
    double residual = 0.0; // max_{1≤l≤t, m} |(1/N) Σ_j Y_lm(x_j)|
    bool from_cache = false;
};
// Computes a design without touching the cache.
SphereRule compute_design(int t, DesignReport* report = nullptr);
// max_{1≤l≤t, m} |Σ_k w_k Y_lm(x_k)|: 0 for a rule of precision ≥ t.
double design_residual(const SphereRule& rule, int t);

} // namespace skybake
