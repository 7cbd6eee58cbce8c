// Shared flags of the sky sub-commands: choosing an atmosphere and a method.
#pragma once

#include <string>

#include "cli.h"
#include "flags.h"
#include "skybake/neural.h"
#include "skybake/sky.h"

namespace skybake::cli {

struct AtmosphereFlags {
    std::string preset;
    std::string file;
    double paper_r = 10000.0, paper_m = 10000.0;
    std::string table_rule; // empty: the atmosphere's own
    std::string scattering, multiple_method; // empty: the atmosphere's own
    int scattering_orders = 0;               // 0: the atmosphere's own

    void add(CLI::App& sub, bool allow_file = true) {
        sub.add_option("--preset", preset, "Atmosphere preset: earth (default), paper, paper-dense");
        if (allow_file)
            sub.add_option("--atmosphere", file, "Atmosphere JSON file (see `skybake sky preset`)");
        sub.add_option("--paper-r", paper_r, "Seed's Rayleigh divisor r, for --preset paper only")
            ->check(real_in(0.0, 1e12, "", End::Open))
            ->capture_default_str();
        sub.add_option("--paper-m", paper_m, "Seed's Mie divisor m, for --preset paper only")
            ->check(real_in(0.0, 1e12, "", End::Open))
            ->capture_default_str();
        sub.add_option("--table-rule", table_rule,
                       "Shell density rule of the tables: as-published (or seed) or refined (default: the atmosphere's own)");
        sub.add_option("--scattering", scattering,
                       "single (seed 000) or multiple (every order, ground bounces included; its tables take seconds once, then "
                       "come from the cache in $SKYBAKE_CACHE_DIR, else $XDG_CACHE_HOME/skybake or ~/.cache/skybake; "
                       "SKYBAKE_CACHE_DIR=off disables it); default: the atmosphere's own, single for the presets");
        sub.add_option("--multiple-method", multiple_method,
                       "With --scattering multiple: orders (Bruneton 2017's precomputed orders, default) or hillaire (Hillaire 2020's table, faster)");
        sub.add_option("--scattering-orders", scattering_orders,
                       "With --multiple-method orders: the highest scattering order counted, 2 to 32 (default 4)")
            ->check(integer_in(2, 32));
    }

    Atmosphere load(const CLI::App& sub) const {
        if (!preset.empty() && !file.empty())
            throw UsageError("give either --preset or --atmosphere, not both", "--preset/--atmosphere");
        if (preset != "paper")
            for (const char* f : {"--paper-r", "--paper-m"})
                refuse_if_given(sub, f, "to " + (file.empty() ? "preset " + (preset.empty() ? std::string("earth") : preset)
                                                            : std::string("an atmosphere file")) +
                                            " (only to --preset paper)");
        Atmosphere a = file.empty() ? parse_flag("--preset", [&] {
            return atmosphere_preset(preset.empty() ? "earth" : preset, paper_r, paper_m);
        })
                                    : load_atmosphere(file);
        if (!table_rule.empty())
            a.table_rule = parse_flag("--table-rule", [&] { return parse_table_rule(table_rule); });
        if (!scattering.empty())
            a.scattering = parse_flag("--scattering", [&] { return parse_scattering(scattering); });
        if (!multiple_method.empty())
            a.multiple_method =
                parse_flag("--multiple-method", [&] { return parse_multiple_scattering_method(multiple_method); });
        if (scattering_orders != 0)
            a.scattering_orders = scattering_orders;
        if (a.scattering == Scattering::Single)
            for (const char* f : {"--multiple-method", "--scattering-orders"})
                refuse_if_given(sub, f, "to single scattering (add --scattering multiple)");
        if (a.multiple_method != MultipleScatteringMethod::Orders)
            refuse_if_given(sub, "--scattering-orders", "to --multiple-method hillaire (it sums every order)");
        return a;
    }
};

// --model weights.json: a trained neural sky in place of the sky model. The
// weights file carries its atmosphere, so --preset/--atmosphere/--method and
// the table flags do not apply.
struct ModelFlag {
    std::string path;
    double aerosol = 1.0;

    void add(CLI::App& sub) {
        sub.add_option("--model", path, "Use a trained neural sky (weights JSON from `skybake sky train`)");
        add_aerosol(sub);
    }
    void add_aerosol(CLI::App& sub) {
        sub.add_option("--aerosol", aerosol,
                       "With --model of an aerosol family (sky train --aerosol-range): the aerosol amount, a "
                       "multiple of its atmosphere's")
            ->capture_default_str();
    }
    // The weights file at `path` with --aerosol applied (a usage error outside the family).
    NeuralSky load_weights() const {
        NeuralSky net = load_neural_sky(path);
        net.aerosol = aerosol;
        parse_flag("--aerosol", [&] { net.validate("aerosol"); return 0; });
        return net;
    }
    bool active() const { return !path.empty(); }
    NeuralSky load(const CLI::App& sub, const AtmosphereFlags& atm) const {
        if (!atm.preset.empty() || !atm.file.empty())
            throw UsageError("a weights file carries its own atmosphere; drop --preset/--atmosphere", "--model");
        for (const char* flag : {"--method", "--table-rule", "--steps", "--uniform-steps", "--shells", "--cosines",
                                 "--paper-r", "--paper-m", "--scattering", "--multiple-method", "--scattering-orders"})
            refuse_if_given(sub, flag, "to a neural sky (--model)");
        return load_weights();
    }
};

inline SkyMethod parse_sky_method(const std::string& s) {
    if (s == "tables")
        return SkyMethod::Tables;
    if (s == "exact")
        return SkyMethod::Exact;
    throw UsageError("unknown method '" + s + "'; use tables or exact", "--method");
}

} // namespace skybake::cli
