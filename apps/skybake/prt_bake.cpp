// skybake prt bake INPUT -o OUTPUT.glb|.gltf|.ply [--order L] [--kind K] [--bounces N] [--rule R] [--backend B]
//                  [--device D] [--method M] [--resolution N] [--albedo A] [--model prt|shading-coefficient] [--max-distance D] [--json]
// Per-vertex diffuse SH transfer (skybake/prt.h), with a JSON sidecar.
// Under mpirun (or with --mpi) the visibility is spread over the ranks (job.h).
#include <limits>
#include <sstream>

#include "cli.h"
#include "commands.h"
#include "flags.h"
#include "job.h"
#include "skybake/bake_job.h"
#include "skybake/files.h"
#include "skybake/mesh.h"
#include "skybake/prt.h"

namespace skybake::cli {

namespace {

struct BakeOpts {
    std::string input, output, rule = "lebedev:590", kind = "shadowed", model = "prt", albedo, backend, method,
        device = "auto";
    std::uint32_t resolution = 0;
    int order = 3, bounces = 0;
    double max_distance = std::numeric_limits<double>::infinity();
    bool json = false, mpi = false;
};

void run(const BakeOpts& o, const CLI::App& sub) {
    const bool job = start_job(o.mpi); // first: in a job, every error is reported once
    BakeJob bake;
    bake.rule = parse_flag("--rule", [&] { return parse_rule(o.rule); });
    bake.shading = false;
    TransferOptions t;
    t.order = o.order;
    t.bounces = o.bounces;
    t.kind = parse_flag("--kind", [&] { return parse_transfer_kind(o.kind); });
    if (o.bounces > 0 && !given(sub, "--kind"))
        t.kind = TransferKind::Interreflected;
    if (t.kind == TransferKind::Interreflected && o.bounces == 0)
        throw UsageError("interreflected transfer needs --bounces N (1 to 16)", "--bounces");
    if (o.bounces > 0 && t.kind != TransferKind::Interreflected)
        throw UsageError(fmt::format("--bounces needs --kind interreflected, not {}", o.kind), "--bounces");
    t.model = parse_flag("--model", [&] { return parse_transfer_model(o.model); });
    if (t.model == TransferModel::ShadingCoefficient && o.bounces > 0)
        throw UsageError("the shading-coefficient model has no bounces", "--bounces");
    bake.tracer.device = o.device;
    bake.tracer.backend = o.backend;
    bake.tracer.method = o.method;
    bake.tracer.resolution = o.resolution;
    bake.options.max_distance = float(o.max_distance);
    bake.transfer = t;
    const TracerChoice choice = parse_flags([&] { return check_bake_job(bake); }); // every rank, before any work
    bake.made_tracer = make_visibility_tracer(choice); // no GPU or GL: exit 1, before the mesh is read
    const bool constant_albedo = !o.albedo.empty() && o.albedo != "material";
    const glm::vec3 albedo_value = constant_albedo ? parse_albedo(o.albedo) : glm::vec3(0.8f);
    check_output_path(o.output, {".glb", ".gltf", ".ply"}, "--output");
    if (job) {
        bake.wrap_tracer = [](std::unique_ptr<VisibilityTracer> local) { return job_tracer(std::move(local), true); };
        if (!job_root() && t.kind == TransferKind::Interreflected) {
            // The bounces run on rank 0, over the gathered words; the other
            // ranks only trace visibility, which the shadowed bake shares.
            bake.transfer->kind = TransferKind::Shadowed;
            bake.transfer->bounces = 0;
        }
    }

    // A glTF 2.0 input keeps its document, as with `ao` (skybake/gltf_asset.h).
    BakeFile file = open_bake_file(o.input, o.output);
    Mesh& mesh = file.mesh();
    const bool had_colors = mesh.colors.size() == mesh.vertex_count();
    test_fault_point("load");
    // --albedo material: the images are decoded once, for the vertices and
    // for the bounces' hits.
    if (!constant_albedo)
        bake.albedo_images = base_color_images(mesh);
    bake.albedo = constant_albedo ? std::vector<glm::vec3>(mesh.vertex_count(), albedo_value)
                                  : mesh_albedo(mesh, bake.albedo_images, albedo_value);
    const std::string albedo_source =
        constant_albedo ? fmt::format("[{}, {}, {}]", albedo_value.x, albedo_value.y, albedo_value.z)
                        : !mesh.materials.empty() && !mesh.triangle_parts.empty()
                            ? "material"
                            : (mesh.colors.size() == mesh.vertex_count() ? "vertex-colors" : "[0.8, 0.8, 0.8]");
    const BakeJobResult result = run_bake_job(mesh, bake);
    const TransferReport& r = result.transfer_report;
    const Transfer& transfer = result.transfer;
    if (job && !job_root())
        return; // rank 0 alone has the results, and writes them
    set_transfer_attributes(mesh, transfer, bake.albedo);
    if (!had_colors)
        set_white_sky_colors(mesh, transfer); // COLOR_0, as `ao` writes it, for any viewer

    OutputSet files;
    file.save(files.stage(o.output));
    const std::string side = transfer_sidecar_json(transfer, mesh.vertex_count(), albedo_source, !had_colors);
    write_stream_atomic(files.stage(prt_sidecar_path(o.output)), [&](std::ostream& out) { out << side; });
    files.commit();

    if (o.json) {
        print_json({{"input", o.input},
                    {"output", o.output},
                    {"sidecar", prt_sidecar_path(o.output).string()},
                    {"backend", r.backend},
                    {"rule", r.rule},
                    {"order", transfer.order},
                    {"coefficients", transfer.coefficients},
                    {"channels", transfer.channels},
                    {"kind", transfer_kind_name(transfer.kind)},
                    {"model", transfer_model_name(transfer.model)},
                    {"bounces", transfer.bounces},
                    {"vertices", r.vertices},
                    {"triangles", r.triangles},
                    {"rays", r.rays},
                    {"bounce_rays", r.bounce_rays},
                    {"seconds", r.seconds},
                    {"trace_seconds", r.trace_seconds},
                    {"bounce_seconds", r.bounce_seconds},
                    {"device", result.choice.device},
                    {"acceleration_structures", result.acceleration_structures}});
        return;
    }
    info("baked {} transfer (order {}, {} coefficients{}) of {} vertices with {} on {}: {} rays{} in {:.2f} s; "
         "wrote {} and {}",
         transfer_kind_name(transfer.kind), transfer.order, transfer.coefficients,
         transfer.channels == 3 ? " x RGB" : "", r.vertices, r.rule, r.backend, r.rays,
         r.bounce_rays ? fmt::format(" + {} bounce rays", r.bounce_rays) : std::string(), r.seconds, o.output,
         prt_sidecar_path(o.output).string());
}

} // namespace

void add_prt_bake(CLI::App& group) {
    auto o = std::make_shared<BakeOpts>();
    auto* sub = group.add_subcommand("bake", "Bake per-vertex diffuse SH transfer vectors (PRT)");
    sub->add_option("input", o->input, "Input mesh (any format 'mesh info' reads)")->required();
    sub->add_option("-o,--output", o->output,
                    "Output mesh (.glb, .gltf or .ply) with attributes prt_0..., albedo and COLOR_0 (the vertex "
                    "under a white sky, AO for a shadowed transfer, unless the input has colours); a glTF 2.0 "
                    "input keeps its whole document; a sidecar OUTPUT.prt.json beside it")
        ->required();
    sub->add_option("--order", o->order, "Highest SH band l (coefficients: (l+1)^2)")
        ->check(integer_in(0, kPrtMaxOrder))
        ->capture_default_str();
    sub->add_option("--kind", o->kind, "unshadowed, shadowed or interreflected")->capture_default_str();
    sub->add_option("--bounces", o->bounces, "Interreflection bounces (implies --kind interreflected)")
        ->check(integer_in(0, 16));
    sub->add_option("--rule", o->rule,
                    "Sphere rule, e.g. lebedev:590, design:t21; +rotate for a per-vertex "
                    "rotation")
        ->capture_default_str();
    sub->add_option("--device", o->device, device_help())->capture_default_str();
    sub->add_option("--backend", o->backend, backend_help() + " Bounces need a backend with closest hits.");
    sub->add_option("--method", o->method, "How blockers are found: one of the backend's methods (--backend)");
    sub->add_option("--resolution", o->resolution, "raster: cube face or depth map size in texels")
        ->check(CLI::Range(8u, kRasterMaxResolution));
    sub->add_option("--albedo", o->albedo,
                    "The bounces' albedo: material (the default: the material's base colour factor x image x vertex "
                    "colour, as glTF defines it, at each hit's UV; else the vertex colours; else 0.8), or a "
                    "constant linear RGB reflectance, one or three numbers in [0, 1]");
    sub->add_option("--model", o->model,
                    "prt (the transfer integral) or shading-coefficient (the seed's A times the unshadowed "
                    "irradiance)")
        ->capture_default_str();
    sub->add_option("--max-distance", o->max_distance, "Ignore occluders further than this, in mesh units")
        ->check(real_in(0.0, 1e30, "mesh units", End::Open));
    sub->add_flag("--mpi", o->mpi,
                  "Run as one rank of an MPI job even when no launcher's variables say so (under mpirun or srun "
                  "it is automatic); fails in a build without MPI");
    add_json_flag(*sub, o->json);
    sub->callback([o, sub] { run(*o, *sub); });
}

SKYBAKE_CLI_COMMAND("prt", add_prt_bake)

} // namespace skybake::cli
