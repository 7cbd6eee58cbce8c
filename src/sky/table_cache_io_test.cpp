// The on-disk cache of the multiple-scattering tables: cached tables are the
// computed ones bit for bit, the key changes with every input that changes the
// tables, damaged files are recomputed, the folder is shared safely, and the
// folder comes from the documented variables.
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include "sky/internal.h"
#include "sky/table_cache.h"
#include "skybake/sky.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;

// A fresh folder per test, and SKYBAKE_CACHE_DIR pointing at it while the test runs.
class CacheDir {
public:
    explicit CacheDir(const std::string& name)
        : dir_(fs::temp_directory_path() / ("skybake-cache-test-" + std::to_string(::getpid())) / name) {
        fs::remove_all(dir_);
        fs::create_directories(dir_);
        const char* old = std::getenv("SKYBAKE_CACHE_DIR");
        had_ = old != nullptr;
        old_ = old ? old : "";
        set(dir_.string());
    }
    ~CacheDir() {
        if (had_)
            ::setenv("SKYBAKE_CACHE_DIR", old_.c_str(), 1);
        else
            ::unsetenv("SKYBAKE_CACHE_DIR");
        std::error_code ec;
        fs::remove_all(dir_, ec);
    }
    static void set(const std::string& value) { ::setenv("SKYBAKE_CACHE_DIR", value.c_str(), 1); }
    const fs::path& path() const { return dir_; }
    // The regular files in the folder, hidden ones (temporaries) included.
    std::vector<fs::path> files() const {
        std::vector<fs::path> out;
        for (const auto& e : fs::directory_iterator(dir_))
            out.push_back(e.path());
        return out;
    }

private:
    fs::path dir_;
    bool had_ = false;
    std::string old_;
};

// Small tables: milliseconds per model, also under the sanitizers.
SkyModelOptions small_options() {
    SkyModelOptions o;
    o.tables = {32, 16};
    o.steps = 8;
    MultipleScatteringResolution& m = o.multiple;
    m.r = 4;
    m.mu = 4;
    m.mu_s = 4;
    m.nu = 3;
    m.sphere = 4;
    m.psi_r = 5;
    m.psi_mu_s = 6;
    m.irradiance_r = 3;
    m.irradiance_mu_s = 5;
    return o;
}

Atmosphere earth_multiple(MultipleScatteringMethod method) {
    Atmosphere a = atmosphere_preset("earth");
    a.scattering = Scattering::Multiple;
    a.multiple_method = method;
    a.scattering_orders = 3;
    return a;
}

// The model's tables as bytes: the main table (orders or psi), then the irradiance table.
std::string table_bytes(const SkyModel& model) {
    const sky::MultipleHD& m = sky::atmosphere_hd(model).ms;
    std::string out;
    const auto add = [&](const float* p, std::size_t floats) {
        EXPECT_NE(p, nullptr);
        if (p)
            out.append(reinterpret_cast<const char*>(p), floats * sizeof(float));
    };
    if (m.method == sky::kMultipleOrders)
        add(m.orders, std::size_t(m.nr) * 2u * std::size_t(m.nmu) * std::size_t(m.nmus) * std::size_t(m.nnu) * 3u);
    else
        add(m.psi, std::size_t(m.psi_nr) * std::size_t(m.psi_nmus) * 3u);
    add(m.irradiance, std::size_t(m.irr_nr) * std::size_t(m.irr_nmus) * 3u);
    return out;
}

// Radiances and sky irradiances of the model, as bytes.
std::string output_bytes(const SkyModel& model) {
    const std::vector<SkySample> samples = draw_sky_samples(257, 7);
    std::vector<glm::vec3> out(samples.size());
    evaluate_sky(model, samples, out, SkyMethod::Tables);
    std::string bytes(reinterpret_cast<const char*>(out.data()), out.size() * sizeof(glm::vec3));
    for (double h : {0.0, 3.0, 30.0})
        for (double mu : {-0.1, 0.2, 0.9}) {
            const glm::dvec3 e = model.sky_irradiance(h, mu);
            bytes.append(reinterpret_cast<const char*>(&e), sizeof e);
        }
    return bytes;
}

