// skybake prt relight BAKED.glb --light sky|constant|FILE.exr|FILE.hdr|FILE.json [--sun-elevation-deg E]
//                    [--sun-azimuth-deg A] [--altitude-km H] [--model W.json | --preset P] [--radiance R]
//                    [--no-sun] [--glossy A [--specular KS]] [--rule R] [--view AZ,EL] [--size WxH]
//                    [--exposure EV] -o OUT.ply|.png|.exr
// Lights a baked transfer (skybake/prt.h): per-vertex radiance, or an image.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "cli.h"
#include "commands.h"
#include "flags.h"
#include "sky_common.h"
#include "skybake/files.h"
#include "skybake/mesh.h"
#include "skybake/prt.h"
#include "skybake/image_io.h"

namespace skybake::cli {

namespace {

struct RelightOpts {
    AtmosphereFlags atm;
    ModelFlag model;
    std::string input, output, light = "sky", rule = kSkyLightRule, size = "960x720", view = "35,30",
                               exposure = "auto";
    double elevation = 30.0, azimuth = 0.0, altitude = 0.0, radiance = 1.0, glossy = 0.0, specular = 0.3;
    bool no_sun = false, json = false;
};

void run(const RelightOpts& o, const CLI::App& sub) {
    check_output_path(o.output, {".ply", ".png", ".exr"}, "--output");
    const std::string ext = lower_extension(o.output);
    const SphereRule rule = parse_flag("--rule", [&] { return parse_rule(o.rule); });
    AoPreviewOptions view;
    if (ext == ".ply") {
        for (const char* f : {"--size", "--view", "--exposure", "--glossy", "--specular"})
            refuse_if_given(sub, f, "to a .ply output (per-vertex radiance)");
    } else {
        parse_flag("--size", [&] { parse_size(o.size, view.width, view.height, "--size"); });
        float az = 0.0f, el = 0.0f;
        char comma = 0;
        std::istringstream s(o.view);
        if (!(s >> az >> comma >> el) || comma != ',' || !s.eof() || !(std::abs(el) <= 90.0f) ||
            !(std::abs(az) <= 360.0f))
            throw UsageError(fmt::format("view '{}' is not AZIMUTH,ELEVATION in degrees (e.g. 35,30)", o.view),
                             "--view");
        view.azimuth_deg = az;
        view.elevation_deg = el;
    }
    float exposure_ev = 0.0f;
    const bool auto_exposure = o.exposure == "auto";
    if (!auto_exposure)
        exposure_ev = parse_flag("--exposure", [&] {
            std::size_t used = 0;
            float x = 0.0f;
            try {
                x = std::stof(o.exposure, &used);
            } catch (const std::exception&) {
            }
            if (used != o.exposure.size() || !(std::abs(x) <= 64.0f))
                throw Error(fmt::format("exposure '{}' is not auto or stops in [-64, 64]", o.exposure), "--exposure");
            return x;
        });
    const bool sky = o.light == "sky", constant = o.light == "constant";
    if (!sky)
        for (const char* f :
             {"--sun-elevation-deg", "--sun-azimuth-deg", "--altitude-km", "--model", "--preset", "--atmosphere"})
            refuse_if_given(sub, f, "to --light " + o.light + " (only to --light sky)");
    if (!constant)
        refuse_if_given(sub, "--radiance", "to --light " + o.light + " (only to --light constant)");

    PrtModel model = load_prt(o.input);
    const int order = model.transfer.order;
    ShLight light;
    if (sky) {
        const bool neural = o.model.active();
        const SkySource source =
            neural ? SkySource::network(o.model.load(sub, o.atm)) : SkySource::reference(SkyModel(o.atm.load(sub)));
        SkyLightSettings s;
        s.sun_elevation_deg = o.elevation;
        s.sun_azimuth_deg = o.azimuth;
        s.altitude_km = o.altitude;
        light = sky_light(source, s, order, rule);
    } else if (constant) {
        light = constant_light(glm::vec3(float(o.radiance)), order);
    } else {
        const std::string le = lower_extension(o.light);
        if (le == ".json") {
            light = load_light(o.light);
        } else if (le == ".exr" || le == ".hdr") {
            Image map;
            try {
                map = load_image(o.light);
            } catch (const Error& e) {
                throw Error(e.message(), "light");
            }
            light = equirect_light(map, order, rule);
        } else {
            throw UsageError(fmt::format("light '{}' is not sky, constant, a light .json (`skybake sky sh`) or an "
                                         "equirectangular .exr or .hdr map",
                                         o.light),
                             "--light");
        }
    }
    std::vector<glm::vec3> normals;
    std::vector<float> visible;
    const bool sun = !o.no_sun && light.sun_irradiance != glm::vec3(0.0f);
    const auto t0 = std::chrono::steady_clock::now();
    if (sun) {
        if (model.mesh.normals.size() != model.mesh.vertex_count())
            compute_normals(model.mesh);
        normals = model.mesh.normals;
        const auto queries = make_ray_queries("embree");
        queries->set_mesh(model.mesh);
        visible = sun_visibility(model.mesh, light.sun_direction, *queries);
    }
    const std::vector<glm::vec3> radiance = relight(model.transfer, light, model.albedo, normals, visible);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    if (ext == ".ply") {
        Mesh& m = model.mesh;
        for (int c = 0; c < 3; ++c) {
            std::vector<float> v(m.vertex_count());
            for (std::size_t i = 0; i < v.size(); ++i)
                v[i] = radiance[i][c];
            m.set_attribute(std::string("radiance_") + "rgb"[c], 1, std::move(v));
        }
        save_mesh(o.output, m);
    } else {
        const Image img =
            render_prt_preview(model.mesh, model.transfer, radiance, light, o.glossy, float(o.specular), view);
        if (auto_exposure) {
            // From the model's radiance, not the background: its 95th
            // percentile luminance (Rec. 709) maps to 0.6.
            std::vector<float> lum;
            for (const glm::vec3& c : radiance)
                if (const float y = 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; y > 0.0f && std::isfinite(y))
                    lum.push_back(y);
            if (!lum.empty()) {
                const auto k = std::ptrdiff_t(0.95 * double(lum.size() - 1));
                std::nth_element(lum.begin(), lum.begin() + k, lum.end());
                exposure_ev = std::log2(0.6f / lum[std::size_t(k)]);
            }
        }
        save_image(o.output, img, ToneMap{exposure_ev, ToneCurve::Aces});
    }
    if (o.json) {
        print_json({{"input", o.input},
                    {"output", o.output},
                    {"light", o.light},
                    {"order", order},
                    {"vertices", radiance.size()},
                    {"sun", sun},
                    {"seconds", seconds},
                    {"exposure_ev", ext == ".ply" ? nlohmann::json(nullptr) : nlohmann::json(exposure_ev)}});
        return;
    }
    info("relit {} vertices (order {}, {}) with {}{} in {:.3f} s; wrote {}", radiance.size(), order,
         transfer_kind_name(model.transfer.kind), o.light, sun ? " and the sun" : "", seconds, o.output);
}

} // namespace

void add_prt_relight(CLI::App& group) {
    auto o = std::make_shared<RelightOpts>();
    auto* sub = group.add_subcommand("relight", "Light a baked transfer: per-vertex radiance (.ply) or an image");
    sub->add_option("input", o->input, "Mesh written by 'prt bake' (its .prt.json sidecar beside it)")->required();
    sub->add_option("-o,--output", o->output,
                    ".ply (per-vertex radiance_r/g/b) or .png/.exr (ray-cast image of the relit mesh)")
        ->required();
    sub->add_option("--light", o->light,
                    "sky (the sky model or --model network), constant, a light .json from 'sky sh', or an "
                    "equirectangular .exr/.hdr map")
        ->capture_default_str();
    o->atm.add(*sub);
    o->model.add(*sub);
    sub->add_option("--sun-elevation-deg", o->elevation, "Sun above the horizon, degrees (--light sky)")
        ->check(real_in(-90.0, 90.0, "degrees"))
        ->capture_default_str();
    sub->add_option("--sun-azimuth-deg", o->azimuth, "Sun azimuth, degrees: 0 towards +z, 90 towards +x")
        ->check(real_in(-360.0, 360.0, "degrees"))
        ->capture_default_str();
    sub->add_option("--altitude-km", o->altitude, "Observer above the ground, km (--light sky)")
        ->check(real_in(0.0, 1e6, "km"))
        ->capture_default_str();
    sub->add_option("--radiance", o->radiance, "Radiance of --light constant")
        ->check(real_in(0.0, 1e30, ""))
        ->capture_default_str();
    sub->add_flag("--no-sun", o->no_sun, "Leave out the sun as a direct light");
    sub->add_option("--glossy", o->glossy, "Phong exponent of a glossy layer (DPRT, image outputs; 0: diffuse only)")
        ->check(real_in(0.0, 10000.0, ""))
        ->capture_default_str();
    sub->add_option("--specular", o->specular, "Weight of the glossy layer (with --glossy)")
        ->check(real_in(0.0, 1.0, ""))
        ->capture_default_str();
    sub->add_option("--rule", o->rule, "Sphere rule of the light's projection")->capture_default_str();
    sub->add_option("--view", o->view, "Camera AZIMUTH,ELEVATION in degrees (image outputs)")->capture_default_str();
    sub->add_option("--size", o->size, "Image size WxH (image outputs)")->capture_default_str();
    sub->add_option("--exposure", o->exposure, "Exposure in stops, or auto (image outputs)")->capture_default_str();
    add_json_flag(*sub, o->json);
    sub->callback([o, sub] { run(*o, *sub); });
}

SKYBAKE_CLI_COMMAND("prt", add_prt_relight)

} // namespace skybake::cli
