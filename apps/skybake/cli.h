// Shared plumbing for the skybake sub-commands.
//
// Each sub-command lives in its own file and exposes one function,
// `void add_<group>_<name>(CLI::App& group)`, listed in commands.cpp.
// A sub-command's callback throws skybake::Error on bad input; main() turns it
// into one line on stderr and exit code 1. CLI11 usage errors exit with 2.
#pragma once

#include <cstdio>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "skybake/core.h"
#include "skybake/error.h"
#include "skybake/gltf_asset.h"
#include "skybake/mesh.h"

namespace skybake::cli {

// Adds the --json flag every sub-command has.
inline CLI::Option* add_json_flag(CLI::App& sub, bool& json) {
    return sub.add_flag("--json", json, "Print a machine-readable JSON summary on stdout");
}

// Prints a JSON document on stdout (one object, pretty-printed).
inline void print_json(const nlohmann::json& j) { std::fputs((j.dump(2) + "\n").c_str(), stdout); }

// Informational line on stderr, unless --quiet.
template <class... Args>
void info(fmt::format_string<Args...> f, Args&&... args) {
    if (!skybake::quiet())
        fmt::print(stderr, "{}\n", fmt::format(f, std::forward<Args>(args)...));
}

// load_mesh(), with a warning line for each texture the model names that was
// not found (the material keeps its colour): every command that reads a model.
Mesh load_model(const std::string& path);
// The mesh of a bake that writes `output` (skybake/gltf_asset.h, BakeFile): a
// glTF 2.0 input keeps its document; warns of missing textures as
// load_model() does. A .gltf output of another input is a UsageError.
BakeFile open_bake_file(const std::string& input, const std::string& output);
// The warning lines of load_model(), for a report from elsewhere.
void warn_missing_textures(const std::string& path, const ImportReport& report);

// Parses "WxH" (e.g. "1280x720"); throws skybake::Error naming the flag.
void parse_size(const std::string& text, int& width, int& height, const char* flag);

} // namespace skybake::cli
