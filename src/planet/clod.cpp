// Mark Duchaineau, Murray Wolinsky, David E. Sigeti, Mark C. Miller, Charles
// Aldrich, Mark B. Mineev-Weinstein. ROAMing Terrain: Real-time Optimally
// Adapting Meshes. IEEE Visualization 1997.
// Peter Lindstrom, Valerio Pascucci. Terrain Simplification Simplified: A
// General Framework for View-Dependent Out-of-Core Visualization. IEEE TVCG
// 8(3), 2002 (longest-edge bisection seen as diamonds).
//
// The triangle bintree of ROAM on the icosahedron: every triangle has an apex
// and a base edge (the edge opposite the apex). Splitting a triangle bisects
// its base edge and makes two children whose bases are the parent's two other
// edges. The mesh stays conforming (no T-junction, hence no crack) when a
// triangle is only ever split together with the triangle on the other side of
// its base, whose base is the same edge: the two form a diamond. If that
// neighbour is coarser (the shared edge is one of its sides), it is split
// first ("forced split", ROAM section 4). A diamond may be merged back when
// its four children are leaves. The 20 faces are paired into 10 rhombi (a
// perfect matching of the dodecahedral dual graph), so that each face's base
// is the edge it shares with its partner: then every edge that is not a base
// is a side of both its faces, and their children form diamonds on it.
//
// Each frame: merge the diamonds whose merged screen-space error is within
// the bound (coarsest last), then split leaves in order of decreasing error
// until every leaf is within the bound or the triangle budget is reached.
// Ties are broken by node id, and ids are recycled in LIFO order, so the
// result is deterministic.
#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstring>
#include <queue>
#include <unordered_map>

#include <glm/geometric.hpp>

#include "skybake/planet.h"

namespace skybake {

namespace {

constexpr std::int32_t kNone = -1;

std::uint64_t edge_key(std::uint32_t a, std::uint32_t b) {
    const std::uint32_t lo = a < b ? a : b, hi = a < b ? b : a;
    return (std::uint64_t(lo) << 32) | hi;
}

struct EdgeHash {
    std::size_t operator()(std::uint64_t k) const noexcept {
        k ^= k >> 33;
        k *= 0xff51afd7ed558ccdULL;
        k ^= k >> 33;
        return std::size_t(k);
    }
};

struct Node {
    std::uint32_t v[3] = {0, 0, 0}; // apex, base0, base1 (counter-clockwise from outside)
    std::int32_t parent = kNone;
    std::int32_t partner = kNone; // the other triangle of the diamond on this node's base (set when split)
    std::int32_t child[2] = {kNone, kNone};
    std::uint32_t generation = 0; // bumped when the id is recycled or the node changes leaf state
    int level = 0;
    bool leaf = false;
    bool live = false;
    double error_km = 0.0;  // object-space error
    glm::dvec3 centre{0.0}; // bounding sphere of the triangle and the surface it stands for
    double radius_km = 0.0;
    double priority_px = 0.0; // screen-space error, last evaluation
};

struct Vertex {
    glm::dvec3 dir{0.0}; // unit direction from the centre
    glm::dvec3 pos{0.0}; // km
    glm::dvec3 normal{0.0};
    bool live = false;
};

// splitmix64
std::uint64_t mix(std::uint64_t x) {
    x += 0x9e3779b97f4a7c15ULL;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
    return x ^ (x >> 31);
}

double lattice(std::int64_t x, std::int64_t y, std::int64_t z, std::uint64_t seed) {
    std::uint64_t h = mix(seed ^ mix(std::uint64_t(x) ^ mix(std::uint64_t(y) ^ mix(std::uint64_t(z)))));
    return double(h >> 11) * (1.0 / 9007199254740992.0); // [0, 1)
}

// Trilinear value noise with quintic fade, values in [0, 1).
double value_noise(const glm::dvec3& p, std::uint64_t seed) {
    const double fx = std::floor(p.x), fy = std::floor(p.y), fz = std::floor(p.z);
    const std::int64_t ix = std::int64_t(fx), iy = std::int64_t(fy), iz = std::int64_t(fz);
    auto fade = [](double t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); };
    const double u = fade(p.x - fx), v = fade(p.y - fy), w = fade(p.z - fz);
    double c[2][2][2];
    for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b)
            for (int d = 0; d < 2; ++d)
                c[a][b][d] = lattice(ix + a, iy + b, iz + d, seed);
    auto lerp = [](double a, double b, double t) { return a + (b - a) * t; };
    const double x00 = lerp(c[0][0][0], c[1][0][0], u), x10 = lerp(c[0][1][0], c[1][1][0], u);
    const double x01 = lerp(c[0][0][1], c[1][0][1], u), x11 = lerp(c[0][1][1], c[1][1][1], u);
    return lerp(lerp(x00, x10, v), lerp(x01, x11, v), w);
}

} // namespace

