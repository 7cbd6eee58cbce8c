// skybake ao INPUT -o OUTPUT.glb|.gltf|.ply [--rule R] [--device D] [--backend B] [--method M] [--resolution N]
//            [--max-distance D] [--offset E]
//            [--back-faces occlude|ignore] [--normalize] [--bits FILE] [--preview FILE.png]
//            [--preview-size WxH] [--texture N [--uv K] [--texture-out FILE.png|.exr] [--dilate N]] [--json]
// skybake ao --batch LIST --out-dir DIR [the same bake flags]
// Under mpirun (or with --mpi) the bake is spread over the ranks (job.h).
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <sstream>
#include <limits>
#include <optional>

#include "cli.h"
#include "commands.h"
#include "flags.h"
#include "job.h"
#include "skybake/files.h"
#include "skybake/bake.h"
#include "skybake/bake_job.h"
#include "skybake/core.h"
#include "skybake/gltf_asset.h"
#include "skybake/interrupt.h"
#include "skybake/mesh.h"
#include "skybake/prt.h"
#include "skybake/sphere.h"
#include "skybake/texture_bake.h"
#include "skybake/visibility.h"
#include "skybake/image_io.h"

namespace skybake::cli {

namespace {

constexpr const char* kDefaultRule = "lebedev:590";

struct AoOptions {
    std::string input, output;
    std::string rule = kDefaultRule;
    std::string device = "auto";
    std::string backend; // empty: embree on the CPU, cuda on the GPU
    std::string method; // empty: the backend's default (bvh; cube for raster)
    std::uint32_t resolution = 0; // raster: 0 = the method's default
    double max_distance = std::numeric_limits<double>::infinity();
    std::string offset = "auto";
    std::string back_faces = "occlude";
    bool normalize = false;
    std::string bits;
    std::string preview;
    std::string preview_size = "960x720";
    float azimuth_deg = 35.0f, elevation_deg = 30.0f;
    bool json = false;
    int texture = 0; // texture size; 0: no texture bake
    int uv = 0;
    std::string texture_out;
    int dilate = 8;
    bool keep_seams = false;
    bool mpi = false;
    std::string batch, out_dir;
};

// The texture file beside the output: OUT.glb -> OUT_ao.png.
std::string default_texture_path(const std::string& output) {
    std::filesystem::path p(output);
    return (p.parent_path() / (p.stem().string() + "_ao.png")).string();
}

// Wires `image` as the occlusion texture of a plain mesh's materials, giving
// the parts without one (or the whole mesh) a material of their own.
void wire_occlusion(Mesh& mesh, const std::string& image, int uv_set, const std::string& png) {
    int bare = -1;
    auto bare_material = [&] {
        if (bare < 0) {
            mesh.materials.push_back({});
            mesh.materials.back().name = "skybake occlusion";
            bare = int(mesh.materials.size() - 1);
        }
        return bare;
    };
    if (mesh.triangle_parts.empty()) {
        mesh.parts.assign(1, MeshPart{});
        mesh.triangle_parts.assign(mesh.triangle_count(), 0);
    }
    for (auto& part : mesh.parts)
        if (part.material < 0)
            part.material = bare_material();
    for (auto& m : mesh.materials) {
        m.occlusion_texture = image;
        m.occlusion_image.assign(png.begin(), png.end());
        m.occlusion_texcoord = uv_set;
    }
}

nlohmann::json stats(const std::vector<float>& v) {
    if (v.empty())
        return nullptr;
    double sum = 0.0;
    float lo = v[0], hi = v[0];
    for (float x : v) {
        sum += x;
        lo = std::min(lo, x);
        hi = std::max(hi, x);
    }
    return {{"min", lo}, {"mean", sum / double(v.size())}, {"max", hi}};
}

// The tracer for --device, --backend, --method and --resolution, resolved by
// the library (its errors name the fields, which main() maps to the flags).
TracerChoice tracer_choice(const AoOptions& o) {
    TracerRequest r;
    r.device = o.device;
    r.backend = o.backend;
    r.method = o.method;
    r.resolution = o.resolution;
    return parse_flags([&] { return resolve_tracer(r); });
}

// One bake: INPUT to OUTPUT. `job`: spread over the ranks of an MPI job.
void run(const AoOptions& o, const CLI::App& sub, bool job) {
    // Everything that can be checked without the mesh is checked first, so a
    // typo fails at once and no output file is started.
    BakeJob bake;
    bake.rule = parse_flag("--rule", [&] { return parse_rule(o.rule); });
    bake.tracer.device = o.device;
    bake.tracer.backend = o.backend;
    bake.tracer.method = o.method;
    bake.tracer.resolution = o.resolution;
    bake.options.max_distance = float(o.max_distance);
    const BackFaces back_faces = parse_flag("--back-faces", [&] { return parse_back_faces(o.back_faces); });
    AoPreviewOptions preview;
    parse_flag("--preview-size", [&] { parse_size(o.preview_size, preview.width, preview.height, "--preview-size"); });
    if (o.preview.empty())
        for (const char* f : {"--preview-size", "--preview-azimuth", "--preview-elevation"})
            refuse_if_given(sub, f, "without --preview");
    preview.azimuth_deg = o.azimuth_deg;
    preview.elevation_deg = o.elevation_deg;
    check_output_path(o.output, {".glb", ".gltf", ".ply"}, "--output");
    if (!o.preview.empty())
        check_output_path(o.preview, {".png", ".exr"}, "--preview");
    if (!o.bits.empty())
        check_output_path(o.bits, {}, "--bits");
    const std::string texture_out = o.texture_out.empty() ? default_texture_path(o.output) : o.texture_out;
    if (o.texture == 0) {
        for (const char* f : {"--uv", "--texture-out", "--dilate", "--keep-seams"})
            refuse_if_given(sub, f, "without --texture");
    } else {
        check_output_path(texture_out, {".png", ".exr"}, "--texture-out");
        if (lower_extension(o.output) == ".ply")
            throw UsageError("a texture bake is wired into a glTF material; write the mesh as .glb or .gltf",
                             "--output");
    }
    BakeOptions& b = bake.options;
    b.ray_offset = o.offset == "auto" ? 0.0f : float(std::stod(o.offset)); // validated: auto or a number ≥ 0
    b.back_faces = back_faces;
    b.normalize = o.normalize;
    bake.bits = !o.bits.empty();
    if (o.texture != 0) {
        bake.texture.emplace();
        bake.texture->texture_size = o.texture;
        bake.texture->uv_set = o.uv;
        bake.texture->dilate_texels = o.dilate;
        bake.texture->stitch_seams = !o.keep_seams;
    }
    if (!o.preview.empty() && (!job || job_root()))
        bake.preview = preview;
    if (job) // each rank traces its share with its own backend
        bake.wrap_tracer = [](std::unique_ptr<VisibilityTracer> local) { return job_tracer(std::move(local), true); };
    const TracerChoice choice = parse_flags([&] { return check_bake_job(bake); });
    bake.made_tracer = make_visibility_tracer(choice); // no GPU or GL: exit 1, before the mesh is read
    const TraceMethod method = choice.method;
    const std::uint32_t resolution = !choice.backend->resolution  ? 0
                                     : o.resolution                ? o.resolution
                                     : method == TraceMethod::Cube ? raster_cube_resolution(bake.rule.size())
                                                                   : kRasterDirectionalResolution;

    // A glTF 2.0 input written as glTF is baked in place: the output is the
    // input document with the new attributes (skybake/gltf_asset.h).
    BakeFile file = open_bake_file(o.input, o.output);
    GltfAsset* asset = file.document();
    Mesh& mesh = file.mesh();
    test_fault_point("load");
    if (bake.texture && bake.preview)
        bake.base_colors = base_color_images(mesh); // the texture shown over them, where they load
    BakeJobResult result = run_bake_job(mesh, bake);
    const AoBakeReport& r = result.ao;
    const BakeOutputs& outputs = result.outputs;
    const std::optional<AoTexture>& texture = result.texture;
    if (texture && texture->overlapping_texels > 0)
        info("warning: UV set {} overlaps: {} texel centres lie in two or more triangles ({} triangles); "
             "the nearest triangle in mesh order wins there",
             o.uv, texture->overlapping_texels, texture->overlapping_triangles);
    // A .glb embeds a PNG texture, so that it travels alone; the file is
    // written beside it too. A .gltf names the file.
    const bool texture_png = texture && lower_extension(texture_out) == ".png";
    const std::string png =
        texture_png ? encode_png16_gray(texture->texture_size, texture->texture_size, texture->ao) : std::string();
    const std::string embedded = lower_extension(o.output) == ".glb" ? png : std::string();
    if (texture) {
        if (asset)
            asset->set_occlusion_texture(texture_out, o.uv, embedded);
        else
            wire_occlusion(mesh, std::filesystem::absolute(texture_out).string(), o.uv, embedded);
    }

    if (job && !job_root())
        return; // in a job, rank 0 alone has the results, and writes them

    // Every output is staged, then all are committed together: a failure in
    // any one of them leaves none written.
    OutputSet files;
    file.save(files.stage(o.output));
    if (!o.preview.empty())
        save_image(files.stage(o.preview), result.preview, ToneMap{0.0f, ToneCurve::Clamp});
    if (!o.bits.empty())
        save_visibility_bits(files.stage(o.bits), outputs, bake.rule);
    if (texture) {
        const int n = texture->texture_size;
        if (lower_extension(texture_out) == ".exr") {
            Image image(n, n);
            for (std::size_t k = 0; k < texture->ao.size(); ++k)
                image.rgb[3 * k] = image.rgb[3 * k + 1] = image.rgb[3 * k + 2] = texture->ao[k];
            save_exr(files.stage(texture_out), image);
        } else {
            write_stream_atomic(files.stage(texture_out), [&](std::ostream& out) { out.write(png.data(), std::streamsize(png.size())); });
        }
    }
    files.commit();

    const std::string device = result.device_name;
    if (o.json) {
        nlohmann::json j = {{"input", o.input},
                            {"output", o.output},
                            {"backend", r.backend},
                            {"method", r.method},
                            {"device", choice.device},
                            {"gpu", device.empty() ? nlohmann::json(nullptr) : nlohmann::json(device)},
                            {"resolution", resolution ? nlohmann::json(resolution) : nlohmann::json(nullptr)},
                            {"rule", r.rule},
                            {"directions", r.directions},
                            {"vertices", r.vertices},
                            {"triangles", r.triangles},
                            {"rays", r.rays},
                            {"seconds", r.seconds},
                            {"build_seconds", r.build_seconds},
                            {"trace_seconds", r.trace_seconds},
                            {"rays_per_second", r.rays_per_second()},
                            {"ray_offset", r.ray_offset},
                            {"max_distance", std::isfinite(b.max_distance) ? nlohmann::json(b.max_distance) : nullptr},
                            {"back_faces", back_faces_name(b.back_faces)},
                            {"normalize", b.normalize},
                            {"negative_weights", r.negative_weights},
                            {"clamped_vertices", r.clamped_vertices},
                            {"ao", stats(outputs.ao)},
                            {"shading", stats(outputs.shading)},
                            {"preview", o.preview.empty() ? nlohmann::json(nullptr) : nlohmann::json(o.preview)},
                            {"bits", o.bits.empty() ? nlohmann::json(nullptr) : nlohmann::json(o.bits)},
                            {"threads", thread_count()},
                            {"acceleration_structures", result.acceleration_structures}};
        if (job) {
            const DistributedStats d = last_distributed_stats();
            j["ranks"] = d.ranks;
            j["gathered_bytes"] = d.bytes_gathered;
            j["gather_seconds"] = d.gather_seconds;
            j["distributed_seconds"] = d.trace_seconds;
            j["points_per_rank"] = d.points_per_rank;
        }
        j["vertices_per_second"] = r.trace_seconds > 0 ? double(r.vertices) / r.trace_seconds : 0.0;
        if (texture) {
            const double sec = texture->trace_seconds;
            j["texture"] = {{"file", texture_out},
                            {"size", texture->texture_size},
                            {"uv_set", o.uv},
                            {"covered_texels", texture->covered_texels},
                            {"overlapping_texels", texture->overlapping_texels},
                            {"overlapping_triangles", texture->overlapping_triangles},
                            {"dilate_texels", o.dilate},
                            {"seam_edges", texture->seams.seam_edges},
                            {"seam_mismatch_before_max", texture->seams.mismatch_before_max},
                            {"seam_mismatch_after_max", texture->seams.mismatch_after_max},
                            {"rays", texture->rays},
                            {"sample_seconds", texture->sample_seconds},
                            {"build_seconds", texture->build_seconds},
                            {"trace_seconds", sec},
                            {"texels_per_second", sec > 0 ? double(texture->covered_texels) / sec : 0.0}};
        } else {
            j["texture"] = nullptr;
        }
        print_json(j);
        return;
    }
    double mean = 0.0;
    for (float a : outputs.ao)
        mean += a;
    mean /= double(std::max<std::size_t>(1, outputs.ao.size()));
    info("baked {} vertices ({} triangles) with {} ({} directions, {}{}{}): {} rays in {:.2f} s ({:.1f} Mrays/s), "
         "{} {:.2f} s",
         r.vertices, r.triangles, r.rule, r.directions, r.backend,
         method == TraceMethod::Bvh ? ""
         : resolution != 0          ? fmt::format(" {} {}", r.method, resolution)
                                    : " " + r.method,
         device.empty() ? "" : " on " + device, r.rays, r.seconds, r.rays_per_second() * 1e-6,
         resolution != 0 ? "mesh upload" : "BVH", r.build_seconds);
    if (r.negative_weights)
        info("note: {} has negative weights; {} vertices had sums outside [0, 1], clamped", r.rule,
             r.clamped_vertices);
    if (texture)
        info("texture {}x{}: {} texels covered, {} rays in {:.2f} s ({:.0f} texels/s; vertices {:.0f}/s)",
             texture->texture_size, texture->texture_size, texture->covered_texels, texture->rays,
             texture->trace_seconds, double(texture->covered_texels) / std::max(1e-9, texture->trace_seconds),
             double(r.vertices) / std::max(1e-9, r.trace_seconds));
    info("mean AO {:.4f}, ray offset {:.3g}; wrote {}{}{}{}", mean, r.ray_offset, o.output,
         o.preview.empty() ? "" : ", " + o.preview, o.bits.empty() ? "" : ", " + o.bits,
         texture ? ", " + texture_out : "");
}

// [batch] ------------------------------------------------------------------------------
//
// `--batch LIST --out-dir DIR`: every asset of LIST (one path a line, relative
// to LIST's folder; blank lines and lines starting with # skipped) is baked to
// DIR/<stem>.glb with the same flags, whole meshes handed to the ranks of a
// job from a queue on rank 0. Beside each output, DIR/<stem>.glb.bake.json
// records the input (absolute path, size, modification time) and the flags
// that shape the result; a rerun skips an asset whose output and record are
// both there, the record matches, and the output is not older than the input.

// The flags that shape a bake's output, as one text (recorded, and compared on a rerun).
std::string batch_flags(const AoOptions& o) {
    return fmt::format("skybake {}; rule {}; device {}; backend {}; method {}; resolution {}; max-distance {}; "
                       "offset {}; back-faces {}; normalize {}; texture {}; uv {}; dilate {}",
                       version(), o.rule, o.device, o.backend.empty() ? "default" : o.backend,
                       o.method.empty() ? "default" : o.method, o.resolution, o.max_distance, o.offset, o.back_faces,
                       o.normalize, o.texture, o.uv, o.dilate);
}

std::int64_t mtime_ns(const std::filesystem::path& p) {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(std::filesystem::last_write_time(p).time_since_epoch())
        .count();
}

nlohmann::json batch_record(const std::filesystem::path& input, const AoOptions& o) {
    return {{"input", std::filesystem::absolute(input).lexically_normal().string()},
            {"input_bytes", std::filesystem::file_size(input)},
            {"input_mtime_ns", mtime_ns(input)},
            {"flags", batch_flags(o)}};
}

std::filesystem::path record_path(const std::filesystem::path& output) {
    return output.string() + ".bake.json";
}

// Whether `output` is complete and current for `input` baked with `o`.
bool batch_current(const std::filesystem::path& input, const std::filesystem::path& output, const AoOptions& o) {
    std::error_code ec;
    const std::filesystem::path rec = record_path(output);
    if (!std::filesystem::is_regular_file(output, ec) || !std::filesystem::is_regular_file(rec, ec) ||
        !std::filesystem::is_regular_file(input, ec))
        return false;
    if (o.texture != 0 && !std::filesystem::is_regular_file(default_texture_path(output.string()), ec))
        return false;
    try {
        const nlohmann::json want = batch_record(input, o);
        const nlohmann::json have = nlohmann::json::parse(read_file(rec, 1 << 20));
        return have == want && mtime_ns(output) >= want["input_mtime_ns"].get<std::int64_t>();
    } catch (const std::exception&) {
        return false; // unreadable record: bake again
    }
}

void run_batch(const AoOptions& o, const CLI::App& sub, bool job) {
    for (const char* f : {"input", "--output", "--bits", "--preview", "--texture-out", "--json"})
        refuse_if_given(sub, f, "with --batch (each asset's outputs are named after it in --out-dir)");
    if (o.out_dir.empty())
        throw UsageError("--batch needs --out-dir DIR for the outputs", "--out-dir");
    // The flags are checked once, before any asset.
    parse_flag("--rule", [&] { return parse_rule(o.rule); });
    tracer_choice(o);
    parse_flag("--back-faces", [&] { return parse_back_faces(o.back_faces); });

    const std::filesystem::path list(o.batch);
    std::vector<std::filesystem::path> assets;
    {
        std::istringstream in(read_file(list, std::uint64_t(64) << 20));
        std::string line;
        while (std::getline(in, line)) {
            const auto b = line.find_first_not_of(" \t\r");
            if (b == std::string::npos || line[b] == '#')
                continue;
            const auto e = line.find_last_not_of(" \t\r");
            const std::filesystem::path p(line.substr(b, e - b + 1));
            assets.push_back(p.is_absolute() ? p : list.parent_path() / p);
        }
    }
    if (assets.empty())
        throw Error(fmt::format("{} lists no assets (one path a line; # starts a comment)", o.batch), "--batch");
    const std::filesystem::path dir(o.out_dir);
    OutputFolder folder(o.out_dir, "--out-dir");
    folder.keep(); // each asset's outputs are committed on their own
    std::vector<std::filesystem::path> outputs;
    std::map<std::string, std::size_t> by_output;
    for (std::size_t i = 0; i < assets.size(); ++i) {
        outputs.push_back(dir / (assets[i].stem().string() + ".glb"));
        const auto [it, fresh] = by_output.emplace(outputs.back().string(), i);
        if (!fresh)
            throw Error(fmt::format("{} and {} would both be written to {}; rename one", assets[it->second].string(),
                                    assets[i].string(), outputs.back().string()),
                        "--batch");
    }

    // Each task bakes one whole asset on one rank; its failure is reported,
    // not fatal. Results: "" baked, "skip" current, else the error line.
    const auto task = [&](std::size_t i) -> std::string {
        if (batch_current(assets[i], outputs[i], o))
            return "skip";
        try {
            AoOptions one = o;
            one.input = assets[i].string();
            one.output = outputs[i].string();
            one.batch.clear();
            run(one, sub, false);
            const std::string record = batch_record(assets[i], o).dump(2) + "\n";
            write_stream_atomic(record_path(outputs[i]), [&](std::ostream& out) { out << record; });
            return {};
        } catch (const Interrupted&) {
            throw;
        } catch (const UsageError& e) {
            return format_error_line(e.message(), e.where());
        } catch (const Error& e) {
            return format_error_line(e.message(), flag_for_field(e.where()));
        } catch (const std::exception& e) {
            return fmt::format("internal error: {}", e.what());
        }
    };
    const std::vector<std::string> results = run_task_queue(assets.size(), task, "batch");
    std::int64_t failed = 0;
    if (job_root()) {
        std::size_t baked = 0, skipped = 0;
        for (const std::string& r : results) {
            if (r.empty())
                ++baked;
            else if (r == "skip")
                ++skipped;
            else
                ++failed;
        }
        std::fprintf(stderr, "skybake: batch: %zu assets: %zu baked, %zu current (skipped), %lld failed\n",
                     assets.size(), baked, skipped, static_cast<long long>(failed));
        for (std::size_t i = 0; i < results.size(); ++i)
            if (!results[i].empty() && results[i] != "skip")
                std::fprintf(stderr, "skybake: failed: %s: %s\n", assets[i].string().c_str(), results[i].c_str());
    }
    if (job)
        failed = broadcast_from_root(failed);
    if (failed > 0)
        throw JobError(fmt::format("{} of {} assets failed (listed above); the others are written", failed,
                                   assets.size()),
                       "--batch");
}

} // namespace

void add_ao_bake(CLI::App& group) {
    auto o = std::make_shared<AoOptions>();
    CLI::App* sub = &group;
    sub->add_option("input", o->input, "Input mesh (any format 'mesh info' reads); not with --batch");
    sub->add_option("-o,--output", o->output, "Output mesh with AO, shading and bent normals (.glb, .gltf or .ply); a glTF 2.0 input keeps its "
                    "whole document (nodes, materials, UVs, animations...)");
    sub->add_option("--rule", o->rule,
                    "Sphere rule, e.g. lebedev:5810, design:t21, fibonacci:1000, mc:4096; add +rotate for a random "
                    "rotation per vertex (see 'sphere list')")
        ->capture_default_str();
    sub->add_option("--device", o->device, device_help())->capture_default_str();
    sub->add_option("--backend", o->backend, backend_help());
    sub->add_option("--method", o->method,
                    "How blockers are found. cuda: bvh (default), per-vertex (every triangle for every ray, the "
                    "seed's naive method) or per-polygon (every triangle, cached in shared memory); raster: cube "
                    "(default: a depth cube map per vertex, the seed's) or directional (a depth map per direction)");
    sub->add_option("--resolution", o->resolution,
                    "raster: cube face or depth map size in texels (default: cube, from the rule's spacing, 32 for "
                    "lebedev:590; directional, 2048)")
        ->check(CLI::Range(8u, kRasterMaxResolution));
    sub->add_option("--max-distance", o->max_distance,
                    "Ignore occluders further than this, in mesh units (default: unlimited)")
        ->check(real_in(0.0, 1e30, "mesh units", End::Open)); // stored as a float
    sub->add_option("--offset", o->offset,
                    "Move ray origins this much further along the normal, in mesh units; auto (= 0): only the "
                    "step past rounding, 2^-15 of the vertex's coordinates")
        ->check(auto_or_real_in(0.0, kMaxRayOffset, "mesh units"))
        ->capture_default_str();
    sub->add_option("--back-faces", o->back_faces,
                    "occlude: both sides of a triangle block rays; ignore: rays pass through triangles seen from "
                    "behind (open, single-sided meshes)")
        ->capture_default_str();
    sub->add_flag("--normalize", o->normalize,
                  "Divide AO and A by their unoccluded sums (an open vertex gets exactly 1 with any rule)");
    sub->add_option("--bits", o->bits, "Also write the bit-packed visibility per rule direction to this file");
    sub->add_option("--preview", o->preview, "Also write a preview image (.png or .exr) shaded by the baked AO");
    sub->add_option("--preview-size", o->preview_size, "Preview size WxH in pixels")->capture_default_str();
    sub->add_option("--preview-azimuth", o->azimuth_deg, "Preview camera azimuth around +y, degrees")
        ->check(real_in(-360.0, 360.0, "degrees"))
        ->capture_default_str();
    sub->add_option("--preview-elevation", o->elevation_deg, "Preview camera elevation, degrees")
        ->check(real_in(-90.0, 90.0, "degrees"))
        ->capture_default_str();
    sub->add_option("--texture", o->texture,
                    "Also bake AO into a texture of this many texels square over the mesh's UVs, wired as the "
                    "glTF material's occlusionTexture")
        ->check(integer_in(kMinTextureSize, kMaxTextureSize, "texels"));
    sub->add_option("--uv", o->uv, "UV set (TEXCOORD_n) of the texture bake")
        ->check(integer_in(0, 7))
        ->capture_default_str();
    sub->add_option("--texture-out", o->texture_out,
                    "The AO texture file: .png (16-bit grey) or .exr (default: OUTPUT's name + _ao.png)");
    sub->add_option("--dilate", o->dilate, "Gutter grown around the UV islands of the texture, texels")
        ->check(integer_in(0, 256, "texels"))
        ->capture_default_str();
    sub->add_flag("--keep-seams", o->keep_seams,
                  "Leave the texture as traced along UV seams; by default the texels there are adjusted so that "
                  "both sides of a seam read the same AO");
    add_json_flag(*sub, o->json);
    sub->add_flag("--mpi", o->mpi,
                  "Run as one rank of an MPI job even when no launcher's variables say so (under mpirun or srun "
                  "it is automatic); fails in a build without MPI");
    sub->add_option("--batch", o->batch,
                    "Bake every asset listed in this file (one path a line, relative to the file; # comments) to "
                    "--out-dir, skipping outputs that are current; under mpirun whole assets go to the ranks");
    sub->add_option("--out-dir", o->out_dir, "With --batch: the folder of the outputs, DIR/<stem>.glb");
    sub->callback([o, sub] {
        const bool job = start_job(o->mpi);
        if (!o->batch.empty())
            return run_batch(*o, *sub, job);
        refuse_if_given(*sub, "--out-dir", "without --batch");
        if (o->input.empty())
            throw UsageError("the input mesh is missing: skybake ao INPUT -o OUTPUT (or --batch LIST)", "input");
        if (o->output.empty())
            throw UsageError("--output is required: the baked mesh (.glb, .gltf or .ply)", "--output");
        run(*o, *sub, job);
    });
}

SKYBAKE_CLI_GROUP_COMMAND("ao", add_ao_bake)

} // namespace skybake::cli
