// Atmosphere description: validation, presets and JSON files.
//
// Presets: Bruneton E. "Precomputed Atmospheric Scattering: a New
// Implementation", 2017 (demo defaults, also used by Hillaire S. "A Scalable
// and Production Ready Sky and Atmosphere Rendering Technique", EGSR 2020) for
// "earth"; Pietras & Rudnicki (seed 000) section VII for "paper".
#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "skybake/error.h"
#include "skybake/names.h"
#include "skybake/files.h"
#include "skybake/sky.h"
#include "sky/sky_hd.h"

namespace skybake {

namespace {

using nlohmann::json;

bool finite3(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

constexpr NamedValue<PhaseFunction> kPhaseNames[] = {
    {PhaseFunction::None, "none"},
    {PhaseFunction::Rayleigh, "rayleigh"},
    {PhaseFunction::HenyeyGreenstein, "henyey-greenstein"},
    {PhaseFunction::CornetteShanks, "cornette-shanks"},
    {PhaseFunction::PietrasRudnickiMie, "pietras-rudnicki-mie", nullptr, "seed-mie"},
};

const char* phase_name(PhaseFunction p) { return name_of(kPhaseNames, p); }

PhaseFunction parse_phase(const std::string& s, const std::string& where) {
    return parse_name(kPhaseNames, s, "phase function", where);
}

} // namespace

const char* phase_function_name(PhaseFunction phase) { return phase_name(phase); }
PhaseFunction parse_phase_function(const std::string& text, const std::string& where) {
    return parse_phase(text, where);
}

namespace {
constexpr NamedValue<TableRule> kTableRuleNames[] = {
    {TableRule::AsPublished, "as-published", "the paper's density at the shell boundary", "seed"},
    {TableRule::Refined, "refined", "sub-shells weighted by their mean density"},
};
} // namespace

const char* table_rule_name(TableRule rule) { return name_of(kTableRuleNames, rule); }

namespace {
constexpr NamedValue<Scattering> kScatteringNames[] = {
    {Scattering::Single, "single", "light scattered once (seed 000)"},
    {Scattering::Multiple, "multiple", "every order, ground bounces included"},
};
constexpr NamedValue<MultipleScatteringMethod> kMultipleMethodNames[] = {
    {MultipleScatteringMethod::Orders, "orders", "Bruneton 2017's precomputed scattering orders"},
    {MultipleScatteringMethod::Hillaire, "hillaire", "Hillaire 2020's isotropic multiple-scattering table"},
};
} // namespace

const char* scattering_name(Scattering scattering) { return name_of(kScatteringNames, scattering); }
const char* multiple_scattering_method_name(MultipleScatteringMethod method) {
    return name_of(kMultipleMethodNames, method);
}
Scattering parse_scattering(const std::string& text, const std::string& where) {
    return parse_name(kScatteringNames, text, "scattering", where);
}
MultipleScatteringMethod parse_multiple_scattering_method(const std::string& text, const std::string& where) {
    return parse_name(kMultipleMethodNames, text, "multiple-scattering method", where);
}

TableRule parse_table_rule(const std::string& text, const std::string& where) {
    return parse_name(kTableRuleNames, text, "table rule", where);
}

namespace {

constexpr NamedValue<DensityProfile> kProfileNames[] = {
    {DensityProfile::Exponential, "exponential"},
    {DensityProfile::Tent, "tent"},
    {DensityProfile::Constant, "constant"},
};

const char* profile_name(DensityProfile p) { return name_of(kProfileNames, p); }

DensityProfile parse_profile(const std::string& s, const std::string& where) {
    return parse_name(kProfileNames, s, "density profile", where);
}

json vec_json(const glm::dvec3& v) { return json::array({v.x, v.y, v.z}); }

// Reads a field with a type check; `where` names the file and the field.
template <class T>
T get(const json& j, const char* key, const std::string& where, const T* fallback = nullptr) {
    if (!j.contains(key)) {
        if (fallback)
            return *fallback;
        throw Error(fmt::format("missing field '{}'", key), where);
    }
    try {
        return j.at(key).get<T>();
    } catch (const json::exception&) {
        throw Error(fmt::format("field '{}' has the wrong type", key), where);
    }
}

glm::dvec3 get_vec(const json& j, const char* key, const std::string& where, const glm::dvec3* fallback = nullptr) {
    if (!j.contains(key)) {
        if (fallback)
            return *fallback;
        throw Error(fmt::format("missing field '{}'", key), where);
    }
    const json& v = j.at(key);
    if (v.is_number()) {
        const double x = v.get<double>();
        return glm::dvec3(x);
    }
    if (!v.is_array() || v.size() != 3 || !v[0].is_number() || !v[1].is_number() || !v[2].is_number())
        throw Error(fmt::format("field '{}' must be a number or an array of 3 numbers (R, G, B)", key), where);
    return {v[0].get<double>(), v[1].get<double>(), v[2].get<double>()};
}

AtmosphereComponent exponential(std::string name, double scale_height_km, glm::dvec3 sca, glm::dvec3 ext,
                                PhaseFunction phase, double g) {
    AtmosphereComponent c;
    c.name = std::move(name);
    c.profile = DensityProfile::Exponential;
    c.scale_height_km = scale_height_km;
    c.scattering_per_km = sca;
    c.extinction_per_km = ext;
    c.phase = phase;
    c.phase_g = g;
    return c;
}

} // namespace

// ---- validation ---------------------------------------------------------------------

void Atmosphere::validate() const {
    const std::string where = name.empty() ? std::string("atmosphere") : fmt::format("atmosphere '{}'", name);
    if (!(std::isfinite(planet_radius_km) && planet_radius_km > 0.0))
        throw Error("planet_radius_km must be a positive number of km", where);
    if (!(std::isfinite(top_radius_km) && top_radius_km > planet_radius_km))
        throw Error("top_radius_km must be larger than planet_radius_km", where);
    if (components.empty() || components.size() > std::size_t(sky::kMaxComponents))
        throw Error(fmt::format("an atmosphere needs 1 to {} components, got {}", sky::kMaxComponents,
                                components.size()),
                    where);
    if (components[0].profile != DensityProfile::Exponential)
        throw Error("the first component must have an exponential profile: its density is the observer coordinate",
                    where);
    for (std::size_t i = 0; i < components.size(); ++i) {
        const AtmosphereComponent& c = components[i];
        const std::string w = fmt::format("{}, component {} ('{}')", where, i, c.name);
        if (c.profile == DensityProfile::Exponential && !(std::isfinite(c.scale_height_km) && c.scale_height_km > 0))
            throw Error("scale_height_km must be positive", w);
        if (c.profile == DensityProfile::Tent &&
            !(std::isfinite(c.tent_center_km) && std::isfinite(c.tent_half_width_km) && c.tent_half_width_km > 0))
            throw Error("a tent profile needs a finite center_km and a positive half_width_km", w);
        if (!finite3(c.scattering_per_km) || !finite3(c.extinction_per_km) || c.scattering_per_km.x < 0 ||
            c.scattering_per_km.y < 0 || c.scattering_per_km.z < 0)
            throw Error("scattering_per_km must be finite and non-negative", w);
        const glm::dvec3 absorption = c.extinction_per_km - c.scattering_per_km;
        const double slack = 1e-12;
        if (absorption.x < -slack || absorption.y < -slack || absorption.z < -slack)
            throw Error("extinction_per_km must be at least scattering_per_km in every channel", w);
        if (c.phase == PhaseFunction::None && (c.scattering_per_km != glm::dvec3(0.0)))
            throw Error("a component that scatters needs a phase function", w);
        if ((c.phase == PhaseFunction::HenyeyGreenstein || c.phase == PhaseFunction::CornetteShanks ||
             c.phase == PhaseFunction::PietrasRudnickiMie) &&
            !(std::isfinite(c.phase_g) && std::abs(c.phase_g) < 1.0))
            throw Error("phase g must be in (-1, 1)", w);
    }
    if (!finite3(sun_irradiance) || sun_irradiance.x < 0 || sun_irradiance.y < 0 || sun_irradiance.z < 0)
        throw Error("sun irradiance must be finite and non-negative", where);
    if (!(std::isfinite(sun_angular_radius_rad) && sun_angular_radius_rad > 0 && sun_angular_radius_rad < 0.5))
        throw Error("sun angular_radius_rad must be in (0, 0.5)", where);
    if (!(std::isfinite(sun_elevation_deg) && std::isfinite(sun_azimuth_deg)))
        throw Error("sun elevation and azimuth must be finite", where);
    for (int i = 0; i < 3; ++i)
        if (!(ground_albedo[i] >= 0.0 && ground_albedo[i] <= 1.0))
            throw Error("ground_albedo must be in [0, 1]", where);
    if (scattering != Scattering::Single && scattering != Scattering::Multiple)
        throw Error("scattering must be single or multiple", where);
    if (multiple_method != MultipleScatteringMethod::Orders && multiple_method != MultipleScatteringMethod::Hillaire)
        throw Error("multiple_method must be orders or hillaire", where);
    if (scattering_orders < 2 || scattering_orders > 32)
        throw Error("scattering_orders must be 2 to 32", where);
}

double Atmosphere::altitude_from_density(double rho) const {
    return -components.at(0).scale_height_km * std::log(rho);
}

double Atmosphere::density_from_altitude(double altitude_km) const {
    return std::exp(-altitude_km / components.at(0).scale_height_km);
}

// ---- presets ------------------------------------------------------------------------------

std::vector<std::string> atmosphere_preset_names() { return {"earth", "paper", "paper-dense"}; }

Atmosphere atmosphere_preset(std::string_view name, double paper_r, double paper_m) {
    Atmosphere a;
    if (name == "earth") {
        // Bruneton 2017 demo: Rayleigh β = 1.24062e-6 λ[µm]^-4 per metre at
        // 680/550/440 nm; Mie 4.44e-6 (ext) and 3.996e-6 (sca) per metre;
        // ozone tent 10–40 km. Converted to per km.
        a.name = "earth";
        a.planet_radius_km = 6360.0;
        a.top_radius_km = 6420.0;
        const glm::dvec3 rayleigh(5.802e-3, 13.558e-3, 33.100e-3);
        a.components.push_back(exponential("rayleigh", 8.0, rayleigh, rayleigh, PhaseFunction::Rayleigh, 0.0));
        a.components.push_back(exponential("mie", 1.2, glm::dvec3(3.996e-3), glm::dvec3(4.44e-3),
                                           PhaseFunction::CornetteShanks, 0.8));
        AtmosphereComponent ozone;
        ozone.name = "ozone";
        ozone.profile = DensityProfile::Tent;
        ozone.tent_center_km = 25.0;
        ozone.tent_half_width_km = 15.0;
        ozone.scattering_per_km = glm::dvec3(0.0);
        ozone.extinction_per_km = glm::dvec3(0.650e-3, 1.881e-3, 0.085e-3);
        ozone.phase = PhaseFunction::None;
        a.components.push_back(ozone);
        a.sun_angular_radius_rad = 0.004675;
        a.ground_albedo = glm::dvec3(0.1);
        a.sun_elevation_deg = 30.0;
        return a;
    }
    if (name == "paper" || name == "paper-dense") {
        if (name == "paper-dense")
            paper_r = paper_m = 100.0;
        if (!(std::isfinite(paper_r) && paper_r > 0 && std::isfinite(paper_m) && paper_m > 0))
            throw Error("the paper preset's r and m must be positive", "paper_r/paper_m");
        a.name = name == "paper" ? fmt::format("paper r={:g} m={:g}", paper_r, paper_m) : std::string(name);
        a.planet_radius_km = 6371.0;
        a.top_radius_km = 6471.0;
        // Seed 000 section VII, as printed: b = [(475/700)^4, (546/700)^4, 1]/r
        // (R, G, B) and (475/700)^4 / m in every channel.
        const double q475 = std::pow(475.0 / 700.0, 4.0), q546 = std::pow(546.0 / 700.0, 4.0);
        const glm::dvec3 br = glm::dvec3(q475, q546, 1.0) / paper_r;
        const glm::dvec3 bm = glm::dvec3(q475) / paper_m;
        a.components.push_back(exponential("rayleigh", 8.3, br, br, PhaseFunction::Rayleigh, 0.0));
        a.components.push_back(exponential("mie", 1.6, bm, bm, PhaseFunction::PietrasRudnickiMie, 0.76));
        a.ground_albedo = glm::dvec3(0.5); // the seed's grey surface, C = 0.5
        a.sun_elevation_deg = 30.0;
        return a;
    }
    throw Error(fmt::format("unknown atmosphere preset '{}'; use earth, paper or paper-dense", name), "preset");
}

// ---- JSON ------------------------------------------------------------------------------------

std::string atmosphere_to_json(const Atmosphere& a) {
    json j;
    j["name"] = a.name;
    j["length_unit"] = "km";
    j["planet_radius_km"] = a.planet_radius_km;
    j["top_radius_km"] = a.top_radius_km;
    j["table_rule"] = table_rule_name(a.table_rule);
    json comps = json::array();
    for (const AtmosphereComponent& c : a.components) {
        json cj;
        cj["name"] = c.name;
        json prof;
        prof["type"] = profile_name(c.profile);
        if (c.profile == DensityProfile::Exponential)
            prof["scale_height_km"] = c.scale_height_km;
        if (c.profile == DensityProfile::Tent) {
            prof["center_km"] = c.tent_center_km;
            prof["half_width_km"] = c.tent_half_width_km;
        }
        cj["profile"] = prof;
        cj["scattering_per_km"] = vec_json(c.scattering_per_km);
        cj["extinction_per_km"] = vec_json(c.extinction_per_km);
        json ph;
        ph["type"] = phase_name(c.phase);
        if (c.phase == PhaseFunction::HenyeyGreenstein || c.phase == PhaseFunction::CornetteShanks ||
            c.phase == PhaseFunction::PietrasRudnickiMie)
            ph["g"] = c.phase_g;
        cj["phase"] = ph;
        comps.push_back(cj);
    }
    j["components"] = comps;
    j["sun"] = {{"elevation_deg", a.sun_elevation_deg},
                {"azimuth_deg", a.sun_azimuth_deg},
                {"irradiance", vec_json(a.sun_irradiance)},
                {"angular_radius_rad", a.sun_angular_radius_rad}};
    j["ground_albedo"] = vec_json(a.ground_albedo);
    if (a.scattering != Scattering::Single) {
        j["scattering"] = scattering_name(a.scattering);
        j["multiple_method"] = multiple_scattering_method_name(a.multiple_method);
        j["scattering_orders"] = a.scattering_orders;
    }
    return j.dump(2) + "\n";
}

Atmosphere atmosphere_from_json(std::string_view text, const std::string& where) {
    json j;
    try {
        j = json::parse(text.begin(), text.end());
    } catch (const json::exception& e) { // parse_error, and out_of_range for a number such as 1e3080
        throw Error(fmt::format("not valid JSON: {}", e.what()), where);
    }
    if (!j.is_object())
        throw Error("an atmosphere must be a JSON object", where);
    Atmosphere a;
    const std::string empty;
    a.name = get<std::string>(j, "name", where, &empty);
    if (j.contains("length_unit") && !(j["length_unit"].is_string() && j["length_unit"] == "km"))
        throw Error("length_unit must be \"km\"", where);
    a.planet_radius_km = get<double>(j, "planet_radius_km", where);
    a.top_radius_km = get<double>(j, "top_radius_km", where);
    const std::string published = table_rule_name(TableRule::AsPublished);
    a.table_rule = parse_table_rule(get<std::string>(j, "table_rule", where, &published), where);
    if (!j.contains("components") || !j["components"].is_array())
        throw Error("missing array 'components'", where);
    for (std::size_t i = 0; i < j["components"].size(); ++i) {
        const json& cj = j["components"][i];
        const std::string w = fmt::format("{}, components[{}]", where, i);
        if (!cj.is_object())
            throw Error("a component must be an object", w);
        AtmosphereComponent c;
        c.name = get<std::string>(cj, "name", w, &empty);
        if (!cj.contains("profile") || !cj["profile"].is_object())
            throw Error("missing object 'profile'", w);
        const json& pj = cj["profile"];
        c.profile = parse_profile(get<std::string>(pj, "type", w), w);
        if (c.profile == DensityProfile::Exponential)
            c.scale_height_km = get<double>(pj, "scale_height_km", w);
        if (c.profile == DensityProfile::Tent) {
            c.tent_center_km = get<double>(pj, "center_km", w);
            c.tent_half_width_km = get<double>(pj, "half_width_km", w);
        }
        c.scattering_per_km = get_vec(cj, "scattering_per_km", w);
        c.extinction_per_km = get_vec(cj, "extinction_per_km", w, &c.scattering_per_km);
        if (!cj.contains("phase") || !cj["phase"].is_object())
            throw Error("missing object 'phase'", w);
        const json& phj = cj["phase"];
        c.phase = parse_phase(get<std::string>(phj, "type", w), w);
        const double zero = 0.0;
        c.phase_g = get<double>(phj, "g", w, &zero);
        a.components.push_back(c);
    }
    if (j.contains("sun")) {
        const json& sj = j["sun"];
        if (!sj.is_object())
            throw Error("'sun' must be an object", where);
        a.sun_elevation_deg = get<double>(sj, "elevation_deg", where, &a.sun_elevation_deg);
        a.sun_azimuth_deg = get<double>(sj, "azimuth_deg", where, &a.sun_azimuth_deg);
        a.sun_irradiance = get_vec(sj, "irradiance", where, &a.sun_irradiance);
        a.sun_angular_radius_rad = get<double>(sj, "angular_radius_rad", where, &a.sun_angular_radius_rad);
    }
    a.ground_albedo = get_vec(j, "ground_albedo", where, &a.ground_albedo);
    const std::string single = scattering_name(Scattering::Single);
    const std::string orders = multiple_scattering_method_name(MultipleScatteringMethod::Orders);
    a.scattering = parse_scattering(get<std::string>(j, "scattering", where, &single), where);
    a.multiple_method = parse_multiple_scattering_method(get<std::string>(j, "multiple_method", where, &orders), where);
    a.scattering_orders = get<int>(j, "scattering_orders", where, &a.scattering_orders);
    try {
        a.validate();
    } catch (const Error& e) {
        throw Error(e.message(), where);
    }
    return a;
}

Atmosphere load_atmosphere(const std::filesystem::path& path) {
    const std::string text = read_file(path, std::uint64_t(1) << 24);
    return atmosphere_from_json(text, path.string());
}

void save_atmosphere(const std::filesystem::path& path, const Atmosphere& atmosphere) {
    atmosphere.validate();
    const std::string text = atmosphere_to_json(atmosphere);
    write_stream_atomic(path, [&](std::ostream& out) { out << text; });
}

// ---- phase functions and profiles -------------------------------------------------------

double phase_function(PhaseFunction phase, double g, double mu) {
    constexpr double pi = 3.14159265358979323846;
    switch (phase) {
    case PhaseFunction::None:
        return 0.0;
    case PhaseFunction::Rayleigh:
        return 3.0 / (16.0 * pi) * (1.0 + mu * mu);
    case PhaseFunction::HenyeyGreenstein: {
        const double d = 1.0 + g * g - 2.0 * g * mu;
        return (1.0 - g * g) / (4.0 * pi * d * std::sqrt(d));
    }
    case PhaseFunction::CornetteShanks: {
        const double d = 1.0 + g * g - 2.0 * g * mu;
        return 3.0 * (1.0 - g * g) * (1.0 + mu * mu) / (8.0 * pi * (2.0 + g * g) * d * std::sqrt(d));
    }
    case PhaseFunction::PietrasRudnickiMie: {
        const double d = 1.0 + g * g - 2.0 * g * mu;
        return (1.0 - g * g) / (16.0 * pi * d * std::sqrt(d));
    }
    }
    return 0.0;
}

double relative_density(const AtmosphereComponent& c, double h) {
    switch (c.profile) {
    case DensityProfile::Exponential:
        return std::exp(-h / c.scale_height_km);
    case DensityProfile::Tent:
        return std::max(0.0, 1.0 - std::abs(h - c.tent_center_km) / c.tent_half_width_km);
    case DensityProfile::Constant:
        return 1.0;
    }
    return 0.0;
}

} // namespace skybake
