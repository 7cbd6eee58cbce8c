// Adaptive Gauss–Kronrod quadrature (7-point Gauss, 15-point Kronrod), the
// rule of QUADPACK's QK15: Piessens R. et al., QUADPACK, Springer 1983.
// Vector-valued (glm::dvec3) so that three colour channels share the nodes.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/vec3.hpp>

namespace skybake::sky {

struct GaussKronrod15 {
    static constexpr double x[8] = {0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
                                    0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
                                    0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
                                    0.207784955007898467600689403773245, 0.000000000000000000000000000000000};
    static constexpr double wk[8] = {0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
                                     0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
                                     0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
                                     0.204432940075298892414161999234649, 0.209482141084727828012999174891714};
    // Gauss weights for the nodes x[1], x[3], x[5], x[7].
    static constexpr double wg[4] = {0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
                                     0.381830050505118944950369775488975, 0.417959183673469387755102040816327};
};

// Gauss–Legendre nodes and weights on [0, 1] (Newton on P_n from the
// Chebyshev guesses; converged to double precision).
inline void gauss_legendre_unit(int n, std::vector<double>& x, std::vector<double>& w) {
    x.assign(std::size_t(n), 0.0);
    w.assign(std::size_t(n), 0.0);
    for (int i = 0; i < n; ++i) {
        double z = std::cos(3.14159265358979323846 * (double(i) + 0.75) / (double(n) + 0.5)), dp = 1.0;
        for (int it = 0; it < 100; ++it) {
            double p0 = 1.0, p1 = z;
            for (int k = 2; k <= n; ++k) {
                const double p2 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / double(k);
                p0 = p1;
                p1 = p2;
            }
            if (n == 1)
                p0 = 1.0, p1 = z;
            dp = double(n) * (z * p1 - p0) / (z * z - 1.0);
            const double dz = p1 / dp;
            z -= dz;
            if (std::abs(dz) < 1e-15)
                break;
        }
        x[std::size_t(i)] = 0.5 * (1.0 - z);
        w[std::size_t(i)] = 1.0 / ((1.0 - z * z) * dp * dp);
    }
}

inline double max_abs(const glm::dvec3& v) { return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)}); }

// One panel: Kronrod estimate, and |Kronrod − Gauss| as the error.
template <class F>
glm::dvec3 gk15_panel(const F& f, double a, double b, double& error) {
    using R = GaussKronrod15;
    const double c = 0.5 * (a + b), h = 0.5 * (b - a);
    glm::dvec3 k(0.0), g(0.0);
    const glm::dvec3 fc = f(c);
    k += R::wk[7] * fc;
    g += R::wg[3] * fc;
    for (int i = 0; i < 7; ++i) {
        const glm::dvec3 s = f(c - h * R::x[i]) + f(c + h * R::x[i]);
        k += R::wk[i] * s;
        if (i % 2 == 1)
            g += R::wg[i / 2] * s;
    }
    error = max_abs(k - g) * h;
    return k * h;
}

// Integral of f over [a, b] split first at the sorted breakpoints, then by
// bisection of the worst panel until the summed error is ≤ max(abs_tol,
// rel_tol·|I|), or max_panels is reached.
template <class F>
glm::dvec3 integrate_adaptive(const F& f, const std::vector<double>& breakpoints, double rel_tol, double abs_tol,
                              int max_panels = 2000) {
    struct Panel {
        double a, b, err;
        glm::dvec3 val;
    };
    std::vector<Panel> panels;
    panels.reserve(64);
    glm::dvec3 total(0.0);
    double err_total = 0.0;
    for (std::size_t i = 0; i + 1 < breakpoints.size(); ++i) {
        const double a = breakpoints[i], b = breakpoints[i + 1];
        if (!(b > a))
            continue;
        double e;
        const glm::dvec3 v = gk15_panel(f, a, b, e);
        panels.push_back({a, b, e, v});
        total += v;
        err_total += e;
    }
    while (int(panels.size()) < max_panels) {
        if (err_total <= std::max(abs_tol, rel_tol * max_abs(total)))
            break;
        auto worst = std::max_element(panels.begin(), panels.end(),
                                      [](const Panel& p, const Panel& q) { return p.err < q.err; });
        const Panel p = *worst;
        const double mid = 0.5 * (p.a + p.b);
        if (!(mid > p.a && mid < p.b))
            break;
        double e1, e2;
        const glm::dvec3 v1 = gk15_panel(f, p.a, mid, e1);
        const glm::dvec3 v2 = gk15_panel(f, mid, p.b, e2);
        *worst = {p.a, mid, e1, v1};
        panels.push_back({mid, p.b, e2, v2});
        total += v1 + v2 - p.val;
        err_total = std::max(0.0, err_total + e1 + e2 - p.err);
    }
    return total;
}

// Breakpoints on [a, b]: the ends, the given interior points, and points at
// distances scale·2^k on both sides of each "centre" (where the integrand is
// sharpest), so that no initial panel is much wider than the local scale.
inline std::vector<double> graded_breakpoints(double a, double b, const std::vector<double>& centres, double scale,
                                              const std::vector<double>& extra = {}) {
    std::vector<double> pts{a, b};
    for (double p : extra)
        if (p > a && p < b)
            pts.push_back(p);
    if (scale > 0.0) {
        for (double c : centres) {
            if (!(c >= a && c <= b))
                continue;
            pts.push_back(c);
            for (double d = scale; d < (b - a); d *= 2.0) {
                if (c - d > a)
                    pts.push_back(c - d);
                if (c + d < b)
                    pts.push_back(c + d);
            }
        }
    }
    std::sort(pts.begin(), pts.end());
    pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
    return pts;
}

} // namespace skybake::sky