// The model of `atmosphere` computed without the cache.
SkyModel fresh_model(const Atmosphere& atmosphere, const SkyModelOptions& options) {
    const char* dir = std::getenv("SKYBAKE_CACHE_DIR");
    const std::string keep = dir ? dir : "";
    CacheDir::set("off");
    SkyModel model(atmosphere, options);
    if (dir)
        CacheDir::set(keep);
    else
        ::unsetenv("SKYBAKE_CACHE_DIR");
    EXPECT_FALSE(model.multiple_tables_from_cache());
    return model;
}

class TableCacheMethod : public ::testing::TestWithParam<MultipleScatteringMethod> {};

TEST_P(TableCacheMethod, ASecondModelReadsTheTablesBitForBit) {
    const CacheDir cache(std::string("bits-") + multiple_scattering_method_name(GetParam()));
    const Atmosphere atm = earth_multiple(GetParam());
    const SkyModel fresh = fresh_model(atm, small_options());
    EXPECT_TRUE(cache.files().empty()) << "the cache was off";

    const SkyModel first(atm, small_options());
    EXPECT_FALSE(first.multiple_tables_from_cache());
    ASSERT_EQ(cache.files().size(), 1u);
    EXPECT_EQ(cache.files().front().filename().string().rfind("multiple-scattering-", 0), 0u);

    const SkyModel second(atm, small_options());
    EXPECT_TRUE(second.multiple_tables_from_cache());
    EXPECT_EQ(second.multiple_table_bytes(), fresh.multiple_table_bytes());
    EXPECT_EQ(table_bytes(second), table_bytes(fresh));
    EXPECT_EQ(output_bytes(second), output_bytes(fresh));
    EXPECT_EQ(output_bytes(first), output_bytes(fresh));
    EXPECT_EQ(cache.files().size(), 1u);
}

INSTANTIATE_TEST_SUITE_P(Methods, TableCacheMethod,
                         ::testing::Values(MultipleScatteringMethod::Orders, MultipleScatteringMethod::Hillaire),
                         [](const auto& info) { return std::string(multiple_scattering_method_name(info.param)); });

TEST(TableCache, SingleScatteringNeitherReadsNorWrites) {
    const CacheDir cache("single");
    const SkyModel model(atmosphere_preset("earth"), small_options());
    EXPECT_FALSE(model.multiple_tables_from_cache());
    EXPECT_TRUE(cache.files().empty());
}

TEST(TableCache, OffWritesNothing) {
    const CacheDir cache("off");
    for (const char* off : {"off", "none", "0"}) {
        CacheDir::set(off);
        EXPECT_TRUE(sky_table_cache_dir().empty()) << off;
        const SkyModel a(earth_multiple(MultipleScatteringMethod::Hillaire), small_options());
        const SkyModel b(earth_multiple(MultipleScatteringMethod::Hillaire), small_options());
        EXPECT_FALSE(b.multiple_tables_from_cache()) << off;
    }
    EXPECT_TRUE(cache.files().empty());
    EXPECT_FALSE(fs::exists(fs::current_path() / "off"));
}

// Runs fn with the environment variables set as given (nullptr: unset), then restores them.
void with_env(const std::vector<std::pair<const char*, const char*>>& vars, const std::function<void()>& fn) {
    std::vector<std::pair<std::string, std::optional<std::string>>> saved;
    for (const auto& [name, value] : vars) {
        const char* old = std::getenv(name);
        saved.emplace_back(name, old ? std::optional<std::string>(old) : std::nullopt);
        if (value)
            ::setenv(name, value, 1);
        else
            ::unsetenv(name);
    }
    fn();
    for (const auto& [name, value] : saved)
        if (value)
            ::setenv(name.c_str(), value->c_str(), 1);
        else
            ::unsetenv(name.c_str());
}