double PlanetCamera::pixels_per_radian() const {
    return double(viewport_height) / (2.0 * std::tan(0.5 * fov_y_rad));
}

double relief_height_km(const PlanetRelief& r, const glm::dvec3& dir) {
    if (!(r.amplitude_km > 0.0))
        return 0.0;
    // Octave o: wavelength λ0 / 2^o, amplitude 2^-o, normalised to [0, 1].
    double sum = 0.0, norm = 0.0, amp = 1.0, freq = 1.0;
    for (int o = 0; o < r.octaves; ++o) {
        // Positions on a sphere of radius 1000 km, measured in wavelengths.
        const glm::dvec3 p = dir * (1000.0 * freq / r.base_wavelength_km);
        sum += amp * value_noise(p, r.seed + std::uint64_t(o) * 0x632be59bd9b4e019ULL);
        norm += amp;
        amp *= 0.5;
        freq *= 2.0;
    }
    // Sums of octaves gather around 0.5: stretch [0.3, 0.7] to [0, 1], flat lowlands.
    const double t = sum / norm;
    const double s = std::clamp((t - 0.3) / 0.4, 0.0, 1.0);
    return r.amplitude_km * s * std::sqrt(s);
}

struct PlanetMesh::Impl {
    ClodOptions opt;
    std::vector<Node> nodes;
    std::vector<std::int32_t> free_nodes;
    std::vector<Vertex> verts;
    std::vector<std::uint32_t> free_verts;
    std::unordered_map<std::uint64_t, std::array<std::int32_t, 2>, EdgeHash> edges; // leaf triangles on each edge
    std::size_t leaves = 0;
    std::size_t live_verts = 0;
    // Camera state of the current update.
    glm::dvec3 eye{0.0};
    double k_px = 1.0;
    double horizon_km = 0.0;
    std::array<glm::dvec3, 4> planes{}; // inward normals of the side planes through the eye
    bool culling = false;

    // --- vertices ---------------------------------------------------------------
    std::uint32_t add_vertex(const glm::dvec3& dir_in) {
        const glm::dvec3 dir = glm::normalize(dir_in);
        std::uint32_t id;
        if (!free_verts.empty()) {
            id = free_verts.back();
            free_verts.pop_back();
        } else {
            id = std::uint32_t(verts.size());
            verts.emplace_back();
        }
        Vertex& v = verts[id];
        v.dir = dir;
        const double R = opt.planet_radius_km;
        v.pos = dir * (R + relief_height_km(opt.relief, dir));
        v.normal = dir;
        if (opt.relief.amplitude_km > 0.0) {
            // Normal from central differences of the height field, over about 20 m.
            glm::dvec3 t1 =
                glm::normalize(glm::cross(std::abs(dir.z) < 0.9 ? glm::dvec3(0, 0, 1) : glm::dvec3(1, 0, 0), dir));
            glm::dvec3 t2 = glm::cross(dir, t1);
            const double e = 0.02 / R;
            auto p = [&](const glm::dvec3& d) {
                const glm::dvec3 u = glm::normalize(d);
                return u * (R + relief_height_km(opt.relief, u));
            };
            const glm::dvec3 n = glm::cross(p(dir + e * t1) - p(dir - e * t1), p(dir + e * t2) - p(dir - e * t2));
            v.normal = glm::normalize(n);
        }
        v.live = true;
        ++live_verts;
        return id;
    }
    void free_vertex(std::uint32_t id) {
        verts[id].live = false;
        free_verts.push_back(id);
        --live_verts;
    }

