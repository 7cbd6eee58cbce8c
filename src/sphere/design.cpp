// Spherical t-designs computed in the library.
//
// Delsarte P., Goethals J. M., Seidel J. J. Spherical codes and designs. Geom.
// Dedicata 6, 1977: a t-design is an equal-weight rule exact for degree ≤ t,
// equivalently Σ_j Y_lm(x_j) = 0 for 1 ≤ l ≤ t. Following Gräf M., Potts D. On
// the computation of spherical designs by a new optimization approach based on
// fast spherical Fourier transforms. Numer. Math. 119, 2011, we solve those
// (t+1)² − 1 equations directly, here by Levenberg–Marquardt with the minimum-norm
// step (the system is underdetermined: 2N − 3 ≥ (t+1)² − 1 free coordinates),
// moving each point in its tangent plane. Derivatives come from evaluating the
// SH recurrence (sh_eval.h) on dual numbers.
//
// Designs are cached on disk (design_cache_dir()), written atomically and
// checked again on load.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <fmt/format.h>

#include "skybake/error.h"
#include "skybake/files.h"
#include "skybake/sh.h"
#include "skybake/sphere.h"
#include "sphere/random_rotation.h"
#include "sphere/sh_eval.h"

namespace skybake {

namespace {

constexpr int kMaxDesignT = 40;
constexpr double kAcceptResidual = 1e-13; // max |(1/N) Σ Y_lm| of a finished design

// Value and derivatives along two tangent directions.
struct Dual2 {
    double v = 0.0, d1 = 0.0, d2 = 0.0;
    Dual2() = default;
    explicit Dual2(double value) : v(value) {}
    Dual2(double value, double a, double b) : v(value), d1(a), d2(b) {}
};
inline Dual2 operator+(Dual2 a, Dual2 b) { return {a.v + b.v, a.d1 + b.d1, a.d2 + b.d2}; }
inline Dual2 operator-(Dual2 a, Dual2 b) { return {a.v - b.v, a.d1 - b.d1, a.d2 - b.d2}; }
inline Dual2 operator*(Dual2 a, Dual2 b) { return {a.v * b.v, a.d1 * b.v + a.v * b.d1, a.d2 * b.v + a.v * b.d2}; }
inline Dual2 operator*(Dual2 a, double s) { return {a.v * s, a.d1 * s, a.d2 * s}; }

void check_t(int t) {
    if (t < 1 || t > kMaxDesignT)
        throw Error(fmt::format("design strength t = {} is out of range 1 to {}", t, kMaxDesignT), "design:tT");
}

// Orthonormal tangent basis at a unit vector.
void tangent_basis(const glm::dvec3& n, glm::dvec3& e1, glm::dvec3& e2) {
    const glm::dvec3 a = std::abs(n.x) < 0.7 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
    e1 = glm::normalize(a - n * glm::dot(a, n));
    e2 = glm::cross(n, e1);
}

// Antipodal designs (Womersley's "efficient symmetric" designs): the rule is
// {±x_1, ..., ±x_M}, so Σ Y_lm vanishes for every odd l by symmetry and only the
// even bands 2 ≤ l ≤ L (L = the even number below the odd strength) remain.
// Residuals r_i = (1/M) Σ_j Y_i(x_j) over those bands, and optionally the
// Jacobian with respect to the tangent coordinates (2 per point).
int odd_strength(int t) { return t % 2 == 1 ? t : t + 1; }

int equation_count(int t) {
    int e = 0;
    for (int l = 2; l <= odd_strength(t) - 1; l += 2)
        e += 2 * l + 1;
    return e;
}

void residuals(int t, const std::vector<glm::dvec3>& x, Eigen::VectorXd& r, Eigen::MatrixXd* jac,
               std::vector<glm::dvec3>* e1s, std::vector<glm::dvec3>* e2s) {
    const int lmax = odd_strength(t) - 1;
    const int count = sh_count(lmax);
    const int rows = equation_count(t);
    const int n = int(x.size());
    r.setZero(rows);
    if (jac)
        jac->setZero(rows, 2 * n);
    std::vector<Dual2> yd(static_cast<std::size_t>(count));
    std::vector<double> y(static_cast<std::size_t>(count));
    const double inv_n = 1.0 / n;
    for (int j = 0; j < n; ++j) {
        const glm::dvec3& p = x[std::size_t(j)];
        if (jac) {
            glm::dvec3 e1, e2;
            tangent_basis(p, e1, e2);
            (*e1s)[std::size_t(j)] = e1;
            (*e2s)[std::size_t(j)] = e2;
            sphere::sh_eval_hd<Dual2>(lmax, Dual2(p.x, e1.x, e2.x), Dual2(p.y, e1.y, e2.y), Dual2(p.z, e1.z, e2.z),
                                      yd.data());
        } else {
            sphere::sh_eval_hd<double>(lmax, p.x, p.y, p.z, y.data());
        }
        int row = 0;
        for (int l = 2; l <= lmax; l += 2) {
            for (int i = l * l; i < (l + 1) * (l + 1); ++i, ++row) {
                if (jac) {
                    r[row] += yd[std::size_t(i)].v * inv_n;
                    (*jac)(row, 2 * j) = yd[std::size_t(i)].d1 * inv_n;
                    (*jac)(row, 2 * j + 1) = yd[std::size_t(i)].d2 * inv_n;
                } else {
                    r[row] += y[std::size_t(i)] * inv_n;
                }
            }
        }
    }
}

// Levenberg–Marquardt from the given start. Returns the final max-norm residual.
double solve(int t, std::vector<glm::dvec3>& x, int& iterations) {
    const int n = int(x.size());
    std::vector<glm::dvec3> e1(static_cast<std::size_t>(n)), e2(static_cast<std::size_t>(n)), trial(static_cast<std::size_t>(n));
    Eigen::VectorXd r, r_trial;
    Eigen::MatrixXd jac;
    residuals(t, x, r, &jac, &e1, &e2);
    double lambda = 1e-3;
    iterations = 0;
    for (int it = 0; it < 150; ++it) {
        ++iterations;
        if (r.lpNorm<Eigen::Infinity>() < 1e-15)
            break;
        const Eigen::MatrixXd jjt = jac * jac.transpose();
        const double scale = jjt.diagonal().maxCoeff();
        bool accepted = false;
        for (int attempt = 0; attempt < 30 && !accepted; ++attempt) {
            Eigen::MatrixXd a = jjt;
            a.diagonal().array() += lambda * scale;
            const Eigen::VectorXd yv = a.ldlt().solve(r);
            const Eigen::VectorXd step = -jac.transpose() * yv;
            for (int j = 0; j < n; ++j) {
                const glm::dvec3 moved = x[std::size_t(j)] + step[2 * j] * e1[std::size_t(j)] +
                                         step[2 * j + 1] * e2[std::size_t(j)];
                trial[std::size_t(j)] = glm::normalize(moved);
            }
            residuals(t, trial, r_trial, nullptr, nullptr, nullptr);
            if (r_trial.squaredNorm() < r.squaredNorm()) {
                accepted = true;
                x = trial;
                lambda = std::max(lambda / 5.0, 1e-15);
            } else {
                lambda *= 8.0;
            }
        }
        if (!accepted)
            break; // no further progress possible in double precision
        residuals(t, x, r, &jac, &e1, &e2);
    }
    return r.lpNorm<Eigen::Infinity>();
}

SphereRule make_design_rule(int t, const std::vector<glm::dvec3>& points) {
    SphereRule rule;
    rule.kind = RuleKind::Design;
    rule.precision = odd_strength(t); // antipodal: exact for the next odd degree too
    rule.spec = fmt::format("design:t{}", t);
    rule.points.reserve(2 * points.size());
    for (const glm::dvec3& p : points)
        rule.points.push_back(p);
    for (const glm::dvec3& p : points)
        rule.points.push_back(-p);
    rule.weights.assign(rule.points.size(), 1.0 / double(rule.points.size()));
    return rule;
}

std::filesystem::path cache_file(int t) {
    return design_cache_dir() / fmt::format("design-v1-t{}.txt", t);
}

// Reads a cached design; returns false when the file is missing, damaged or not a design.
bool load_cached(int t, SphereRule& out) {
    if (design_cache_dir().empty()) // the cache is off
        return false;
    const std::filesystem::path path = cache_file(t);
    std::ifstream in(path);
    if (!in)
        return false;
    std::vector<glm::dvec3> points;
    std::string line;
    while (std::getline(in, line)) {
        if (line.empty() || line[0] == '#')
            continue;
        std::istringstream s(line);
        glm::dvec3 p;
        if (!(s >> p.x >> p.y >> p.z))
            return false;
        if (std::abs(glm::length(p) - 1.0) > 1e-12)
            return false;
        points.push_back(p);
    }
    if (2 * int(points.size()) < design_point_count(t))
        return false;
    out = make_design_rule(t, points);
    return design_residual(out, t) <= kAcceptResidual;
}

void store_cached(int t, const SphereRule& rule, double residual) {
    if (design_cache_dir().empty())
        return;
    try {
        const std::filesystem::path path = cache_file(t);
        std::filesystem::create_directories(path.parent_path());
        write_stream_atomic(path, [&](std::ostream& out) {
            out << fmt::format("# skybake spherical {}-design, {} points, equal weights; max |(1/N) sum Y_lm| = {:.3g}\n",
                               t, rule.points.size(), residual);
            // The first half; the second half is its antipodes.
            for (std::size_t i = 0; i < rule.points.size() / 2; ++i)
                out << fmt::format("{:.17g} {:.17g} {:.17g}\n", rule.points[i].x, rule.points[i].y, rule.points[i].z);
        });
    } catch (const std::exception&) {
        // A read-only or missing cache folder only costs recomputation next time.
    }
}

} // namespace

int design_point_count(int t) {
    check_t(t);
    // 2M points with 2M − 3 ≥ (number of equations) free coordinates.
    const int e = equation_count(t);
    return e == 0 ? 2 : 2 * ((e + 3 + 1) / 2);
}

std::filesystem::path design_cache_dir() { return cache_dir(); }

double design_residual(const SphereRule& rule, int t) {
    const int count = sh_count(t);
    std::vector<double> sum(std::size_t(count), 0.0), y(static_cast<std::size_t>(count));
    for (std::size_t k = 0; k < rule.points.size(); ++k) {
        sh_eval(t, rule.points[k], y.data());
        for (int i = 0; i < count; ++i)
            sum[std::size_t(i)] += rule.weights[k] * y[std::size_t(i)];
    }
    double worst = 0.0;
    for (int i = 1; i < count; ++i)
        worst = std::max(worst, std::abs(sum[std::size_t(i)]));
    return worst;
}

SphereRule compute_design(int t, DesignReport* report) {
    check_t(t);
    const int base = design_point_count(t) / 2; // free half of the antipodal pairs
    std::vector<glm::dvec3> best;
    double best_residual = 1e300;
    int total_iterations = 0;
    // A stalled run (a local minimum of the residual) is restarted from a turned and
    // jittered lattice; after a few stalls one more antipodal pair adds slack.
    for (int extra = 0; extra <= 4 && best_residual > kAcceptResidual; ++extra) {
        const int n = base + extra;
        for (int attempt = 0; attempt < 3 && best_residual > kAcceptResidual; ++attempt) {
            // Start from the northern half of a Fibonacci lattice; the rule adds the antipodes.
            std::vector<glm::dvec3> x = fibonacci_rule(2 * n).points;
            x.resize(std::size_t(n));
            if (attempt > 0) {
                const std::uint64_t seed = 0x5eedull * std::uint64_t(t) + std::uint64_t(attempt);
                const glm::dmat3 rot = sphere::vertex_rotation_hd<double>(0xffffffffu, seed);
                for (std::size_t i = 0; i < x.size(); ++i) {
                    const glm::dmat3 jitter = sphere::vertex_rotation_hd<double>(std::uint32_t(i), seed);
                    x[i] = glm::normalize(rot * x[i] + 0.05 / (t + 1) * (jitter * glm::dvec3(0, 0, 1)));
                }
            }
            int iterations = 0;
            const double residual = solve(t, x, iterations);
            total_iterations += iterations;
            if (residual < best_residual) {
                best_residual = residual;
                best = x;
            }
        }
    }
    if (best_residual > kAcceptResidual)
        throw Error(fmt::format("the design optimiser did not converge for t = {} (residual {:.3g}); use a Lebedev rule "
                                "of the same precision instead",
                                t, best_residual),
                    "design:tT");
    SphereRule rule = make_design_rule(t, best);
    if (report) {
        report->t = t;
        report->points = int(rule.points.size());
        report->iterations = total_iterations;
        report->residual = design_residual(rule, t);
        report->from_cache = false;
    }
    return rule;
}

SphereRule design_rule(int t) {
    check_t(t);
    static std::mutex mutex;
    static std::map<int, SphereRule> memory;
    std::lock_guard<std::mutex> lock(mutex);
    if (auto it = memory.find(t); it != memory.end())
        return it->second;
    SphereRule rule;
    if (!load_cached(t, rule)) {
        DesignReport report;
        rule = compute_design(t, &report);
        store_cached(t, rule, report.residual);
    }
    memory[t] = rule;
    return rule;
}

} // namespace skybake
