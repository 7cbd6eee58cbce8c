// Measures the bake's per-vertex AO against a double-precision reference of
// our own on real meshes: the same sphere rule (directions, weights and
// per-vertex rotations), each ray from p + 1e-9·diagonal·n in double
// precision against every triangle (Möller–Trumbore in double, no BVH). The
// difference is then visibility alone: self-intersection (AO too low) or
// jumped surfaces (too high).
//
//   ray_origin_report MESH [RULE] [MAX_VERTICES] [OFFSET]
//
// Prints the RMS and largest difference, and how many vertices are off by
// more than 0.05. OFFSET (default: the bake's default) sets
// BakeOptions::ray_offset. Built as a tool, not a test: the reference costs
// vertices × directions × triangles.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "core/parallel.h"
#include "skybake/bake.h"
#include "skybake/mesh.h"
#include "skybake/sphere.h"
#include "sphere/random_rotation.h"
#include "visibility/triangle_hd.h"

using namespace skybake;

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: ray_origin_report MESH [RULE] [MAX_VERTICES] [OFFSET]\n");
        return 2;
    }
    try {
        Mesh mesh = load_mesh(argv[1]);
        const SphereRule rule = parse_rule(argc > 2 ? argv[2] : "lebedev:590+rotate");
        const std::size_t max_vertices = argc > 3 ? std::strtoull(argv[3], nullptr, 10) : 0;
        BakeOptions options;
        if (argc > 4)
            options.ray_offset = std::strtof(argv[4], nullptr);
        if (mesh.normals.empty())
            compute_normals(mesh);
        bake_ambient_occlusion(mesh, rule, "embree", options);
        const std::vector<float>& ao = mesh.find_attribute("ao")->values;

        const std::size_t n = mesh.vertex_count();
        const std::size_t step = max_vertices && n > max_vertices ? n / max_vertices : 1;
        std::vector<std::size_t> picked;
        for (std::size_t v = 0; v < n; v += step)
            picked.push_back(v);
        const double lift = 1e-9 * double(compute_bounds(mesh).diagonal());
        std::vector<double> ref(picked.size());
        parallel_for(picked.size(), 1, [&](std::size_t b, std::size_t e) {
            for (std::size_t i = b; i < e; ++i) {
                const std::size_t v = picked[i];
                const glm::dvec3 nrm = glm::normalize(glm::dvec3(mesh.normals[v]));
                const glm::dvec3 o = glm::dvec3(mesh.positions[v]) + lift * nrm;
                const glm::dmat3 R = rule.rotate_per_vertex
                                         ? sphere::vertex_rotation_hd<double>(std::uint32_t(v), rule.rotation_seed)
                                         : glm::dmat3(1.0);
                double sum = 0.0;
                for (std::size_t k = 0; k < rule.size(); ++k) {
                    const glm::dvec3 x = R * rule.points[k];
                    const double c = glm::dot(nrm, x);
                    if (c <= 0.0)
                        continue;
                    bool blocked = false;
                    for (std::size_t t = 0; t < mesh.triangle_count() && !blocked; ++t) {
                        const glm::dvec3 p0 = mesh.positions[mesh.indices[3 * t]];
                        const glm::dvec3 p1 = mesh.positions[mesh.indices[3 * t + 1]];
                        const glm::dvec3 p2 = mesh.positions[mesh.indices[3 * t + 2]];
                        double tt, u, w;
                        blocked = visibility::ray_triangle(o, x, p0, p1 - p0, p2 - p0, 0.0, 1e300, tt, u, w);
                    }
                    if (!blocked)
                        sum += rule.weights[k] * 4.0 * c;
                }
                ref[i] = std::clamp(sum, 0.0, 1.0);
            }
        });
        double s2 = 0.0, worst = 0.0, mean_bake = 0.0, mean_ref = 0.0;
        std::size_t off = 0;
        for (std::size_t i = 0; i < picked.size(); ++i) {
            const double d = double(ao[picked[i]]) - ref[i];
            s2 += d * d;
            worst = std::max(worst, std::abs(d));
            off += std::abs(d) > 0.05;
            if (std::abs(d) > 0.05 && std::getenv("RAY_ORIGIN_REPORT_LIST"))
                std::printf("vertex %zu: bake %.3f reference %.3f\n", picked[i], ao[picked[i]], ref[i]);
            mean_bake += ao[picked[i]];
            mean_ref += ref[i];
        }
        const double m = double(picked.size());
        std::printf("%s, %s, %zu of %zu vertices: RMS %.4f, max %.3f, %zu off by > 0.05; mean AO bake %.4f, "
                    "reference %.4f\n",
                    argv[1], rule.spec.c_str(), picked.size(), n, std::sqrt(s2 / m), worst, off, mean_bake / m,
                    mean_ref / m);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "ray_origin_report: %s\n", e.what());
        return 1;
    }
    return 0;
}