    // --- nodes ---------------------------------------------------------------------
    std::int32_t new_node(std::uint32_t apex, std::uint32_t b0, std::uint32_t b1, std::int32_t parent, int level) {
        std::int32_t id;
        if (!free_nodes.empty()) {
            id = free_nodes.back();
            free_nodes.pop_back();
        } else {
            id = std::int32_t(nodes.size());
            nodes.emplace_back();
        }
        Node& n = nodes[std::size_t(id)];
        const std::uint32_t gen = n.generation + 1;
        n = Node{};
        n.generation = gen;
        n.v[0] = apex;
        n.v[1] = b0;
        n.v[2] = b1;
        n.parent = parent;
        n.level = level;
        n.live = true;
        compute_bounds(n);
        if (parent != kNone)
            n.error_km = std::min(n.error_km, nodes[std::size_t(parent)].error_km);
        return id;
    }

    void compute_bounds(Node& n) const {
        const glm::dvec3& a = verts[n.v[0]].pos;
        const glm::dvec3& b = verts[n.v[1]].pos;
        const glm::dvec3& c = verts[n.v[2]].pos;
        const double R = opt.planet_radius_km;
        const glm::dvec3 nrm = glm::normalize(glm::cross(b - a, c - a));
        const double plane = std::abs(glm::dot(nrm, a));
        // Smooth sphere: the flat triangle is within R − plane of the sphere
        // (exact when the foot of the perpendicular is inside the triangle).
        double err = std::max(0.0, R - plane);
        const double edge = std::max({glm::length(b - a), glm::length(c - b), glm::length(a - c)});
        if (opt.relief.amplitude_km > 0.0) {
            // Terrain the triangle cannot resolve: octave o (wavelength λ_o,
            // amplitude A_o) counts fully when λ_o < 4 edge, and by its
            // interpolation error A_o (π edge / λ_o)² / 2 otherwise.
            double amp = 1.0, norm = 0.0, lam = opt.relief.base_wavelength_km, e = 0.0;
            for (int o = 0; o < opt.relief.octaves; ++o) {
                norm += amp;
                const double x = 3.14159265358979 * edge / lam;
                e += amp * std::min(1.0, 0.5 * x * x);
                amp *= 0.5;
                lam *= 0.5;
            }
            err += opt.relief.amplitude_km * e / norm;
        }
        n.error_km = err;
        n.centre = (a + b + c) / 3.0;
        n.radius_km = std::max({glm::length(a - n.centre), glm::length(b - n.centre), glm::length(c - n.centre)}) + err;
    }

    void free_node(std::int32_t id) {
        Node& n = nodes[std::size_t(id)];
        n.live = false;
        n.leaf = false;
        ++n.generation;
        free_nodes.push_back(id);
    }

