// skybake sky sh [--model W.json | --preset P | --atmosphere A.json] --sun-elevation-deg E [--sun-azimuth-deg A]
//                [--altitude-km H] [--order L] [--rule R] [--device D] -o light.json [--json]
//                [--gltf MODEL.glb -o LIT.glb [--cube-size N]]
// The sky as RGB spherical harmonics, for PRT relighting (skybake/prt.h);
// or, written into a glTF document, as an EXT_lights_image_based light
// (order-2 irradiance and a radiance cube) for engines that read it.
#include <chrono>

#include "commands.h"
#include "flags.h"
#include "sky_common.h"
#include "skybake/files.h"
#include "skybake/gltf_asset.h"
#include "skybake/prt.h"
#include "skybake/sky_source.h"

namespace skybake::cli {

void add_sky_sh(CLI::App& group) {
    auto* sub = group.add_subcommand("sh", "Project the sky onto spherical harmonics (RGB) for PRT relighting");
    struct Opts {
        AtmosphereFlags atm;
        ModelFlag model;
        std::string output, gltf, rule = kSkyLightRule, device = "cpu", convention = "skybake", ground;
        int cube_size = 32;
        double elevation = 30.0, azimuth = 0.0, altitude = 0.0;
        int order = 3;
        bool json = false;
    };
    auto o = std::make_shared<Opts>();
    o->atm.add(*sub);
    o->model.add(*sub);
    sub->add_option("--sun-elevation-deg", o->elevation, "Sun above the horizon, degrees")
        ->check(real_in(-90.0, 90.0, "degrees"))
        ->capture_default_str();
    sub->add_option("--sun-azimuth-deg", o->azimuth, "Sun azimuth, degrees: 0 towards +z, 90 towards +x")
        ->check(real_in(-360.0, 360.0, "degrees"))
        ->capture_default_str();
    sub->add_option("--altitude-km", o->altitude, "Observer above the ground, km")
        ->check(real_in(0.0, 1e6, "km"))
        ->capture_default_str();
    sub->add_option("--order", o->order, "Highest SH band l (coefficients: (l+1)^2)")
        ->check(integer_in(0, kPrtMaxOrder))
        ->capture_default_str();
    sub->add_option("--rule", o->rule, "Sphere rule of the projection (see 'sphere list')")->capture_default_str();
    sub->add_option("--device", o->device, "cpu or cuda (the sky's evaluation)")->capture_default_str();
    sub->add_option("--sh-convention", o->convention,
                    "Signs of the written coefficients: skybake (no (-1)^m, Ramamoorthi & Hanrahan 2001) or "
                    "condon-shortley ((-1)^m, Sloan 2008 and D3DX: odd-|m| terms negated); the file records it")
        ->capture_default_str();
    sub->add_option("--ground-albedo", o->ground,
                    "Light the ground below the horizon: a Lambertian ground of this albedo (A or R,G,B in [0, 1]) "
                    "lit by the sun and the sky (default: none, only the air's light below the horizon)");
    sub->add_option("--gltf", o->gltf,
                    "A glTF 2.0 document (.glb or .gltf) to write again as -o LIT.glb/.gltf with the sky as an "
                    "EXT_lights_image_based light: order-2 irradiance SH (Babylon.js's basis) and a radiance cube");
    sub->add_option("--cube-size", o->cube_size, "With --gltf: texels along each face of the radiance cube")
        ->check(integer_in(1, 1024))
        ->capture_default_str();
    sub->add_option("-o,--output", o->output,
                    "Light JSON file (order, RGB coefficients, sun); with --gltf, the .glb or .gltf to write")
        ->required();
    add_json_flag(*sub, o->json);
    sub->callback([o, sub] {
        const bool gltf = !o->gltf.empty();
        if (gltf)
            check_output_path(o->output, {".glb", ".gltf"}, "--output");
        else
            check_output_path(o->output, {".json"}, "--output");
        if (!gltf && sub->count("--cube-size"))
            throw UsageError("--cube-size is for the light written into a glTF document (--gltf)", "--cube-size");
        if (gltf && sub->count("--order") && o->order != 2)
            throw UsageError("EXT_lights_image_based holds order 2 (9 coefficients); leave --order out", "--order");
        if (gltf && !o->ground.empty())
            throw UsageError("--ground-albedo lights the SH light file's lower hemisphere; the glTF light holds the sky "
                             "alone (its engine draws the ground)",
                             "--ground-albedo");
        if (gltf && sub->count("--sh-convention"))
            throw UsageError("EXT_lights_image_based fixes its SH convention (Babylon.js's); leave --sh-convention out",
                             "--sh-convention");
        if (gltf && (o->cube_size & (o->cube_size - 1)) != 0)
            throw UsageError(fmt::format("--cube-size {} is not a power of two", o->cube_size), "--cube-size");
        const SphereRule rule = parse_flag("--rule", [&] { return parse_rule(o->rule); });
        if (rule.kind == RuleKind::Phong)
            throw UsageError(fmt::format("'{}' integrates against a Phong lobe; use a horizon, lebedev, design, "
                                         "fibonacci or mc rule",
                                         rule.spec),
                             "--rule");
        const Device device = parse_flag("--device", [&] { return parse_device(o->device); });
        const ShConvention convention =
            parse_flag("--sh-convention", [&] { return parse_sh_convention(o->convention); });
        const bool neural = o->model.active();
        const SkySource sky = neural ? SkySource::network(o->model.load(*sub, o->atm), device)
                                     : SkySource::reference(SkyModel(o->atm.load(*sub)), SkyMethod::Tables, device);
        SkyLightSettings s;
        s.sun_elevation_deg = o->elevation;
        s.sun_azimuth_deg = o->azimuth;
        s.altitude_km = o->altitude;
        if (!o->ground.empty())
            s.ground_albedo = parse_albedo(o->ground, "--ground-albedo");
        if (gltf) {
            GltfAsset doc = parse_flag("--gltf", [&] { return GltfAsset::load(o->gltf); });
            const auto t0 = std::chrono::steady_clock::now();
            ImageBasedLight ibl = sky_image_based_light(sky, s, rule, o->cube_size);
            const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            const glm::vec3 e0 = ibl.irradiance[0];
            doc.set_image_based_light(std::move(ibl));
            doc.save(o->output);
            if (o->json) {
                print_json({{"output", o->output},
                            {"order", 2},
                            {"rule", rule.spec},
                            {"extension", "EXT_lights_image_based"},
                            {"cube_size", o->cube_size},
                            {"source", sky.method_name()},
                            {"seconds", seconds},
                            {"irradiance_00", {e0.x, e0.y, e0.z}}});
                return;
            }
            info("sky ({}) at sun elevation {} deg, altitude {} km -> EXT_lights_image_based (order 2 with {}, "
                 "{}x{} cube) in {:.2f} ms; wrote {}",
                 sky.method_name(), o->elevation, o->altitude, rule.spec, o->cube_size, o->cube_size, seconds * 1e3,
                 o->output);
            return;
        }
        const SkyProjector projector(o->order, rule);
        const auto t0 = std::chrono::steady_clock::now();
        const ShLight light = projector.project(sky, s);
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        const std::string text = light_json(light, neural ? "network" : "reference", rule.spec, convention);
        write_stream_atomic(o->output, [&](std::ostream& out) { out << text; });
        if (o->json) {
            print_json({{"output", o->output},
                        {"order", light.order},
                        {"rule", rule.spec},
                        {"sh_convention", sh_convention_name(convention)},
                        {"source", sky.method_name()},
                        {"seconds", seconds},
                        {"L00", {light.coeffs[0].x, light.coeffs[0].y, light.coeffs[0].z}},
                        {"sun_irradiance", {light.sun_irradiance.x, light.sun_irradiance.y, light.sun_irradiance.z}}});
            return;
        }
        info("sky ({}) at sun elevation {} deg, altitude {} km -> order {} SH with {} ({} points) in {:.2f} ms; "
             "wrote {}",
             sky.method_name(), o->elevation, o->altitude, light.order, rule.spec, rule.size(), seconds * 1e3,
             o->output);
    });
}

SKYBAKE_CLI_COMMAND("sky", add_sky_sh)

} // namespace skybake::cli
