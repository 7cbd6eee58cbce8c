#include "io/texture_path.h"

#include <cctype>
#include <string>
#include <system_error>
#include <vector>

namespace skybake::io {

std::optional<std::filesystem::path> find_texture(std::string_view written, const std::filesystem::path& model_dir) {
    namespace fs = std::filesystem;
    std::string path(written);
    for (char& c : path)
        if (c == '\\')
            c = '/';
    if (path.empty())
        return std::nullopt;
    const auto is_file = [](const fs::path& p) {
        std::error_code ec;
        return fs::is_regular_file(p, ec);
    };
    // A drive letter ("D:/...") or a leading '/' makes it absolute on its machine.
    const bool drive = path.size() >= 2 && path[1] == ':' &&
                       ((path[0] >= 'A' && path[0] <= 'Z') || (path[0] >= 'a' && path[0] <= 'z'));
    const bool absolute = drive || path[0] == '/';
    if (!drive) {
        const fs::path as_written = absolute ? fs::path(path) : model_dir / path;
        if ((absolute || !model_dir.empty()) && is_file(as_written))
            return as_written.lexically_normal();
    }
    if (model_dir.empty())
        return std::nullopt;
    std::vector<std::string> parts; // the folders and the file name, without "." and ".."
    std::size_t start = drive ? 2 : 0;
    while (start <= path.size()) {
        const std::size_t end = std::min(path.find('/', start), path.size());
        const std::string part = path.substr(start, end - start);
        if (!part.empty() && part != "." && part != "..")
            parts.push_back(part);
        start = end + 1;
    }
    for (std::size_t first = 0; first < parts.size(); ++first) {
        fs::path tail;
        for (std::size_t i = first; i < parts.size(); ++i)
            tail /= parts[i];
        for (const fs::path& base : {model_dir, model_dir.parent_path()})
            if (!base.empty() && is_file(base / tail))
                return (base / tail).lexically_normal();
    }
    return std::nullopt;
}

std::string percent_decode(std::string_view uri) {
    const auto hex = [](char c) { return std::isxdigit(static_cast<unsigned char>(c)) != 0; };
    std::string out;
    for (std::size_t i = 0; i < uri.size(); ++i) {
        if (uri[i] == '%' && i + 2 < uri.size() && hex(uri[i + 1]) && hex(uri[i + 2])) {
            out += char(std::stoi(std::string(uri.substr(i + 1, 2)), nullptr, 16));
            i += 2;
        } else {
            out += uri[i];
        }
    }
    return out;
}

} // namespace skybake::io
