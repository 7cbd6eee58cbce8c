// The look-up table a neural sky is compared with: a plain 4D grid over the
// network's inputs holding its encoded outputs, interpolated quadrilinearly
// (Bruneton & Neyret 2008, Bruneton 2017 store the sky this way), fitted by
// linear least squares to the same targets the network learns.
#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <fmt/format.h>

#include "core/parallel.h"
#include "neural/internal.h"
#include "neural/render_hd.h"
#include "sky/device.h"
#include "skybake/error.h"

namespace skybake {

using namespace neural;

namespace {

// The 16 nodes around an input and their weights.
struct Corners {
    int node[16];
    float weight[16];
};

MlpHD encoding_hd(const SkyLookupTable& t) {
    MlpHD m;
    set_encoding_hd(t.encoding, t.atmosphere, m);
    m.outputs = t.encoding.output_count();
    return m;
}

Corners corners(const SkyLookupTable& t, const float in[4]) {
    int base[4];
    float f[4];
    for (int a = 0; a < 4; ++a) {
        const float u = (in[a] - t.lo[a]) / (t.hi[a] - t.lo[a]) * float(t.size[a] - 1);
        const float c = std::clamp(u, 0.0f, float(t.size[a] - 1));
        base[a] = std::min(int(c), t.size[a] - 2);
        f[a] = c - float(base[a]);
    }
    Corners k;
    for (int j = 0; j < 16; ++j) {
        int node = 0, stride = 1;
        float w = 1.0f;
        for (int a = 0; a < 4; ++a) {
            const int bit = (j >> a) & 1;
            node += (base[a] + bit) * stride;
            stride *= t.size[a];
            w *= bit ? f[a] : 1.0f - f[a];
        }
        k.node[j] = node;
        k.weight[j] = w;
    }
    return k;
}

// The table's radiance for one sample of the sky function.
glm::vec3 table_sky(const SkyLookupTable& t, const MlpHD& m, float cv, float cvs, float cs, float rho) {
    float in[kMaxInputs], enc[kMaxOutputs] = {};
    encode_inputs(m, cv, cvs, cs, rho, in);
    const Corners k = corners(t, in);
    const std::size_t outputs = std::size_t(m.outputs);
    for (int a = 0; a < 16; ++a)
        for (std::size_t q = 0; q < outputs; ++q)
            enc[q] += k.weight[a] * t.values[std::size_t(k.node[a]) * outputs + q];
    return decode_sky(m, enc, cvs);
}

// The range of each input of an encoding (mlp_hd.h, encode_inputs).
void input_ranges(const MlpHD& m, std::array<float, 4>& lo, std::array<float, 4>& hi) {
    lo = {-1.0f, -1.0f, -1.0f, 0.0f};
    hi = {1.0f, 1.0f, 1.0f, 1.0f};
    if (m.inputs == kInputsHorizon)
        lo[3] = -1.0f;
}

// Nodes per input for at most `nodes` nodes: as even as possible, the view
// input first, then altitude, the sun and cos β0.
std::array<int, 4> grid_size(std::size_t nodes) {
    std::array<int, 4> n{2, 2, 2, 2};
    const int order[4] = {0, 3, 2, 1};
    for (bool grew = true; grew;) {
        grew = false;
        for (int a : order) {
            std::array<int, 4> m = n;
            ++m[std::size_t(a)];
            if (std::size_t(m[0]) * std::size_t(m[1]) * std::size_t(m[2]) * std::size_t(m[3]) <= nodes) {
                n = m;
                grew = true;
            }
        }
    }
    return n;
}

} // namespace

SkyLookupTable fit_sky_lookup_table(const SkyModel& model, const NeuralTrainOptions& o, std::size_t floats) {
    if (o.outputs == OutputEncoding::Residual)
        throw Error("look-up tables hold radiance or phase-factored outputs, not residual ones", "outputs");
    SkyLookupTable t;
    t.encoding = make_training_encoding(model, o);
    t.atmosphere = model.atmosphere();
    t.sky_options = model.options();
    const int outputs = t.encoding.output_count();
    if (floats / std::size_t(outputs) < 16)
        throw Error(fmt::format("a table of {} outputs needs at least {} floats", outputs, 16 * outputs), "floats");
    t.size = grid_size(floats / std::size_t(outputs));
    const MlpHD m = encoding_hd(t);
    input_ranges(m, t.lo, t.hi);
    const int nodes = t.size[0] * t.size[1] * t.size[2] * t.size[3];
    const TrainingData d = make_training_data(model, t.encoding, o.samples, stream_seed(o.seed, 0), o.device);

    // Per output, the objective of internal.h (kTableRidge): normal equations with
    // 16 × 16 blocks per sample. The mask is the same for R, G, B (radiance
    // outputs) and 1 elsewhere, so outputs with the same mask share a matrix.
    t.values.assign(std::size_t(nodes) * std::size_t(outputs), 0.0f);
    std::vector<Corners> k(d.size());
    parallel_for(d.size(), 4096, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i)
            k[i] = corners(t, d.x.col(Eigen::Index(i)).data());
    });
    // A node's neighbours in the normal matrix lie within ±1 node along every
    // input: 3⁴ = 81 of them, accumulated per node by offset code
    // Σ (d_a + 1) 3^a, then handed to Eigen once.
    std::array<int, 4> stride{};
    for (int a = 0, s = 1; a < 4; ++a) {
        stride[std::size_t(a)] = s;
        s *= t.size[std::size_t(a)];
    }
    int code[16][16];
    for (int a = 0; a < 16; ++a)
        for (int b = 0; b < 16; ++b) {
            code[a][b] = 0;
            for (int axis = 0, p = 1; axis < 4; ++axis, p *= 3)
                code[a][b] += (((b >> axis) & 1) - ((a >> axis) & 1) + 1) * p;
        }
    std::vector<double> band;
    for (int out = 0; out < outputs; ++out) {
        int same = -1; // an earlier output with the same mask row
        for (int p = 0; p < out && same < 0; ++p)
            if (d.mask.row(p) == d.mask.row(out))
                same = p;
        if (same < 0)
            band.assign(std::size_t(nodes) * 81, 0.0);
        Eigen::VectorXd rhs = Eigen::VectorXd::Zero(nodes);
        for (std::size_t i = 0; i < d.size(); ++i) {
            const double w = d.mask(out, Eigen::Index(i));
            if (w == 0.0)
                continue;
            const double target = d.t(out, Eigen::Index(i));
            for (int a = 0; a < 16; ++a) {
                const double wa = w * double(k[i].weight[a]);
                rhs(k[i].node[a]) += wa * target;
                if (same < 0) {
                    double* row = &band[std::size_t(k[i].node[a]) * 81];
                    for (int b = 0; b < 16; ++b)
                        row[code[a][b]] += wa * double(k[i].weight[b]);
                }
            }
        }
        static thread_local Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver;
        if (same < 0) {
            std::vector<Eigen::Triplet<double>> entries;
            entries.reserve(std::size_t(nodes) * 81);
            double diagonal = 0.0;
            for (int j = 0; j < nodes; ++j)
                for (int c = 0; c < 81; ++c) {
                    const double v = band[std::size_t(j) * 81 + std::size_t(c)];
                    if (v == 0.0)
                        continue;
                    int other = j;
                    for (int axis = 0, q = c; axis < 4; ++axis, q /= 3)
                        other += (q % 3 - 1) * stride[std::size_t(axis)];
                    entries.emplace_back(j, other, v);
                    if (c == 40)
                        diagonal += v;
                }
            // A small first-difference penalty along every input keeps nodes
            // that few samples touch near their neighbours instead of free.
            const double scale = std::max(1e-30, diagonal / double(nodes)), smooth = kTableSmoothing * scale;
            for (int j = 0; j < nodes; ++j)
                for (int axis = 0; axis < 4; ++axis) {
                    const int at = (j / stride[std::size_t(axis)]) % t.size[std::size_t(axis)];
                    if (at + 1 >= t.size[std::size_t(axis)])
                        continue;
                    const int other = j + stride[std::size_t(axis)];
                    entries.emplace_back(j, j, smooth);
                    entries.emplace_back(other, other, smooth);
                    entries.emplace_back(j, other, -smooth);
                    entries.emplace_back(other, j, -smooth);
                }
            Eigen::SparseMatrix<double> A(nodes, nodes);
            A.setFromTriplets(entries.begin(), entries.end());
            const double ridge = kTableRidge * scale;
            for (int j = 0; j < nodes; ++j)
                A.coeffRef(j, j) += ridge;
            solver.compute(A);
            if (solver.info() != Eigen::Success)
                throw Error("the table's least squares did not factor", "floats");
        }
        const Eigen::VectorXd v = solver.solve(rhs);
        for (int j = 0; j < nodes; ++j)
            t.values[std::size_t(j) * std::size_t(outputs) + std::size_t(out)] = float(v(j));
    }
    return t;
}