TEST(TableCache, FolderFollowsTheDocumentedVariables) {
    with_env({{"SKYBAKE_CACHE_DIR", "/tmp/own"}, {"XDG_CACHE_HOME", "/x"}, {"HOME", "/h"}},
             [] { EXPECT_EQ(sky_table_cache_dir(), fs::path("/tmp/own")); });
    with_env({{"SKYBAKE_CACHE_DIR", nullptr}, {"XDG_CACHE_HOME", "/x"}, {"HOME", "/h"}},
             [] { EXPECT_EQ(sky_table_cache_dir(), fs::path("/x/skybake")); });
    // An empty SKYBAKE_CACHE_DIR is unset; a relative XDG_CACHE_HOME is invalid (XDG spec) and ignored.
    with_env({{"SKYBAKE_CACHE_DIR", ""}, {"XDG_CACHE_HOME", "rel"}, {"HOME", "/h"}},
             [] { EXPECT_EQ(sky_table_cache_dir(), fs::path("/h/.cache/skybake")); });
    with_env({{"SKYBAKE_CACHE_DIR", nullptr}, {"XDG_CACHE_HOME", ""}, {"HOME", "/h"}},
             [] { EXPECT_EQ(sky_table_cache_dir(), fs::path("/h/.cache/skybake")); });
    with_env({{"SKYBAKE_CACHE_DIR", nullptr}, {"XDG_CACHE_HOME", nullptr}, {"HOME", nullptr}},
             [] { EXPECT_TRUE(sky_table_cache_dir().empty()); });
}

