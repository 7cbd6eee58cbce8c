// skybake sky optical-length: the seed's relative optical length t(ρ, α) = ∫ρ ds.
#include <cmath>

#include "commands.h"
#include "sky_common.h"

namespace skybake::cli {

void add_sky_optical_length(CLI::App& group) {
    auto* sub = group.add_subcommand(
        "optical-length", "Print the relative optical length t(rho, alpha) = integral of rho ds, in km");
    struct Opts {
        AtmosphereFlags atm;
        double density = 1.0, cos_zenith = 1.0;
        int component = 0, shells = 256, cosines = 128;
        std::string method = "tables";
        bool json = false;
    };
    auto o = std::make_shared<Opts>();
    o->atm.add(*sub);
    sub->add_option("--density", o->density, "Relative density of the first component at the point, in (0, 1]")
        ->required();
    sub->add_option("--cos-zenith", o->cos_zenith, "Cosine of the ray's angle to the local vertical, [-1, 1]")
        ->required();
    sub->add_option("--component", o->component, "Component index (default 0)");
    sub->add_option("--method", o->method, "tables (the seed's tables) or exact (quadrature)");
    sub->add_option("--shells", o->shells, "Table rows n (density steps), default 256");
    sub->add_option("--cosines", o->cosines, "Table columns m (cosine steps), default 128");
    add_json_flag(*sub, o->json);
    sub->callback([o] {
        const Atmosphere a = o->atm.load();
        a.validate();
        if (!(std::isfinite(o->density) && o->density > 0.0 && o->density <= 1.0))
            throw Error("density must be in (0, 1]", "--density");
        if (!(std::isfinite(o->cos_zenith) && std::abs(o->cos_zenith) <= 1.0))
            throw Error("the cosine must be in [-1, 1]", "--cos-zenith");
        if (o->component < 0 || o->component >= int(a.components.size()))
            throw Error("component index out of range: the atmosphere has " + std::to_string(a.components.size()) +
                            " components",
                        "--component");
        if (o->shells < 2 || o->cosines < 2 || o->shells > 16384 || o->cosines > 16384)
            throw Error("table resolution must be 2 to 16384", "--shells/--cosines");
        const SkyMethod method = parse_sky_method(o->method);
        const double h = a.altitude_from_density(o->density) + 0.0; // no "-0"
        double t;
        if (method == SkyMethod::Exact)
            t = optical_length_exact(a, o->component, h, o->cos_zenith);
        else
            t = OpticalLengthTables::build(a, {o->shells, o->cosines}).optical_length(o->component, h, o->cos_zenith);
        if (o->json) {
            print_json({{"atmosphere", a.name},
                        {"component", a.components[std::size_t(o->component)].name},
                        {"density", o->density},
                        {"altitude_km", h},
                        {"cos_zenith", o->cos_zenith},
                        {"method", o->method},
                        {"hits_ground", std::isinf(t)},
                        {"optical_length_km", std::isinf(t) ? nlohmann::json(nullptr) : nlohmann::json(t)}});
            return;
        }
        info("{} / {}: altitude {:.6g} km, cos zenith {:.6g}{}", a.name, a.components[std::size_t(o->component)].name, h,
             o->cos_zenith, std::isinf(t) ? " (the ray meets the ground)" : "");
        fmt::print("{}\n", std::isinf(t) ? std::string("inf") : fmt::format("{:.9g}", t));
    });
}

SKYBAKE_CLI_COMMAND("sky", add_sky_optical_length)

} // namespace skybake::cli
