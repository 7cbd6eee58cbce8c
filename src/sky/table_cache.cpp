// The on-disk cache of the multiple-scattering tables (table_cache.h).
#include "sky/table_cache.h"

#include <bit>
#include <cstdint>
#include <cstring>
#include <fstream>

#include <fmt/format.h>

#include "skybake/core.h"
#include "skybake/files.h"
#include "skybake/interrupt.h"

namespace skybake {

namespace fs = std::filesystem;

fs::path sky_table_cache_dir() { return cache_dir(); }

namespace sky {

namespace {

constexpr char kMagic[8] = {'S', 'K', 'Y', 'B', 'A', 'K', 'E', 'C'};
constexpr std::size_t kHeaderBytes = 8 + 4 + 4 + 8 + 8;
constexpr std::uint64_t kMaxFileBytes = std::uint64_t(1) << 31;

std::uint64_t fnv1a(const void* data, std::size_t n, std::uint64_t h = 0xcbf29ce484222325ull) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) {
        h ^= p[i];
        h *= 0x100000001b3ull;
    }
    return h;
}

template <class T>
void put(std::string& out, const T& v) {
    out.append(reinterpret_cast<const char*>(&v), sizeof v);
}

template <class T>
T get(const std::string& in, std::size_t at) {
    T v;
    std::memcpy(&v, in.data() + at, sizeof v);
    return v;
}

std::string hex3(const glm::dvec3& v) {
    return fmt::format("{:a} {:a} {:a}", v.x, v.y, v.z);
}

// What the compiler may change in the tables' last bits.
std::string build_identity() {
    std::string s = fmt::format("skybake {}; format {}; ", version(), kTableCacheFormat);
#if defined(__VERSION__)
    s += "compiler " __VERSION__ "; ";
#endif
#if defined(__OPTIMIZE__)
    s += "optimized; ";
#endif
#if defined(__FMA__)
    s += "fma; ";
#endif
#if defined(__AVX2__)
    s += "avx2; ";
#endif
#if defined(__AVX512F__)
    s += "avx512f; ";
#endif
#if defined(__FAST_MATH__)
    s += "fast-math; ";
#endif
    s += fmt::format("{}-bit {}-endian", 8 * sizeof(void*),
                     std::endian::native == std::endian::little ? "little" : "big");
    return s;
}

} // namespace

std::string multiple_tables_key(const Atmosphere& a, const SkyModelOptions& o) {
    std::string k = build_identity() + "\n";
    k += fmt::format("planet_radius_km {:a}\ntop_radius_km {:a}\nground_albedo {}\ntable_rule {}\n", a.planet_radius_km,
                     a.top_radius_km, hex3(a.ground_albedo), int(a.table_rule));
    k += fmt::format("scattering {}\nmultiple_method {}\n", int(a.scattering), int(a.multiple_method));
    if (a.multiple_method == MultipleScatteringMethod::Orders)
        k += fmt::format("scattering_orders {}\n", a.scattering_orders);
    for (const AtmosphereComponent& c : a.components)
        k += fmt::format("component profile {} scale_height_km {:a} tent_center_km {:a} tent_half_width_km {:a} "
                         "scattering_per_km {} extinction_per_km {} phase {} phase_g {:a}\n",
                         int(c.profile), c.scale_height_km, c.tent_center_km, c.tent_half_width_km,
                         hex3(c.scattering_per_km), hex3(c.extinction_per_km), int(c.phase), c.phase_g);
    const MultipleScatteringResolution& m = o.multiple;
    k += fmt::format("tables {} {}\nsteps {} uniform {}\n", o.tables.shells, o.tables.cosines, o.steps,
                     o.uniform_steps ? 1 : 0);
    k += fmt::format("grid {} {} {} {} sphere {} psi {} {} irradiance {} {} mu_s_min {:a}\n", m.r, m.mu, m.mu_s, m.nu,
                     m.sphere, m.psi_r, m.psi_mu_s, m.irradiance_r, m.irradiance_mu_s, m.mu_s_min);
    return k;
}

fs::path cached_tables_path(const fs::path& dir, const std::string& key) {
    return dir / fmt::format("multiple-scattering-{:016x}.bin", fnv1a(key.data(), key.size()));
}

bool load_cached_tables(const fs::path& dir, const std::string& key, std::size_t main_floats,
                        std::size_t irradiance_floats, CachedTables& out) {
    try {
        const fs::path path = cached_tables_path(dir, key);
        const std::uint64_t expected =
            kHeaderBytes + key.size() + (main_floats + irradiance_floats) * sizeof(float) + sizeof(std::uint64_t);
        std::error_code ec;
        const std::uint64_t size = fs::file_size(path, ec);
        if (ec || size != expected || size > kMaxFileBytes)
            return false;
        std::ifstream in(path, std::ios::binary);
        if (!in)
            return false;
        std::string data(size, '\0');
        in.read(data.data(), std::streamsize(size));
        if (std::uint64_t(in.gcount()) != size)
            return false;
        const std::size_t body = std::size_t(size) - sizeof(std::uint64_t);
        if (std::memcmp(data.data(), kMagic, 8) != 0 || get<std::uint32_t>(data, 8) != kTableCacheFormat ||
            get<std::uint32_t>(data, 12) != key.size() || get<std::uint64_t>(data, 16) != main_floats ||
            get<std::uint64_t>(data, 24) != irradiance_floats ||
            get<std::uint64_t>(data, body) != fnv1a(data.data(), body) ||
            data.compare(kHeaderBytes, key.size(), key) != 0)
            return false;
        out.main.resize(main_floats);
        out.irradiance.resize(irradiance_floats);
        const std::size_t at = kHeaderBytes + key.size();
        std::memcpy(out.main.data(), data.data() + at, main_floats * sizeof(float));
        std::memcpy(out.irradiance.data(), data.data() + at + main_floats * sizeof(float),
                    irradiance_floats * sizeof(float));
        return true;
    } catch (...) { // out of memory, a stream error: compute the tables instead
        return false;
    }
}

void store_cached_tables(const fs::path& dir, const std::string& key, const CachedTables& t) {
    try {
        std::string data;
        data.reserve(kHeaderBytes + key.size() + (t.main.size() + t.irradiance.size()) * sizeof(float) + 8);
        data.append(kMagic, 8);
        put(data, std::uint32_t(kTableCacheFormat));
        put(data, std::uint32_t(key.size()));
        put(data, std::uint64_t(t.main.size()));
        put(data, std::uint64_t(t.irradiance.size()));
        data += key;
        data.append(reinterpret_cast<const char*>(t.main.data()), t.main.size() * sizeof(float));
        data.append(reinterpret_cast<const char*>(t.irradiance.data()), t.irradiance.size() * sizeof(float));
        put(data, fnv1a(data.data(), data.size()));
        std::error_code ec;
        fs::create_directories(dir, ec);
        write_stream_atomic(cached_tables_path(dir, key),
                            [&](std::ostream& f) { f.write(data.data(), std::streamsize(data.size())); });
    } catch (const Interrupted&) {
        throw;
    } catch (...) { // a read-only or full disk: the next run computes the tables again
    }
}

} // namespace sky
} // namespace skybake
