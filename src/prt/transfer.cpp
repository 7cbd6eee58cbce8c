// Diffuse transfer vectors from the visibility words, and their bounces.
//
// Sloan, Kautz & Snyder, Precomputed Radiance Transfer for Real-Time Rendering
// in Dynamic, Low-Frequency Lighting Environments, SIGGRAPH 2002 (sections 4
// and 5); Svistunov (seed 002) for the visibility words and B ≈ A · B̃.
// See skybake/prt.h, [SECTION] Definitions.
#include <atomic>
#include <chrono>
#include <cmath>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "core/parallel.h"
#include "skybake/error.h"
#include "skybake/names.h"
#include "skybake/prt.h"
#include "visibility/trace_hd.h"

namespace skybake {

namespace {

constexpr NamedValue<TransferKind> kKindNames[] = {
    {TransferKind::Unshadowed, "unshadowed", "no visibility"},
    {TransferKind::Shadowed, "shadowed", "through the visibility bits"},
    {TransferKind::Interreflected, "interreflected", "shadowed plus bounces"},
};
constexpr NamedValue<TransferModel> kModelNames[] = {
    {TransferModel::Prt, "prt", "the transfer integral"},
    {TransferModel::ShadingCoefficient, "shading-coefficient", "A times the unshadowed irradiance"},
};

constexpr int kMaxBounces = 16;

// Y_i(x) for i < sh_count(order), in float.
void eval_sh_f(int order, const glm::vec3& x, float* out) {
    double y[sh_count(kPrtMaxOrder)];
    sh_eval(order, glm::dvec3(x), y);
    for (int i = 0; i < sh_count(order); ++i)
        out[i] = float(y[i]);
}

} // namespace

const char* transfer_kind_name(TransferKind kind) {
    return name_of(kKindNames, kind);
}
const char* transfer_model_name(TransferModel model) {
    return name_of(kModelNames, model);
}
TransferKind parse_transfer_kind(const std::string& text) {
    return parse_name(kKindNames, text, "transfer kind", "kind");
}
TransferModel parse_transfer_model(const std::string& text) {
    return parse_name(kModelNames, text, "transfer model", "model");
}

TransferReduction::TransferReduction(Transfer& out, bool keep_words) : out_(out), keep_words_(keep_words) {}

void TransferReduction::begin(const VisibilityRule& rule, std::size_t vertices) {
    rule_ = rule;
    const int nc = out_.coefficients;
    out_.channels = 1;
    out_.coeffs.assign(vertices * std::size_t(nc), 0.0f);
    shading_.assign(vertices, 0.0f);
    words_.assign(keep_words_ ? vertices * rule.words_per_vertex : 0, 0u);
    table_.clear();
    if (!rule.rotate) {
        table_.resize(rule.points.size() * std::size_t(nc));
        for (std::size_t j = 0; j < rule.points.size(); ++j)
            eval_sh_f(out_.order, rule.points[j], &table_[j * std::size_t(nc)]);
    }
}

std::uint64_t TransferReduction::reduce(const VisibilityChunk& c) {
    if (c.words.empty())
        throw Error("the transfer reduction reads host visibility words; this tracer gave none", "backend");
    const std::uint32_t words = rule_.words_per_vertex;
    const auto directions = std::uint32_t(rule_.points.size());
    const int nc = out_.coefficients;
    const bool shadowed = out_.kind != TransferKind::Unshadowed;
    if (keep_words_)
        std::copy(c.words.begin(), c.words.end(), words_.begin() + std::ptrdiff_t(c.first) * words);
    std::atomic<std::uint64_t> rays{0};
    parallel_for(c.count, 64, [&](std::size_t b, std::size_t e) {
        std::uint64_t traced = 0;
        float y[sh_count(kPrtMaxOrder)];
        for (std::size_t i = b; i < e; ++i) {
            const std::size_t v = std::size_t(c.first) + i;
            const std::uint32_t* w = c.words.data() + i * words;
            const glm::vec3 n = c.normals[i];
            const glm::mat3 rot = rule_.rotate ? c.rotations[i] : glm::mat3(1.0f);
            float* t = out_.coeffs.data() + v * std::size_t(nc);
            float a = 0.0f;
            for (std::uint32_t j = 0; j < directions; ++j) {
                glm::vec3 x;
                float cos_n;
                visibility::vertex_direction(rule_.points[j], rot, rule_.rotate, n, x, cos_n);
                if (!visibility::needs_ray(cos_n))
                    continue;
                ++traced;
                const bool seen = visibility::get_bit(w, rule_.order[j]);
                if (seen)
                    a += 2.0f * rule_.weights[j] * (cos_n > 0.0f ? 1.0f : 0.5f);
                if ((shadowed && !seen) || !(cos_n > 0.0f))
                    continue;
                const float f = 4.0f * rule_.weights[j] * cos_n;
                const float* yj = y;
                if (rule_.rotate)
                    eval_sh_f(out_.order, x, y);
                else
                    yj = &table_[std::size_t(j) * std::size_t(nc)];
                for (int k = 0; k < nc; ++k)
                    t[k] += f * yj[k];
            }
            shading_[v] = a;
        }
        rays += traced;
    });
    return rays;
}

namespace {

// Sloan 2002, section 5: each bounce gathers, along every occluded rule
// direction, the transfer of the closest hit (interpolated, times its albedo).
void add_bounces(const Mesh& mesh, const SphereRule& rule, const BakeOptions& bake, const TransferReduction& red,
                 std::span<const glm::vec3> albedo, const std::vector<Image>& images, RayQueries& queries,
                 int bounces, Transfer& out, TransferReport& report) {
    const std::size_t n = mesh.vertex_count();
    const int nc = out.coefficients;

    // Closest hits of every occluded direction above the horizon, once, from
    // the bake's own ray origins.
    struct Gather {
        std::uint32_t vertex, triangle;
        float weight, u, v; // weight: w_k 4 (n·x_k)
        bool at_hit;        // rho is the albedo at the hit (a material's image), else the corners' albedo
        glm::vec3 rho;
    };
    std::vector<Gather> gathers;
    {
        const std::vector<BlockedDirection> blocked = blocked_directions(mesh, rule, bake, red.words(), queries);
        report.bounce_rays = blocked.size(); // traced once, gathered by every bounce
        gathers.reserve(blocked.size());
        for (const BlockedDirection& b : blocked) {
            Gather g{b.vertex, b.hit.triangle, 4.0f * b.weight * b.cosine, b.hit.u, b.hit.v, false, glm::vec3(0.0f)};
            if (!images.empty() && g.triangle != kNoHit)
                g.at_hit = surface_base_color(mesh, images, g.triangle, g.u, g.v, g.rho);
            gathers.push_back(g);
        }
    }
    // Gathers are grouped by vertex (pushed in vertex order).
    std::vector<std::size_t> start(n + 1, 0);
    for (const Gather& g : gathers)
        ++start[g.vertex + 1];
    for (std::size_t v = 0; v < n; ++v)
        start[v + 1] += start[v];

    // T^(0) grey → RGB; each bounce adds the light of the previous bounce only.
    const std::vector<float> direct = out.coeffs;
    std::vector<float> total(n * 3 * std::size_t(nc)), previous(n * 3 * std::size_t(nc));
    for (std::size_t v = 0; v < n; ++v)
        for (int ch = 0; ch < 3; ++ch)
            for (int k = 0; k < nc; ++k)
                total[(v * 3 + std::size_t(ch)) * std::size_t(nc) + std::size_t(k)] =
                    direct[v * std::size_t(nc) + std::size_t(k)];
    previous = total;
    std::vector<float> next(previous.size());
    for (int b = 0; b < bounces; ++b) {
        parallel_for(n, 64, [&](std::size_t lo, std::size_t hi) {
            for (std::size_t v = lo; v < hi; ++v) {
                float* t = next.data() + v * 3 * std::size_t(nc);
                std::fill(t, t + 3 * nc, 0.0f);
                for (std::size_t g = start[v]; g < start[v + 1]; ++g) {
                    const Gather& ga = gathers[g];
                    if (ga.triangle == kNoHit)
                        continue;
                    const std::uint32_t* tri = &mesh.indices[3 * std::size_t(ga.triangle)];
                    const float bw[3] = {1.0f - ga.u - ga.v, ga.u, ga.v};
                    for (int corner = 0; corner < 3; ++corner) {
                        const std::size_t h = tri[corner];
                        const glm::vec3 rho =
                            ga.at_hit ? ga.rho * (ga.weight * bw[corner]) : albedo[h] * (ga.weight * bw[corner]);
                        for (int ch = 0; ch < 3; ++ch) {
                            const float* src = previous.data() + (h * 3 + std::size_t(ch)) * std::size_t(nc);
                            float* dst = t + std::size_t(ch) * std::size_t(nc);
                            for (int k = 0; k < nc; ++k)
                                dst[k] += rho[ch] * src[k];
                        }
                    }
                }
            }
        });
        for (std::size_t i = 0; i < total.size(); ++i)
            total[i] += next[i];
        previous.swap(next);
    }
    out.coeffs = std::move(total);
    out.channels = 3;
}

} // namespace

TransferReport bake_transfer(Mesh& mesh, const SphereRule& rule, VisibilityTracer& tracer, const BakeOptions& bake,
                             const TransferOptions& options, std::span<const glm::vec3> albedo, RayQueries* queries,
                             Transfer& out, const std::vector<Image>& images) {
    const auto t0 = std::chrono::steady_clock::now();
    if (options.order < 0 || options.order > kPrtMaxOrder)
        throw Error(fmt::format("SH order must be 0 to {} (at most {} coefficients); got {}", kPrtMaxOrder,
                                sh_count(kPrtMaxOrder), options.order),
                    "order");
    const bool bounce = options.kind == TransferKind::Interreflected;
    if (bounce && (options.bounces < 1 || options.bounces > kMaxBounces))
        throw Error(fmt::format("interreflected transfer needs 1 to {} bounces; got {}", kMaxBounces, options.bounces),
                    "bounces");
    if (!bounce && options.bounces != 0)
        throw Error(fmt::format("bounces need the interreflected kind; the {} transfer has none",
                                transfer_kind_name(options.kind)),
                    "bounces");
    if (bounce && options.model != TransferModel::Prt)
        throw Error("the shading-coefficient model has no bounces", "model");
    if (bounce && !queries)
        throw Error(fmt::format("interreflection needs a backend that answers ray queries (embree or brute); the {} "
                                "tracer has none here",
                                tracer.name()),
                    "backend");
    validate_mesh(mesh, "mesh");
    if (mesh.normals.empty())
        compute_normals(mesh);
    if (bounce && albedo.size() != mesh.vertex_count())
        throw Error(fmt::format("{} albedo values for {} vertices", albedo.size(), mesh.vertex_count()), "albedo");

    out = Transfer{};
    out.order = options.order;
    out.coefficients = sh_count(options.order);
    out.kind = options.kind;
    out.model = options.model;
    out.bounces = options.bounces;
    out.rule = rule.spec;
    TransferReduction reduction(out, bounce);
    const VisibilityBakeStats stats = bake_visibility(mesh, rule, tracer, bake, reduction);

    TransferReport r;
    r.backend = tracer.name();
    r.rule = rule.spec;
    r.vertices = mesh.vertex_count();
    r.triangles = mesh.triangle_count();
    r.directions = rule.size();
    r.rays = stats.rays;
    r.trace_seconds = stats.trace_seconds;
    r.ray_offset = stats.ray_offset;

    if (options.model == TransferModel::ShadingCoefficient) {
        // T_lm = A (Â_l / π) Y_lm(n), A from the same bits.
        const std::vector<glm::vec3> normals = bake_vertex_normals(mesh);
        const int nc = out.coefficients;
        std::vector<double> zonal(std::size_t(options.order) + 1);
        for (int l = 0; l <= options.order; ++l)
            zonal[std::size_t(l)] = clamped_cosine_zonal(l) / M_PI;
        std::vector<double> y(static_cast<std::size_t>(nc));
        for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
            sh_eval(options.order, glm::dvec3(normals[v]), y.data());
            const double a = options.kind == TransferKind::Unshadowed ? 1.0 : double(reduction.shading()[v]);
            for (int l = 0; l <= options.order; ++l)
                for (int m = -l; m <= l; ++m)
                    out.coeffs[v * std::size_t(nc) + std::size_t(sh_index(l, m))] =
                        float(a * zonal[std::size_t(l)] * y[std::size_t(sh_index(l, m))]);
        }
    }
    out.shading = reduction.shading();
    if (bounce) {
        const auto tb = std::chrono::steady_clock::now();
        queries->set_mesh(mesh, bake.back_faces);
        add_bounces(mesh, rule, bake, reduction, albedo, images, *queries, options.bounces, out, r);
        r.bounce_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - tb).count();
    }
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return r;
}

} // namespace skybake
