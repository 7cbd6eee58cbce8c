// Atmosphere::validate: every field it checks gives its own message, naming
// the atmosphere and, for a component's field, the component.
#include <cmath>
#include <functional>
#include <limits>

#include <gtest/gtest.h>

#include "skybake/error.h"
#include "skybake/sky.h"

using namespace skybake;

namespace {

struct Case {
    const char* what;
    std::function<void(Atmosphere&)> spoil;
    const char* message; // a part of the message
    const char* where;   // a part of where()
};

const double kNan = std::numeric_limits<double>::quiet_NaN();
const double kInf = std::numeric_limits<double>::infinity();

} // namespace

TEST(AtmosphereValidate, EachFieldHasItsOwnMessage) {
    const Case cases[] = {
        {"radius 0", [](Atmosphere& a) { a.planet_radius_km = 0; }, "planet_radius_km must be a positive",
         "atmosphere 'earth'"},
        {"radius NaN", [](Atmosphere& a) { a.planet_radius_km = kNan; }, "planet_radius_km", "atmosphere 'earth'"},
        {"top below", [](Atmosphere& a) { a.top_radius_km = a.planet_radius_km; }, "top_radius_km must be larger",
         "earth"},
        {"top inf", [](Atmosphere& a) { a.top_radius_km = kInf; }, "top_radius_km", "earth"},
        {"no components", [](Atmosphere& a) { a.components.clear(); }, "needs 1 to 4 components, got 0", "earth"},
        {"five components", [](Atmosphere& a) { a.components.resize(5, a.components[0]); }, "got 5", "earth"},
        {"first not exponential", [](Atmosphere& a) { a.components[0].profile = DensityProfile::Tent; },
         "first component must have an exponential profile", "earth"},
        {"scale height", [](Atmosphere& a) { a.components[1].scale_height_km = -1; },
         "scale_height_km must be positive", "component 1 ('mie')"},
        {"tent width", [](Atmosphere& a) { a.components[2].tent_half_width_km = 0; }, "positive half_width_km",
         "component 2 ('ozone')"},
        {"tent centre", [](Atmosphere& a) { a.components[2].tent_center_km = kNan; }, "finite center_km",
         "component 2 ('ozone')"},
        {"negative scattering", [](Atmosphere& a) { a.components[0].scattering_per_km.y = -1e-3; },
         "scattering_per_km must be finite and non-negative", "component 0 ('rayleigh')"},
        {"NaN extinction", [](Atmosphere& a) { a.components[1].extinction_per_km.z = kNan; }, "finite and non-negative",
         "component 1 ('mie')"},
        {"extinction below scattering", [](Atmosphere& a) { a.components[1].extinction_per_km.x = 0.001; },
         "extinction_per_km must be at least scattering_per_km", "component 1 ('mie')"},
        {"scatters without phase", [](Atmosphere& a) { a.components[1].phase = PhaseFunction::None; },
         "needs a phase function", "component 1 ('mie')"},
        {"g = 1", [](Atmosphere& a) { a.components[1].phase_g = 1.0; }, "phase g must be in (-1, 1)",
         "component 1 ('mie')"},
        {"g NaN", [](Atmosphere& a) { a.components[1].phase_g = kNan; }, "phase g", "component 1 ('mie')"},
        {"negative sun", [](Atmosphere& a) { a.sun_irradiance.x = -1; }, "sun irradiance must be finite", "earth"},
        {"sun radius", [](Atmosphere& a) { a.sun_angular_radius_rad = 0.5; }, "angular_radius_rad must be in (0, 0.5)",
         "earth"},
        {"sun elevation", [](Atmosphere& a) { a.sun_elevation_deg = kInf; }, "elevation and azimuth must be finite",
         "earth"},
        {"albedo", [](Atmosphere& a) { a.ground_albedo.z = 1.5; }, "ground_albedo must be in [0, 1]", "earth"},
        {"albedo NaN", [](Atmosphere& a) { a.ground_albedo.x = kNan; }, "ground_albedo", "earth"},
    };
    EXPECT_NO_THROW(atmosphere_preset("earth").validate());
    for (const Case& c : cases) {
        Atmosphere a = atmosphere_preset("earth");
        c.spoil(a);
        try {
            a.validate();
            ADD_FAILURE() << c.what << ": no error";
        } catch (const Error& e) {
            EXPECT_NE(e.message().find(c.message), std::string::npos) << c.what << ": " << e.what();
            EXPECT_NE(e.where().find(c.where), std::string::npos) << c.what << ": " << e.where();
        }
    }
}

TEST(AtmosphereValidate, JsonFieldsAreCheckedToo) {
    // A spoilt field in a file is the same error as in code, via atmosphere_from_json.
    Atmosphere a = atmosphere_preset("earth");
    a.components[1].phase_g = 1.5;
    const std::string text = atmosphere_to_json(a);
    try {
        atmosphere_from_json(text, "my.json");
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("phase g must be in (-1, 1)"), std::string::npos) << e.what();
    }
}

TEST(AtmosphereValidate, ANumberBeyondDoubleIsAnErrorNotACrash) {
    // Found by the fuzzer: nlohmann::json throws out_of_range, not parse_error,
    // for 1e30885; it escaped as an unknown exception.
    std::string text = atmosphere_to_json(atmosphere_preset("earth"));
    text.replace(text.find("0.005802"), 8, "0.0021e30885");
    try {
        atmosphere_from_json(text, "big.json");
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("not valid JSON"), std::string::npos) << e.what();
        EXPECT_EQ(e.where(), "big.json");
    }
}

TEST(AtmosphereNames, PublishedVariantsHaveTheirNamesAndTheOlderSpellingsStillLoad) {
    Atmosphere a = atmosphere_preset("earth");
    a.components[1].phase = PhaseFunction::PietrasRudnickiMie;
    a.components[1].phase_g = 0.7;
    a.table_rule = TableRule::AsPublished;
    const std::string text = atmosphere_to_json(a);
    EXPECT_NE(text.find("\"pietras-rudnicki-mie\""), std::string::npos) << text;
    EXPECT_NE(text.find("\"as-published\""), std::string::npos) << text;
    // A file written before the rename: the same atmosphere.
    std::string old = text;
    old.replace(old.find("\"pietras-rudnicki-mie\""), 22, "\"seed-mie\"");
    old.replace(old.find("\"as-published\""), 14, "\"seed\"");
    const Atmosphere b = atmosphere_from_json(old, "old.json");
    EXPECT_EQ(b.components[1].phase, PhaseFunction::PietrasRudnickiMie);
    EXPECT_EQ(b.table_rule, TableRule::AsPublished);
    EXPECT_EQ(parse_table_rule("refined"), TableRule::Refined);
    try {
        parse_table_rule("coarse", "--table-rule");
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_EQ(e.where(), "--table-rule");
        EXPECT_NE(e.message().find("as-published"), std::string::npos) << e.message();
    }
}