// Every input of the tables: a change that changes the tables must change the
// key (else a stale file would be read back); a change that leaves them alone
// (the name, the sun of the rendering) keeps the key, so it still hits.
TEST(TableCache, KeyChangesWithEveryInputThatChangesTheTables) {
    using Edit = std::function<void(Atmosphere&, SkyModelOptions&)>;
    struct Case {
        const char* what;
        Edit edit;
    };
    const std::vector<Case> changes = {
        {"planet radius",
         [](Atmosphere& a, SkyModelOptions&) {
             a.planet_radius_km += 1.0;
             a.top_radius_km += 1.0;
         }},
        {"top radius", [](Atmosphere& a, SkyModelOptions&) { a.top_radius_km -= 10.0; }},
        {"ground albedo (blue)", [](Atmosphere& a, SkyModelOptions&) { a.ground_albedo.z = 0.3; }},
        {"table rule", [](Atmosphere& a, SkyModelOptions&) { a.table_rule = TableRule::Refined; }},
        {"orders", [](Atmosphere& a, SkyModelOptions&) { a.scattering_orders = 4; }},
        {"method", [](Atmosphere& a, SkyModelOptions&) { a.multiple_method = MultipleScatteringMethod::Hillaire; }},
        {"scale height", [](Atmosphere& a, SkyModelOptions&) { a.components[0].scale_height_km = 7.0; }},
        {"scattering (green)",
         [](Atmosphere& a, SkyModelOptions&) {
             a.components[0].scattering_per_km.y *= 1.5;
             a.components[0].extinction_per_km.y *= 1.5;
         }},
        {"extinction", [](Atmosphere& a, SkyModelOptions&) { a.components[1].extinction_per_km *= 1.2; }},
        {"phase", [](Atmosphere& a, SkyModelOptions&) { a.components[1].phase = PhaseFunction::HenyeyGreenstein; }},
        {"phase g", [](Atmosphere& a, SkyModelOptions&) { a.components[1].phase_g = 0.7; }},
        {"tent centre", [](Atmosphere& a, SkyModelOptions&) { a.components[2].tent_center_km = 30.0; }},
        {"tent half width", [](Atmosphere& a, SkyModelOptions&) { a.components[2].tent_half_width_km = 10.0; }},
        {"profile", [](Atmosphere& a, SkyModelOptions&) { a.components[1].profile = DensityProfile::Constant; }},
        {"a component fewer", [](Atmosphere& a, SkyModelOptions&) { a.components.pop_back(); }},
        {"table shells", [](Atmosphere&, SkyModelOptions& o) { o.tables.shells = 24; }},
        {"table cosines", [](Atmosphere&, SkyModelOptions& o) { o.tables.cosines = 12; }},
        {"steps", [](Atmosphere&, SkyModelOptions& o) { o.steps = 9; }},
        {"uniform steps", [](Atmosphere&, SkyModelOptions& o) { o.uniform_steps = true; }},
        {"grid r", [](Atmosphere&, SkyModelOptions& o) { o.multiple.r = 5; }},
        {"grid mu", [](Atmosphere&, SkyModelOptions& o) { o.multiple.mu = 5; }},
        {"grid mu_s", [](Atmosphere&, SkyModelOptions& o) { o.multiple.mu_s = 5; }},
        {"grid nu", [](Atmosphere&, SkyModelOptions& o) { o.multiple.nu = 4; }},
        {"sphere", [](Atmosphere&, SkyModelOptions& o) { o.multiple.sphere = 6; }},
        {"mu_s_min", [](Atmosphere&, SkyModelOptions& o) { o.multiple.mu_s_min = -0.3; }},
        {"irradiance r", [](Atmosphere&, SkyModelOptions& o) { o.multiple.irradiance_r = 4; }},
        {"irradiance mu_s", [](Atmosphere&, SkyModelOptions& o) { o.multiple.irradiance_mu_s = 6; }},
    };
    const Atmosphere base = earth_multiple(MultipleScatteringMethod::Orders);
    const SkyModelOptions base_options = small_options();
    const std::string base_key = sky::multiple_tables_key(base, base_options);
    const std::string base_tables = table_bytes(fresh_model(base, base_options));
    for (const Case& c : changes) {
        Atmosphere a = base;
        SkyModelOptions o = base_options;
        c.edit(a, o);
        const std::string tables = table_bytes(fresh_model(a, o));
        EXPECT_NE(tables, base_tables) << c.what << " should change the tables (else the case tests nothing)";
        EXPECT_NE(sky::multiple_tables_key(a, o), base_key) << c.what;
    }
    const std::vector<Case> same = {
        {"name",
         [](Atmosphere& a, SkyModelOptions&) {
             a.name = "other";
             a.components[0].name = "gas";
         }},
        {"sun",
         [](Atmosphere& a, SkyModelOptions&) {
             a.sun_elevation_deg = 5.0;
             a.sun_azimuth_deg = 90.0;
             a.sun_irradiance = glm::dvec3(2.0);
             a.sun_angular_radius_rad = 0.01;
         }},
        {"exact tolerance", [](Atmosphere&, SkyModelOptions& o) { o.exact_tolerance = 1e-5; }},
    };
    for (const Case& c : same) {
        Atmosphere a = base;
        SkyModelOptions o = base_options;
        c.edit(a, o);
        EXPECT_EQ(table_bytes(fresh_model(a, o)), base_tables) << c.what;
        EXPECT_EQ(sky::multiple_tables_key(a, o), base_key) << c.what;
    }
}

TEST(TableCache, ModelsOfADifferentAtmosphereMissAndTheSameOneHits) {
    const CacheDir cache("miss");
    Atmosphere a = earth_multiple(MultipleScatteringMethod::Hillaire);
    const SkyModel first(a, small_options());
    a.ground_albedo = glm::dvec3(0.25);
    const SkyModel other(a, small_options());
    EXPECT_FALSE(other.multiple_tables_from_cache());
    EXPECT_EQ(cache.files().size(), 2u);
    a.name = "renamed";
    a.sun_elevation_deg = -3.0;
    const SkyModel same(a, small_options());
    EXPECT_TRUE(same.multiple_tables_from_cache());
    EXPECT_EQ(table_bytes(same), table_bytes(other));
}

