// Seams of a UV layout, made invisible in a baked texture.
//
// Liu, Ferguson & Jacobson, "Seamless: Seam erasure and seam-aware
// decoupling of shape from mesh resolution", ACM Transactions on Graphics
// 36(6), 2017 (SIGGRAPH Asia), section 4: along every seam the two sides'
// bilinear look-ups should agree; the texels under them are changed as little
// as possible (least squares) so that they do. Here the seam edges are the
// mesh edges whose two triangles share the 3D end points but not the UVs,
// each sampled a few times per texel of its length, and the texels are solved
// for in the sparse normal equations (CᵀC + λI) x = λ x₀.
#include "skybake/texture_bake.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <unordered_map>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <fmt/format.h>

#include "skybake/error.h"

namespace skybake {

namespace {

// The weight of "stay as baked" against "agree across the seam": small, so
// the seam agrees to about λ / (σ² + λ) of its old mismatch, large enough to
// keep the system positive definite and the change local.
constexpr double kLambda = 1e-4;

// The bilinear stencil of a look-up at uv, as sample_texture() reads it.
struct Stencil {
    std::array<std::uint32_t, 4> texel;
    std::array<double, 4> weight;
};

Stencil stencil_at(glm::dvec2 uv, int size) {
    const double fx = std::clamp(uv.x * size - 0.5, 0.0, double(size - 1));
    const double fy = std::clamp(uv.y * size - 0.5, 0.0, double(size - 1));
    const int x0 = int(fx), y0 = int(fy);
    const int x1 = std::min(x0 + 1, size - 1), y1 = std::min(y0 + 1, size - 1);
    const double tx = fx - x0, ty = fy - y0;
    auto k = [&](int x, int y) { return std::uint32_t(std::size_t(y) * std::size_t(size) + std::size_t(x)); };
    return {{k(x0, y0), k(x1, y0), k(x0, y1), k(x1, y1)},
            {(1 - tx) * (1 - ty), tx * (1 - ty), (1 - tx) * ty, tx * ty}};
}

double read(const std::vector<float>& values, const Stencil& s) {
    double v = 0.0;
    for (int i = 0; i < 4; ++i)
        v += s.weight[i] * values[s.texel[i]];
    return v;
}

// One side of a seam edge: its UVs at the edge's two welded end points.
struct Side {
    glm::vec2 uv0, uv1;
};

// Bit-exact position keys, so that only vertices at the same point weld.
struct PositionKey {
    std::uint32_t x, y, z;
    bool operator==(const PositionKey&) const = default;
};
struct PositionHash {
    std::size_t operator()(const PositionKey& k) const {
        return (std::size_t(k.x) * 0x9E3779B97F4A7C15ull) ^ (std::size_t(k.y) * 0xC2B2AE3D27D4EB4Full) ^ k.z;
    }
};
PositionKey key_of(glm::vec3 p) {
    PositionKey k;
    p += glm::vec3(0.0f); // -0 and +0 weld
    std::memcpy(&k.x, &p.x, 4);
    std::memcpy(&k.y, &p.y, 4);
    std::memcpy(&k.z, &p.z, 4);
    return k;
}

} // namespace

SeamStitchReport stitch_texture_seams(const Mesh& mesh, int uv_set, std::vector<float>& values, int size) {
    const std::size_t texel_count = std::size_t(size) * std::size_t(size);
    if (size <= 0 || values.size() != texel_count)
        throw Error(fmt::format("{} values for a {}² texture", values.size(), size), "values");
    if (uv_set < 0 || std::size_t(uv_set) >= mesh.texcoords.size())
        throw Error(fmt::format("the mesh has no UV set {}", uv_set), "uv_set");
    const std::vector<glm::vec2>& uv = mesh.texcoords[std::size_t(uv_set)];

    // Weld the vertices by position; an edge is then a pair of welded ids.
    std::unordered_map<PositionKey, std::uint32_t, PositionHash> ids;
    std::vector<std::uint32_t> weld(mesh.vertex_count());
    for (std::size_t v = 0; v < weld.size(); ++v)
        weld[v] = ids.emplace(key_of(mesh.positions[v]), std::uint32_t(ids.size())).first->second;
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<Side>> edges;
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t)
        for (int e = 0; e < 3; ++e) {
            std::uint32_t a = mesh.indices[3 * t + e], b = mesh.indices[3 * t + (e + 1) % 3];
            if (weld[a] == weld[b])
                continue; // degenerate edge
            if (weld[a] > weld[b])
                std::swap(a, b);
            edges[{weld[a], weld[b]}].push_back({uv[a], uv[b]});
        }