void evaluate_sky_lookup_table(const SkyLookupTable& t, std::span<const SkySample> samples, std::span<glm::vec3> out) {
    assert(samples.size() == out.size());
    const MlpHD m = encoding_hd(t);
    parallel_for(samples.size(), 2048, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) {
            const SkySample& s = samples[i];
            out[i] = table_sky(t, m, s.cos_view_zenith, s.cos_view_sun, s.cos_sun_zenith, s.density);
        }
    });
}

NeuralErrorReport measure_sky_lookup_table_error(const SkyLookupTable& t, const NeuralErrorOptions& o) {
    const SkyModel model(t.atmosphere, t.sky_options);
    const MlpHD m = encoding_hd(t);
    auto sky = [&](float cv, float cvs, float cs, float rho) { return table_sky(t, m, cv, cvs, cs, rho); };
    return measure_approximation_error(
        model, t.encoding.max_n, o,
        [&](std::span<const SkySample> s, std::span<const float>, std::span<glm::vec3> out) {
            evaluate_sky_lookup_table(t, s, out);
        },
        [&](const SkyRenderSettings& v, double, const SkyModel&) {
            const sky::RenderHD p = sky::make_render_hd(model, v);
            return sky::render_pixels(p, [&](const glm::vec3& d) { return shade_ray_approximate(p, sky, d); });
        });
}

} // namespace skybake
