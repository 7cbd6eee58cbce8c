// skybake mesh generate --kind K --triangles N [--seed S] -o FILE [--ascii] [--json]
#include <chrono>
#include <cstdint>

#include "cli.h"
#include "commands.h"
#include "flags.h"
#include "skybake/mesh.h"

namespace skybake::cli {

namespace {
struct MeshGenerateOptions {
    std::string kind = "sphere";
    std::uint64_t triangles = 20000;
    std::uint64_t seed = 1;
    std::string output;
    bool ascii = false;
    bool json = false;
};

void run(const MeshGenerateOptions& o) {
    ProceduralOptions p;
    p.kind = parse_flag("--kind", [&] { return parse_procedural_kind(o.kind); });
    check_output_path(o.output, {".glb", ".ply"}, "--output");
    if (o.ascii && lower_extension(o.output) != ".ply")
        throw UsageError("--ascii applies to .ply outputs only", "--ascii");
    p.target_triangles = o.triangles;
    p.seed = o.seed;
    const auto t0 = std::chrono::steady_clock::now();
    const Mesh mesh = generate_mesh(p);
    ExportOptions e;
    e.ply_encoding = o.ascii ? PlyEncoding::Ascii : PlyEncoding::Binary;
    save_mesh(o.output, mesh, e);
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (o.json) {
        print_json({{"kind", o.kind},
                    {"seed", o.seed},
                    {"output", o.output},
                    {"vertices", mesh.vertex_count()},
                    {"triangles", mesh.triangle_count()},
                    {"seconds", secs}});
        return;
    }
    info("wrote {} ({} vertices, {} triangles) in {:.2f} s", o.output, mesh.vertex_count(), mesh.triangle_count(),
         secs);
}
} // namespace

void add_mesh_generate(CLI::App& group) {
    auto o = std::make_shared<MeshGenerateOptions>();
    CLI::App* sub = group.add_subcommand("generate", "Write a deterministic procedural mesh (for tests and benchmarks)");
    std::string kinds;
    for (const auto& k : procedural_kind_names())
        kinds += (kinds.empty() ? "" : "|") + k;
    sub->add_option("--kind", o->kind, kinds)->capture_default_str();
    sub->add_option("--triangles", o->triangles, "Approximate triangle count")
        ->check(integer_in(20, 50'000'000))
        ->capture_default_str();
    sub->add_option("--seed", o->seed, "Seed for terrain and city layouts")
        ->check(integer_in(0, INT64_MAX))
        ->capture_default_str();
    sub->add_option("-o,--output", o->output, "Output mesh (.glb or .ply)")->required();
    sub->add_flag("--ascii", o->ascii, "Write PLY as ASCII instead of binary");
    add_json_flag(*sub, o->json);
    sub->callback([o] { run(*o); });
}

SKYBAKE_CLI_COMMAND("mesh", add_mesh_generate)

} // namespace skybake::cli
