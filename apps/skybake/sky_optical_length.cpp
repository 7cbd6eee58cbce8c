// skybake sky optical-length: the seed's relative optical length t(ρ, α) = ∫ρ ds.
#include <cmath>

#include "commands.h"
#include "flags.h"
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
    sub->add_option("--density", o->density, "Relative density of the first component at the point")
        ->check(real_in(0.0, 1.0, "", End::Open))
        ->required();
    sub->add_option("--cos-zenith", o->cos_zenith, "Cosine of the ray's angle to the local vertical")
        ->check(real_in(-1.0, 1.0, ""))
        ->required();
    sub->add_option("--component", o->component, "Component index")->check(integer_in(0, 3))->capture_default_str();
    sub->add_option("--method", o->method, "tables (the seed's tables) or exact (quadrature)")->capture_default_str();
    sub->add_option("--shells", o->shells, "Table rows n (density steps)")
        ->check(integer_in(2, 16384))
        ->capture_default_str();
    sub->add_option("--cosines", o->cosines, "Table columns m (cosine steps)")
        ->check(integer_in(2, 16384))
        ->capture_default_str();
    add_json_flag(*sub, o->json);
    sub->callback([o, sub] {
        const Atmosphere a = o->atm.load(*sub);
        a.validate();
        if (o->component >= int(a.components.size()))
            throw UsageError(fmt::format("component {} does not exist: the atmosphere has {} components (0 to {})",
                                         o->component, a.components.size(), a.components.size() - 1),
                             "--component");
        const SkyMethod method = parse_sky_method(o->method);
        if (method == SkyMethod::Exact)
            for (const char* f : {"--shells", "--cosines"})
                refuse_if_given(*sub, f, "to --method exact");
        const double h = a.altitude_from_density(o->density) + 0.0; // no "-0"
        // Whether the ray meets the ground is geometry, the same for both
        // methods: r sin α < R0 on a downward ray. The tables only hold rays
        // that reach the top (the seed's symmetry trick would give a length
        // for a ray through the planet).
        const double r = a.planet_radius_km + h, mu = o->cos_zenith;
        const bool hits_ground = mu < 0.0 && r * r * (1.0 - mu * mu) < a.planet_radius_km * a.planet_radius_km;
        double t = INFINITY;
        if (method == SkyMethod::Exact)
            t = optical_length_exact(a, o->component, h, o->cos_zenith);
        else if (!hits_ground)
            t = OpticalLengthTables::build(a, {o->shells, o->cosines}).optical_length(o->component, h, o->cos_zenith);
        if (hits_ground)
            t = INFINITY;
        if (o->json) {
            print_json({{"atmosphere", a.name},
                        {"component", a.components[std::size_t(o->component)].name},
                        {"density", o->density},
                        {"altitude_km", h},
                        {"cos_zenith", o->cos_zenith},
                        {"method", o->method},
                        {"hits_ground", hits_ground},
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