    // --- leaf edge registry ------------------------------------------------------------
    void add_edge(std::uint32_t a, std::uint32_t b, std::int32_t t) {
        auto [it, inserted] = edges.try_emplace(edge_key(a, b), std::array<std::int32_t, 2>{t, kNone});
        if (inserted)
            return;
        auto& slot = it->second;
        if (slot[0] == kNone)
            slot[0] = t;
        else {
            assert(slot[1] == kNone);
            slot[1] = t;
        }
    }
    void remove_edge(std::uint32_t a, std::uint32_t b, std::int32_t t) {
        auto it = edges.find(edge_key(a, b));
        assert(it != edges.end());
        auto& slot = it->second;
        if (slot[0] == t)
            slot[0] = kNone;
        else {
            assert(slot[1] == t);
            slot[1] = kNone;
        }
        if (slot[0] == kNone && slot[1] == kNone)
            edges.erase(it);
    }
    void make_leaf(std::int32_t t) {
        Node& n = nodes[std::size_t(t)];
        n.leaf = true;
        ++n.generation;
        add_edge(n.v[0], n.v[1], t);
        add_edge(n.v[1], n.v[2], t);
        add_edge(n.v[2], n.v[0], t);
        ++leaves;
    }
    void unmake_leaf(std::int32_t t) {
        Node& n = nodes[std::size_t(t)];
        n.leaf = false;
        ++n.generation;
        remove_edge(n.v[0], n.v[1], t);
        remove_edge(n.v[1], n.v[2], t);
        remove_edge(n.v[2], n.v[0], t);
        --leaves;
    }
    // The other leaf on the base edge of leaf t.
    std::int32_t base_neighbour(std::int32_t t) const {
        const Node& n = nodes[std::size_t(t)];
        auto it = edges.find(edge_key(n.v[1], n.v[2]));
        assert(it != edges.end());
        const auto& s = it->second;
        return s[0] == t ? s[1] : s[0];
    }
    bool same_base(std::int32_t a, std::int32_t b) const {
        const Node& x = nodes[std::size_t(a)];
        const Node& y = nodes[std::size_t(b)];
        return edge_key(x.v[1], x.v[2]) == edge_key(y.v[1], y.v[2]);
    }