    // The constraints: per seam edge, look-ups along both sides agree.
    SeamStitchReport report;
    std::vector<std::pair<Stencil, Stencil>> pairs;
    for (const auto& [edge, sides] : edges)
        for (std::size_t i = 0; i < sides.size(); ++i)
            for (std::size_t j = i + 1; j < sides.size(); ++j) {
                const Side &a = sides[i], &b = sides[j];
                if (a.uv0 == b.uv0 && a.uv1 == b.uv1)
                    continue; // the same UVs: no seam
                ++report.seam_edges;
                const double len = std::max(glm::length(glm::dvec2(a.uv1 - a.uv0)),
                                            glm::length(glm::dvec2(b.uv1 - b.uv0))) *
                                   size;
                const int n = std::clamp(int(std::ceil(2.0 * len)) + 1, 2, 4 * size);
                for (int s = 0; s < n; ++s) {
                    const double f = double(s) / double(n - 1);
                    const glm::dvec2 ua = glm::mix(glm::dvec2(a.uv0), glm::dvec2(a.uv1), f);
                    const glm::dvec2 ub = glm::mix(glm::dvec2(b.uv0), glm::dvec2(b.uv1), f);
                    pairs.push_back({stencil_at(ua, size), stencil_at(ub, size)});
                }
            }
    if (pairs.empty())
        return report;

    // The unknowns: the texels under some look-up.
    std::unordered_map<std::uint32_t, int> column;
    std::vector<std::uint32_t> texel_of;
    auto col = [&](std::uint32_t k) {
        const auto [it, fresh] = column.emplace(k, int(texel_of.size()));
        if (fresh)
            texel_of.push_back(k);
        return it->second;
    };
    std::vector<Eigen::Triplet<double>> c;
    c.reserve(pairs.size() * 8);
    for (std::size_t r = 0; r < pairs.size(); ++r) {
        const auto& [a, b] = pairs[r];
        const double before = std::abs(read(values, a) - read(values, b));
        report.mismatch_before_max = std::max(report.mismatch_before_max, before);
        report.mismatch_before_mean += before / double(pairs.size());
        for (int i = 0; i < 4; ++i) {
            c.emplace_back(int(r), col(a.texel[i]), a.weight[i]);
            c.emplace_back(int(r), col(b.texel[i]), -b.weight[i]);
        }
    }
    const int n = int(texel_of.size());
    Eigen::SparseMatrix<double> cm(int(pairs.size()), n);
    cm.setFromTriplets(c.begin(), c.end()); // duplicates (a texel on both sides) are summed
    Eigen::SparseMatrix<double> normal = cm.transpose() * cm;
    Eigen::VectorXd x0(n);
    for (int j = 0; j < n; ++j) {
        normal.coeffRef(j, j) += kLambda;
        x0[j] = values[texel_of[std::size_t(j)]];
    }
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(normal);
    if (solver.info() != Eigen::Success)
        throw Error("the seam system could not be factored", "values");
    const Eigen::VectorXd x = solver.solve(kLambda * x0);
    for (int j = 0; j < n; ++j)
        values[texel_of[std::size_t(j)]] = float(std::clamp(x[j], 0.0, 1.0));
    report.texels_changed = std::size_t(n);
    for (const auto& [a, b] : pairs) {
        const double after = std::abs(read(values, a) - read(values, b));
        report.mismatch_after_max = std::max(report.mismatch_after_max, after);
        report.mismatch_after_mean += after / double(pairs.size());
    }
    report.lookups = pairs.size();
    return report;
}

} // namespace skybake