// A damaged file is never read back: the model computes its tables (the same
// bits as without a cache), rewrites the file, and the next model reads it.
TEST(TableCache, DamagedFilesAreRecomputedSilently) {
    const CacheDir cache("damaged");
    const Atmosphere atm = earth_multiple(MultipleScatteringMethod::Orders);
    const SkyModelOptions opts = small_options();
    const std::string fresh = table_bytes(fresh_model(atm, opts));
    { const SkyModel writer(atm, opts); }
    ASSERT_EQ(cache.files().size(), 1u);
    const fs::path file = cache.files().front();
    std::string good;
    {
        std::ifstream in(file, std::ios::binary);
        good.assign(std::istreambuf_iterator<char>(in), {});
    }
    const std::string key = sky::multiple_tables_key(atm, opts);
    const std::size_t payload = 32 + key.size(); // the first byte of the main table
    ASSERT_GT(good.size(), payload + 16);
    struct Damage {
        std::string what, bytes;
    };
    std::vector<Damage> damages = {
        {"empty", ""},
        {"header only", good.substr(0, 20)},
        {"half", good.substr(0, good.size() / 2)},
        {"one byte short", good.substr(0, good.size() - 1)},
        {"one byte more", good + "x"},
        {"no checksum", good.substr(0, good.size() - 8)},
    };
    const auto flipped = [&](std::size_t at) {
        std::string s = good;
        s[at] = char(s[at] ^ 0x10);
        return s;
    };
    damages.push_back({"magic", flipped(0)});
    damages.push_back({"format", flipped(8)});
    damages.push_back({"key", flipped(40)});
    damages.push_back({"main table", flipped(payload + 5)});
    damages.push_back({"irradiance table", flipped(good.size() - 8 - 3)});
    damages.push_back({"checksum", flipped(good.size() - 1)});
    for (const Damage& d : damages) {
        {
            std::ofstream out(file, std::ios::binary | std::ios::trunc);
            out.write(d.bytes.data(), std::streamsize(d.bytes.size()));
        }
        const SkyModel model(atm, opts);
        EXPECT_FALSE(model.multiple_tables_from_cache()) << d.what;
        EXPECT_EQ(table_bytes(model), fresh) << d.what;
        std::ifstream in(file, std::ios::binary);
        const std::string now(std::istreambuf_iterator<char>(in), {});
        EXPECT_EQ(now, good) << d.what << ": the file is rewritten whole";
        const SkyModel next(atm, opts);
        EXPECT_TRUE(next.multiple_tables_from_cache()) << d.what;
    }
    EXPECT_EQ(cache.files().size(), 1u) << "no temporaries left behind";
}

TEST(TableCache, AnUnwritableFolderOnlyCostsTheCache) {
    const CacheDir cache("unwritable");
    const fs::path blocker = cache.path() / "a-file";
    std::ofstream(blocker) << "x";
    CacheDir::set((blocker / "sub").string()); // a folder below a regular file cannot exist
    const Atmosphere atm = earth_multiple(MultipleScatteringMethod::Hillaire);
    const SkyModel a(atm, small_options());
    const SkyModel b(atm, small_options());
    EXPECT_FALSE(b.multiple_tables_from_cache());
    EXPECT_EQ(table_bytes(b), table_bytes(fresh_model(atm, small_options())));
}

// Models built at once in one folder (threads here; processes in
// tests/sky_cache_cli_test.cpp): every one has the right tables, and the
// folder ends with one whole file and no temporaries.
TEST(TableCache, ModelsBuiltAtOnceShareTheFolder) {
    const CacheDir cache("concurrent");
    const Atmosphere atm = earth_multiple(MultipleScatteringMethod::Orders);
    const std::string fresh = table_bytes(fresh_model(atm, small_options()));
    constexpr int kThreads = 4;
    std::vector<std::string> got(kThreads);
    std::vector<std::thread> threads;
    for (int i = 0; i < kThreads; ++i)
        threads.emplace_back([&, i] { got[std::size_t(i)] = table_bytes(SkyModel(atm, small_options())); });
    for (std::thread& t : threads)
        t.join();
    for (const std::string& g : got)
        EXPECT_EQ(g, fresh);
    ASSERT_EQ(cache.files().size(), 1u);
    const SkyModel after(atm, small_options());
    EXPECT_TRUE(after.multiple_tables_from_cache());
    EXPECT_EQ(table_bytes(after), fresh);
}

} // namespace
} // namespace skybake
