// skybake.Rule and the spherical harmonics (skybake/sphere.h, skybake/sh.h).
#include <cstring>

#include "common.h"
#include "skybake/sh.h"
#include "skybake/sphere.h"

namespace skybake::python {

void bind_sphere(py::module_& m) {
    py::class_<SphereRule>(m, "Rule",
                           "A sphere rule {x_k, w_k}: Σ_k w_k f(x_k) ≈ (1/4π) ∫ f dω (weights sum to 1).")
        .def(py::init([](const std::string& spec) { return parse_rule(spec); }), py::arg("spec"),
             "From a spec: 'lebedev:590', 'design:20', 'mc:1024', 'fibonacci:500', 'phong:A:N', with an "
             "optional '+rotate[=SEED]'. Raises skybake.Error for an unknown spec.")
        .def_readonly("spec", &SphereRule::spec, "The canonical spec.")
        .def_property_readonly("kind", [](const SphereRule& r) { return std::string(rule_kind_name(r.kind)); })
        .def_readonly("precision", &SphereRule::precision, "Algebraic degree; -1 when the rule has none.")
        .def_readonly("rotate", &SphereRule::rotate_per_vertex, "Turned by a random rotation at each vertex.")
        .def_property_readonly("size", &SphereRule::size)
        .def("__len__", &SphereRule::size)
        .def_property_readonly(
            "points",
            [](const SphereRule& r) {
                std::vector<double> flat(r.size() * 3);
                if (!flat.empty())
                    std::memcpy(flat.data(), r.points.data(), flat.size() * sizeof(double));
                return to_numpy(std::move(flat), {py::ssize_t(r.size()), 3});
            },
            "(K, 3) float64 unit vectors (a copy).")
        .def_property_readonly(
            "weights",
            [](const SphereRule& r) {
                std::vector<double> w = r.weights;
                return to_numpy(std::move(w), {py::ssize_t(r.size())});
            },
            "(K,) float64 (a copy); they sum to 1.")
        .def("__repr__", [](const SphereRule& r) { return "Rule('" + r.spec + "')"; });

    m.def("sh_count", [](int order) { return sh_count(order); }, py::arg("order"),
          "(order + 1)² coefficients up to band `order`.");
    m.def("sh_index", [](int l, int mm) { return sh_index(l, mm); }, py::arg("l"), py::arg("m"),
          "Index of Y_lm: l² + l + m.");
    m.def(
        "sh_eval",
        [](int order, const py::handle& directions) {
            if (order < 0 || order > 16)
                throw Error("order must be in 0..16, got " + std::to_string(order), "order");
            const auto dirs = checked_array<double>(directions, "directions", {-1, 3}, true);
            const std::size_t n = std::size_t(dirs.shape(0));
            const int k = sh_count(order);
            std::vector<double> out(n * std::size_t(k));
            const double* d = dirs.data();
            {
                py::gil_scoped_release release;
                for (std::size_t i = 0; i < n; ++i)
                    sh_eval(order, glm::dvec3(d[3 * i], d[3 * i + 1], d[3 * i + 2]), out.data() + i * std::size_t(k));
            }
            return to_numpy(std::move(out), {py::ssize_t(n), k});
        },
        py::arg("order"), py::arg("directions"),
        "Real orthonormal SH Y_lm at unit directions (N, 3) float64: (N, (order + 1)²) float64, column "
        "sh_index(l, m).");
}

} // namespace skybake::python