    // --- level 0 -------------------------------------------------------------------------
    void build_icosahedron() {
        const double p = (1.0 + std::sqrt(5.0)) / 2.0;
        const double V[12][3] = {{-1, p, 0},  {1, p, 0},  {-1, -p, 0}, {1, -p, 0}, {0, -1, p},  {0, 1, p},
                                 {0, -1, -p}, {0, 1, -p}, {p, 0, -1},  {p, 0, 1},  {-p, 0, -1}, {-p, 0, 1}};
        const int F[20][3] = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                              {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                              {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
        for (const auto& v : V)
            add_vertex(glm::dvec3(v[0], v[1], v[2]));
        // Dual graph and a perfect matching by backtracking (deterministic).
        std::array<std::array<int, 3>, 20> adj{};
        for (int f = 0; f < 20; ++f) {
            int k = 0;
            for (int g = 0; g < 20; ++g) {
                if (g == f)
                    continue;
                int shared = 0;
                for (int i = 0; i < 3; ++i)
                    for (int j = 0; j < 3; ++j)
                        shared += F[f][i] == F[g][j];
                if (shared == 2)
                    adj[std::size_t(f)][std::size_t(k++)] = g;
            }
            assert(k == 3);
        }
        std::array<int, 20> match;
        match.fill(-1);
        auto solve = [&](auto&& self) -> bool {
            int f = 0;
            while (f < 20 && match[std::size_t(f)] >= 0)
                ++f;
            if (f == 20)
                return true;
            for (int g : adj[std::size_t(f)]) {
                if (match[std::size_t(g)] >= 0)
                    continue;
                match[std::size_t(f)] = g;
                match[std::size_t(g)] = f;
                if (self(self))
                    return true;
                match[std::size_t(f)] = match[std::size_t(g)] = -1;
            }
            return false;
        };
        [[maybe_unused]] const bool ok = solve(solve);
        assert(ok);
        for (int f = 0; f < 20; ++f) {
            const int g = match[std::size_t(f)];
            // Apex: the vertex of f not in g; keep the counter-clockwise order.
            int a = 0;
            for (int i = 0; i < 3; ++i) {
                const int vi = F[f][i];
                if (vi != F[g][0] && vi != F[g][1] && vi != F[g][2])
                    a = i;
            }
            const std::int32_t t = new_node(std::uint32_t(F[f][a]), std::uint32_t(F[f][(a + 1) % 3]),
                                            std::uint32_t(F[f][(a + 2) % 3]), kNone, 0);
            make_leaf(t);
        }
    }

    // --- split and merge --------------------------------------------------------------------
    // Splits the diamond of leaves t and b (same base). New leaves go to `created`.
    void split_diamond(std::int32_t t, std::int32_t b, std::vector<std::int32_t>* created) {
        assert(same_base(t, b));
        const Node nt = nodes[std::size_t(t)];
        const Node nb = nodes[std::size_t(b)];
        const std::uint32_t m = add_vertex(verts[nt.v[1]].dir + verts[nt.v[2]].dir);
        unmake_leaf(t);
        unmake_leaf(b);
        const std::int32_t t0 = new_node(m, nt.v[0], nt.v[1], t, nt.level + 1);
        const std::int32_t t1 = new_node(m, nt.v[2], nt.v[0], t, nt.level + 1);
        const std::int32_t b0 = new_node(m, nb.v[0], nb.v[1], b, nb.level + 1);
        const std::int32_t b1 = new_node(m, nb.v[2], nb.v[0], b, nb.level + 1);
        Node& pt = nodes[std::size_t(t)];
        pt.child[0] = t0;
        pt.child[1] = t1;
        pt.partner = b;
        Node& pb = nodes[std::size_t(b)];
        pb.child[0] = b0;
        pb.child[1] = b1;
        pb.partner = t;
        for (std::int32_t c : {t0, t1, b0, b1}) {
            make_leaf(c);
            if (created)
                created->push_back(c);
        }
    }

    // Triangles the split of leaf t would add (forced splits included).
    std::size_t split_cost(std::int32_t t) const {
        std::size_t cost = 2;
        for (;;) {
            const std::int32_t b = base_neighbour(t);
            if (same_base(t, b))
                return cost;
            cost += 2;
            t = b;
        }
    }

    void split(std::int32_t t, std::vector<std::int32_t>* created, std::size_t& splits) {
        std::int32_t b = base_neighbour(t);
        if (!same_base(t, b)) {
            split(b, created, splits); // forced: the neighbour is one level coarser
            b = base_neighbour(t);
            assert(same_base(t, b));
        }
        split_diamond(t, b, created);
        ++splits;
    }

    // Diamond of parents p and q = p.partner: mergeable when all four children are leaves.
    bool mergeable(std::int32_t p) const {
        const Node& a = nodes[std::size_t(p)];
        if (!a.live || a.leaf || a.partner == kNone)
            return false;
        const Node& b = nodes[std::size_t(a.partner)];
        for (std::int32_t c : {a.child[0], a.child[1], b.child[0], b.child[1]})
            if (c == kNone || !nodes[std::size_t(c)].leaf)
                return false;
        return true;
    }

    void merge(std::int32_t p) {
        const std::int32_t q = nodes[std::size_t(p)].partner;
        const std::uint32_t m = nodes[std::size_t(nodes[std::size_t(p)].child[0])].v[0];
        for (std::int32_t x : {p, q}) {
            Node& n = nodes[std::size_t(x)];
            for (std::int32_t& c : n.child) {
                unmake_leaf(c);
                free_node(c);
                c = kNone;
            }
            n.partner = kNone;
        }
        make_leaf(p);
        make_leaf(q);
        free_vertex(m);
    }

    // --- errors -----------------------------------------------------------------------------
    double priority(const Node& n) const {
        const double d = glm::length(n.centre - eye) - n.radius_km;
        if (culling) {
            if (d > horizon_km)
                return 0.0;
            for (const glm::dvec3& pl : planes)
                if (glm::dot(n.centre - eye, pl) < -n.radius_km)
                    return 0.0;
        }
        return n.error_km * k_px / std::max(d, 1e-9);
    }
};

PlanetMesh::PlanetMesh(const ClodOptions& options) : impl_(std::make_unique<Impl>()) {
    assert(options.planet_radius_km > 0.0 && options.max_error_px > 0.0 && options.max_triangles >= 20);
    assert(options.relief.amplitude_km >= 0.0 && options.relief.octaves >= 1 && options.relief.octaves <= 30);
    impl_->opt = options;
    impl_->build_icosahedron();
}
PlanetMesh::~PlanetMesh() = default;
PlanetMesh::PlanetMesh(PlanetMesh&&) noexcept = default;
PlanetMesh& PlanetMesh::operator=(PlanetMesh&&) noexcept = default;

const ClodOptions& PlanetMesh::options() const {
    return impl_->opt;
}
std::size_t PlanetMesh::triangle_count() const {
    return impl_->leaves;
}
std::size_t PlanetMesh::vertex_capacity() const {
    return impl_->verts.size();
}

ClodStats PlanetMesh::update(const PlanetCamera& cam) {
    Impl& m = *impl_;
    const ClodOptions& o = m.opt;
    m.eye = cam.position_km;
    m.k_px = cam.pixels_per_radian();
    m.culling = o.cull;
    // Farthest visible point of a surface no higher than R + A, seen over the sphere R.
    const double R = o.planet_radius_km, D = std::max(glm::length(cam.position_km), R);
    const double top = R + o.relief.amplitude_km;
    m.horizon_km = std::sqrt(D * D - R * R) + std::sqrt(top * top - R * R) + 1e-6;
    {
        const glm::dvec3 f = glm::normalize(cam.forward);
        const glm::dvec3 r = glm::normalize(glm::cross(f, cam.up));
        const glm::dvec3 u = glm::cross(r, f);
        const double ty = std::tan(0.5 * cam.fov_y_rad);
        const double tx = ty * double(cam.viewport_width) / double(cam.viewport_height);
        // Inward normals of the planes through the eye and the frustum's side edges.
        m.planes[0] = glm::normalize(glm::cross(u, f + tx * r)); // right
        m.planes[1] = glm::normalize(glm::cross(f - tx * r, u)); // left
        m.planes[2] = glm::normalize(glm::cross(f + ty * u, r)); // top
        m.planes[3] = glm::normalize(glm::cross(r, f - ty * u)); // bottom
    }
    ClodStats st;
    const double tau = o.max_error_px;

    // 1. Merges: every diamond whose parents are both within the bound.
    std::vector<std::int32_t> work;
    for (std::size_t i = 0; i < m.nodes.size(); ++i)
        if (m.mergeable(std::int32_t(i)) && std::int32_t(i) < m.nodes[i].partner)
            work.push_back(std::int32_t(i));
    // Finest first, so that coarser diamonds can follow in the same update.
    std::stable_sort(work.begin(), work.end(), [&](std::int32_t a, std::int32_t b) {
        return m.nodes[std::size_t(a)].level > m.nodes[std::size_t(b)].level;
    });
    for (std::size_t w = 0; w < work.size(); ++w) {
        const std::int32_t p = work[w];
        if (!m.mergeable(p))
            continue;
        const std::int32_t q = m.nodes[std::size_t(p)].partner;
        if (std::max(m.priority(m.nodes[std::size_t(p)]), m.priority(m.nodes[std::size_t(q)])) > tau)
            continue;
        m.merge(p);
        ++st.merges;
        for (std::int32_t x : {p, q}) {
            const std::int32_t parent = m.nodes[std::size_t(x)].parent;
            if (parent != kNone && m.mergeable(parent)) {
                const std::int32_t a = std::min(parent, m.nodes[std::size_t(parent)].partner);
                if (std::find(work.begin() + std::ptrdiff_t(w) + 1, work.end(), a) == work.end())
                    work.push_back(a);
            }
        }
    }
    // Over budget (a smaller budget than last time): merge the least visible diamonds.
    if (m.leaves > o.max_triangles) {
        std::vector<std::pair<double, std::int32_t>> cand;
        for (std::size_t i = 0; i < m.nodes.size(); ++i)
            if (m.mergeable(std::int32_t(i)) && std::int32_t(i) < m.nodes[i].partner)
                cand.push_back({std::max(m.priority(m.nodes[i]), m.priority(m.nodes[std::size_t(m.nodes[i].partner)])),
                                std::int32_t(i)});
        while (m.leaves > o.max_triangles && !cand.empty()) {
            std::sort(cand.begin(), cand.end());
            std::size_t k = 0;
            for (; k < cand.size() && m.leaves > o.max_triangles; ++k)
                if (m.mergeable(cand[k].second)) {
                    m.merge(cand[k].second);
                    ++st.merges;
                }
            cand.clear();
            for (std::size_t i = 0; i < m.nodes.size(); ++i)
                if (m.mergeable(std::int32_t(i)) && std::int32_t(i) < m.nodes[i].partner)
                    cand.push_back(
                        {std::max(m.priority(m.nodes[i]), m.priority(m.nodes[std::size_t(m.nodes[i].partner)])),
                         std::int32_t(i)});
        }
    }

    // 2. Splits, largest error first.
    using Entry = std::tuple<double, std::int32_t, std::uint32_t>; // priority, -id (ties: lower id first), generation
    std::priority_queue<Entry> heap;
    auto push = [&](std::int32_t id) {
        Node& n = m.nodes[std::size_t(id)];
        n.priority_px = m.priority(n);
        if (n.priority_px > tau && n.level < o.max_level)
            heap.push({n.priority_px, -id, n.generation});
    };
    for (std::size_t i = 0; i < m.nodes.size(); ++i)
        if (m.nodes[i].live && m.nodes[i].leaf)
            push(std::int32_t(i));
    std::vector<std::int32_t> created;
    while (!heap.empty()) {
        const auto [pr, neg, gen] = heap.top();
        heap.pop();
        const std::int32_t id = -neg;
        const Node& n = m.nodes[std::size_t(id)];
        if (!n.live || !n.leaf || n.generation != gen)
            continue;
        if (m.leaves + m.split_cost(id) > o.max_triangles) {
            st.budget_reached = true;
            break;
        }
        created.clear();
        m.split(id, &created, st.splits);
        for (std::int32_t c : created)
            push(c);
    }

    // Final errors of the leaves.
    for (std::size_t i = 0; i < m.nodes.size(); ++i) {
        Node& n = m.nodes[i];
        if (n.live && n.leaf) {
            n.priority_px = m.priority(n);
            st.max_error_px = std::max(st.max_error_px, n.priority_px);
            st.max_level = std::max(st.max_level, n.level);
        }
    }
    st.triangles = m.leaves;
    st.vertices = m.live_verts;
    return st;
}

void PlanetMesh::indices(std::vector<std::uint32_t>& out) const {
    out.clear();
    out.reserve(impl_->leaves * 3);
    for (const Node& n : impl_->nodes)
        if (n.live && n.leaf)
            out.insert(out.end(), {n.v[0], n.v[1], n.v[2]});
}

void PlanetMesh::vertices(const glm::dvec3& origin, std::vector<float>& pos, std::vector<float>& nrm) const {
    const auto& v = impl_->verts;
    pos.assign(v.size() * 3, 0.0f);
    nrm.assign(v.size() * 3, 0.0f);
    for (std::size_t i = 0; i < v.size(); ++i) {
        if (!v[i].live)
            continue;
        const glm::dvec3 p = v[i].pos - origin;
        for (int k = 0; k < 3; ++k) {
            pos[i * 3 + std::size_t(k)] = float(p[k]);
            nrm[i * 3 + std::size_t(k)] = float(v[i].normal[k]);
        }
    }
}

glm::dvec3 PlanetMesh::vertex_position_km(std::uint32_t id) const {
    assert(id < impl_->verts.size() && impl_->verts[id].live);
    return impl_->verts[id].pos;
}

void PlanetMesh::leaf_errors(std::vector<double>& object_km, std::vector<double>& screen_px) const {
    object_km.clear();
    screen_px.clear();
    for (const Node& n : impl_->nodes)
        if (n.live && n.leaf) {
            object_km.push_back(n.error_km);
            screen_px.push_back(n.priority_px);
        }
}

} // namespace skybake
