// The on-disk cache of the multiple-scattering tables (see sky_table_cache_dir()
// in skybake/sky.h and docs/sky.md).
//
// One file per table set, named after a 64-bit FNV-1a hash of its key and
// holding the whole key, so that two keys with one hash never share tables:
//
//   "SKYBAKEC"  magic, 8 bytes
//   u32         kTableCacheFormat
//   u32         key bytes
//   u64         floats of the main table (orders or psi), of the irradiance table
//   key text, main table, irradiance table (floats, host byte order)
//   u64         FNV-1a 64 of every byte before it
//
// A file of the wrong size, checksum, format or key is ignored and rewritten.
// Files are written to a unique temporary name in the same folder and renamed
// into place, so a reader sees a whole file or none, and processes that
// compute the same tables at once each rename a complete copy.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "skybake/sky.h"

namespace skybake::sky {

// Bump whenever the file layout or the tables' algorithms change (results of
// an older build must not be read back as this build's).
inline constexpr unsigned kTableCacheFormat = 4; // 2: orders interpolated geometrically in μs below the horizon; 3: the sphere rule split at the geometric horizon and the horizontal; 4: J interpolated per unit scattering coefficient

struct CachedTables {
    std::vector<float> main;       // MultipleHD::orders or MultipleHD::psi
    std::vector<float> irradiance; // MultipleHD::irradiance
};

// Every input of the multiple-scattering tables, as text (doubles in hex, so
// exact): the atmosphere without its name and sun (which the tables do not
// read), the options that shape them, the format and the build.
std::string multiple_tables_key(const Atmosphere& atmosphere, const SkyModelOptions& options);

// The file of `key` in `dir`.
std::filesystem::path cached_tables_path(const std::filesystem::path& dir, const std::string& key);

// True with `out` filled when `dir` holds a valid file for `key` whose tables
// have the expected sizes (floats); false for a missing, short, corrupt or
// foreign file. Never throws.
bool load_cached_tables(const std::filesystem::path& dir, const std::string& key, std::size_t main_floats,
                        std::size_t irradiance_floats, CachedTables& out);

// Writes the tables for `key` into `dir` (created if needed). Failure (a
// read-only or full disk) is silent: the cache is only a cache. Rethrows
// skybake::Interrupted only.
void store_cached_tables(const std::filesystem::path& dir, const std::string& key, const CachedTables& tables);

} // namespace skybake::sky
