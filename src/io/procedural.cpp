// Deterministic procedural meshes for tests and benchmarks.
// Value-noise fBm after K. Perlin, "An Image Synthesizer", SIGGRAPH 1985;
// geodesic sphere by frequency-n subdivision of the icosahedron.
//
// Everything here uses integer hashing and fixed evaluation order, so the
// output is the same for the same options on every run and thread count
// (bit-identical across machines that share the C maths library).
#include <algorithm>
#include <array>
#include <cmath>
#include <map>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "core/random.h"
#include "skybake/error.h"
#include "skybake/names.h"
#include "skybake/mesh.h"

namespace skybake {

namespace {

constexpr double kPi = 3.14159265358979323846;


// Uniform in [0, 1), from 53 bits of a hash.
double hash01(std::uint64_t seed, std::int64_t a, std::int64_t b = 0, std::int64_t c = 0) {
    std::uint64_t h = splitmix64(seed ^ splitmix64(std::uint64_t(a) ^ splitmix64(std::uint64_t(b) ^ splitmix64(std::uint64_t(c)))));
    return double(h >> 11) * (1.0 / 9007199254740992.0);
}

double value_noise(std::uint64_t seed, double x, double y) {
    const double fx = std::floor(x), fy = std::floor(y);
    const auto ix = std::int64_t(fx), iy = std::int64_t(fy);
    double tx = x - fx, ty = y - fy;
    tx = tx * tx * (3 - 2 * tx);
    ty = ty * ty * (3 - 2 * ty);
    const double a = hash01(seed, ix, iy), b = hash01(seed, ix + 1, iy);
    const double c = hash01(seed, ix, iy + 1), d = hash01(seed, ix + 1, iy + 1);
    return (a + (b - a) * tx) + ((c + (d - c) * tx) - (a + (b - a) * tx)) * ty;
}

double fbm(std::uint64_t seed, double x, double y) {
    double sum = 0, amp = 0.5, freq = 2.0;
    for (int o = 0; o < 6; ++o) {
        sum += amp * (value_noise(seed + std::uint64_t(o), x * freq, y * freq) - 0.5);
        amp *= 0.5;
        freq *= 2.0;
    }
    return sum;
}

struct Builder {
    Mesh mesh;
    std::uint32_t vertex(glm::vec3 p, glm::vec3 n) {
        mesh.positions.push_back(p);
        mesh.normals.push_back(n);
        return std::uint32_t(mesh.positions.size() - 1);
    }
    void tri(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
        mesh.indices.insert(mesh.indices.end(), {a, b, c});
    }
    // A grid of (nu+1) x (nv+1) vertices from f(u, v) in [0,1]^2; two
    // triangles per cell, counter-clockwise when f's du x dv is the front.
    template <class F>
    void grid(int nu, int nv, F f) {
        const auto base = std::uint32_t(mesh.positions.size());
        for (int j = 0; j <= nv; ++j)
            for (int i = 0; i <= nu; ++i) {
                auto [p, n] = f(double(i) / nu, double(j) / nv);
                vertex(p, n);
            }
        const auto row = std::uint32_t(nu + 1);
        for (int j = 0; j < nv; ++j)
            for (int i = 0; i < nu; ++i) {
                const std::uint32_t a = base + std::uint32_t(j) * row + std::uint32_t(i);
                tri(a, a + 1, a + row + 1);
                tri(a, a + row + 1, a + row);
            }
    }
};

using PN = std::pair<glm::vec3, glm::vec3>;

Mesh icosphere(std::uint64_t target) {
    // Frequency-n geodesic sphere: 20 n^2 triangles.
    const int n = std::max(1, int(std::lround(std::sqrt(double(target) / 20.0))));
    const double t = (1.0 + std::sqrt(5.0)) / 2.0;
    const std::array<glm::dvec3, 12> c = {{{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                                           {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                                           {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}}};
    const int faces[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                              {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                              {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                              {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
    Builder b;
    // A point is identified by its corners and integer weights (summing to n),
    // sorted by corner index: points on shared edges get one vertex, and are
    // computed with the same arithmetic from either face.
    std::map<std::array<int, 6>, std::uint32_t> ids;
    auto point = [&](std::array<std::pair<int, int>, 3> w) {
        std::sort(w.begin(), w.end());
        std::array<int, 6> key{};
        glm::dvec3 p(0.0);
        int k = 0;
        for (auto [corner, weight] : w)
            if (weight > 0) {
                key[std::size_t(k++)] = corner;
                key[std::size_t(k++)] = weight;
                p += c[std::size_t(corner)] * double(weight);
            }
        for (; k < 6; ++k)
            key[std::size_t(k)] = -1;
        auto it = ids.find(key);
        if (it != ids.end())
            return it->second;
        const glm::vec3 u(glm::normalize(p));
        const std::uint32_t id = b.vertex(u, u);
        ids.emplace(key, id);
        return id;
    };
    for (const auto& f : faces) {
        auto at = [&](int i, int j) { return point({{{f[0], n - i - j}, {f[1], i}, {f[2], j}}}); };
        for (int j = 0; j < n; ++j)
            for (int i = 0; i + j < n; ++i) {
                b.tri(at(i, j), at(i + 1, j), at(i, j + 1));
                if (i + j + 1 < n)
                    b.tri(at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            }
    }
    return std::move(b.mesh);
}

Mesh terrain(std::uint64_t target, std::uint64_t seed) {
    const int m = std::max(1, int(std::lround(std::sqrt(double(target) / 2.0))));
    Builder b;
    b.grid(m, m, [&](double u, double v) -> PN {
        const double x = -1 + 2 * u, z = 1 - 2 * v; // v runs towards -z so that the front faces +y
        const double h = 0.6 * fbm(seed, x, z);
        return {glm::vec3(float(x), float(h), float(z)), glm::vec3(0, 1, 0)};
    });
    compute_normals(b.mesh);
    return std::move(b.mesh);
}

void add_box(Builder& b, glm::vec3 lo, glm::vec3 hi) {
    // Five faces (no bottom), four vertices each, outward normals.
    const glm::vec3 v[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z},
                            {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
    const int quads[5][4] = {{4, 5, 6, 7}, {1, 0, 3, 2}, {5, 1, 2, 6}, {0, 4, 7, 3}, {3, 7, 6, 2}};
    const glm::vec3 normals[5] = {{0, 0, 1}, {0, 0, -1}, {1, 0, 0}, {-1, 0, 0}, {0, 1, 0}};
    for (int q = 0; q < 5; ++q) {
        std::uint32_t id[4];
        for (int k = 0; k < 4; ++k)
            id[k] = b.vertex(v[quads[q][k]], normals[q]);
        b.tri(id[0], id[1], id[2]);
        b.tri(id[0], id[2], id[3]);
    }
}

Mesh city(std::uint64_t target, std::uint64_t seed) {
    Builder b;
    const std::uint64_t boxes = std::max<std::uint64_t>(1, target * 4 / 5 / 10);
    const int g = std::max(1, int(std::lround(std::sqrt(double(target - std::min(target, boxes * 10)) / 2.0))));
    b.grid(g, g, [&](double u, double v) -> PN {
        return {glm::vec3(float(-1 + 2 * u), 0.0f, float(1 - 2 * v)), glm::vec3(0, 1, 0)};
    });
    // Buildings on a jittered grid, one per cell, so that they never overlap;
    // heights cluster around a few "downtown" centres.
    const int cells = std::max(1, int(std::ceil(std::sqrt(double(boxes)))));
    const double cell = 1.9 / cells;
    const int clusters = 5;
    double cx[clusters], cz[clusters];
    for (int k = 0; k < clusters; ++k) {
        cx[k] = -0.7 + 1.4 * hash01(seed, 1, k);
        cz[k] = -0.7 + 1.4 * hash01(seed, 2, k);
    }
    for (std::uint64_t i = 0; i < boxes; ++i) {
        const auto gi = std::int64_t(i % std::uint64_t(cells)), gj = std::int64_t(i / std::uint64_t(cells));
        const double x0 = -0.95 + cell * double(gi), z0 = -0.95 + cell * double(gj);
        const auto id = std::int64_t(i);
        const double w = cell * (0.25 + 0.2 * hash01(seed, 5, id)), d = cell * (0.25 + 0.2 * hash01(seed, 6, id));
        const double x = x0 + cell * 0.5 + (cell * 0.5 - w) * (2 * hash01(seed, 3, id) - 1);
        const double z = z0 + cell * 0.5 + (cell * 0.5 - d) * (2 * hash01(seed, 4, id) - 1);
        double near2 = 1e9;
        for (int k = 0; k < clusters; ++k)
            near2 = std::min(near2, (x - cx[k]) * (x - cx[k]) + (z - cz[k]) * (z - cz[k]));
        const double h = 0.01 + (0.04 + 0.3 * std::exp(-near2 / 0.03)) * (0.3 + 0.7 * hash01(seed, 7, id));
        add_box(b, glm::vec3(float(x - w), 0.0f, float(z - d)), glm::vec3(float(x + w), float(h), float(z + d)));
    }
    return std::move(b.mesh);
}

Mesh bowl(std::uint64_t target) {
    // Lower hemisphere of the unit sphere (y <= 0), front faces inside.
    const int seg = std::max(3, int(std::lround(std::sqrt(double(target)))));
    const int rings = std::max(1, int(std::lround(double(target) / (2.0 * seg))));
    Builder b;
    b.grid(seg, rings, [&](double u, double v) -> PN {
        // phi runs clockwise seen from above, so that front faces look inwards.
        const double phi = -2 * kPi * u, theta = 0.5 * kPi * (1 - v); // v = 0 at the rim
        const glm::dvec3 p(std::sin(theta) * std::cos(phi), -std::cos(theta), std::sin(theta) * std::sin(phi));
        const glm::vec3 pf(p);
        return {pf, -glm::normalize(pf)};
    });
    // The grid's last row collapses to the bottom pole: those triangles are
    // degenerate and removed, and the seam columns are welded.
    Mesh& m = b.mesh;
    const auto row = std::uint32_t(seg + 1);
    for (auto& idx : m.indices) {
        const std::uint32_t i = idx % row, j = idx / row;
        if (j == std::uint32_t(rings))
            idx = std::uint32_t(rings) * row; // pole
        else if (i == std::uint32_t(seg))
            idx = j * row; // seam
    }
    std::vector<std::uint32_t> kept;
    for (std::size_t t = 0; t < m.indices.size(); t += 3) {
        const auto a = m.indices[t], bb = m.indices[t + 1], c = m.indices[t + 2];
        if (a != bb && bb != c && a != c)
            kept.insert(kept.end(), {a, bb, c});
    }
    m.indices = std::move(kept);
    return std::move(b.mesh);
}

Mesh wall(std::uint64_t target) {
    // Floor area 4, wall area 2: split the triangles in that ratio.
    const int nf = std::max(1, int(std::lround(std::sqrt(double(target) * 2.0 / 3.0 / 2.0))));
    Builder b;
    b.grid(nf, nf, [&](double u, double v) -> PN {
        return {glm::vec3(float(-1 + 2 * u), 0.0f, float(1 - 2 * v)), glm::vec3(0, 1, 0)};
    });
    b.grid(nf, std::max(1, nf / 2), [&](double u, double v) -> PN {
        return {glm::vec3(float(-1 + 2 * u), float(v), -1.0f), glm::vec3(0, 0, 1)};
    });
    return std::move(b.mesh);
}

Mesh torus(std::uint64_t target) {
    const int nu = std::max(3, int(std::lround(std::sqrt(double(target) * 1.5))));
    const int nv = std::max(3, int(std::lround(double(target) / (2.0 * nu))));
    const double R = 1.0, r = 0.35;
    Builder b;
    b.grid(nu, nv, [&](double u, double v) -> PN {
        const double a = 2 * kPi * u, c = -2 * kPi * v;
        const glm::dvec3 n(std::cos(c) * std::cos(a), std::sin(c), std::cos(c) * std::sin(a));
        const glm::dvec3 centre(R * std::cos(a), 0, R * std::sin(a));
        return {glm::vec3(centre + r * n), glm::vec3(n)};
    });
    // Weld the seams (u = 1 onto u = 0, v = 1 onto v = 0).
    const auto row = std::uint32_t(nu + 1);
    for (auto& idx : b.mesh.indices) {
        std::uint32_t i = idx % row, j = idx / row;
        if (i == std::uint32_t(nu))
            i = 0;
        if (j == std::uint32_t(nv))
            j = 0;
        idx = j * row + i;
    }
    return std::move(b.mesh);
}

constexpr NamedValue<ProceduralKind> kKinds[] = {
    {ProceduralKind::Sphere, "sphere"}, {ProceduralKind::Terrain, "terrain"}, {ProceduralKind::City, "city"},
    {ProceduralKind::Bowl, "bowl"},     {ProceduralKind::Wall, "wall"},       {ProceduralKind::Torus, "torus"}};

} // namespace

ProceduralKind parse_procedural_kind(const std::string& name) {
    return parse_name(kKinds, name, "mesh kind", "kind");
}

const char* procedural_kind_name(ProceduralKind kind) { return name_of(kKinds, kind); }

std::vector<std::string> procedural_kind_names() { return names_of(kKinds); }

Mesh generate_mesh(const ProceduralOptions& o) {
    constexpr std::uint64_t kMax = 50'000'000;
    if (o.target_triangles < 20 || o.target_triangles > kMax)
        throw Error(fmt::format("triangle count {} is out of range; use 20 to {}", o.target_triangles, kMax),
                    "target_triangles");
    switch (o.kind) {
    case ProceduralKind::Sphere: return icosphere(o.target_triangles);
    case ProceduralKind::Terrain: return terrain(o.target_triangles, o.seed);
    case ProceduralKind::City: return city(o.target_triangles, o.seed);
    case ProceduralKind::Bowl: return bowl(o.target_triangles);
    case ProceduralKind::Wall: return wall(o.target_triangles);
    case ProceduralKind::Torus: return torus(o.target_triangles);
    }
    return {};
}

} // namespace skybake
