#include "cli.h"

#include <optional>

#include "flags.h"

#include <charconv>

namespace skybake::cli {

Mesh load_model(const std::string& path) {
    ImportReport report;
    Mesh mesh = load_mesh(path, &report);
    warn_missing_textures(path, report);
    return mesh;
}

BakeFile open_bake_file(const std::string& input, const std::string& output) {
    std::optional<BakeFile> f;
    try {
        f.emplace(BakeFile::open(input, output));
    } catch (const Error& e) {
        if (e.where() == "output")
            throw UsageError(e.message(), "--output");
        throw;
    }
    warn_missing_textures(input, f->report());
    return std::move(*f);
}

void warn_missing_textures(const std::string& path, const ImportReport& report) {
    for (const std::string& t : report.missing_textures)
        info("warning: {}: texture '{}' not found (looked beside the model too); its material keeps its colour",
             path, t);
}

void parse_size(const std::string& text, int& width, int& height, const char* flag) {
    const auto x = text.find('x');
    auto parse = [&](std::string_view s, int& out) {
        const auto r = std::from_chars(s.data(), s.data() + s.size(), out);
        return r.ec == std::errc() && r.ptr == s.data() + s.size() && out > 0 && out <= 16384;
    };
    if (x == std::string::npos || !parse(std::string_view(text).substr(0, x), width) ||
        !parse(std::string_view(text).substr(x + 1), height))
        throw Error(fmt::format("bad size '{}': expected WIDTHxHEIGHT, each 1 to 16384", text), flag);
}

} // namespace skybake::cli
