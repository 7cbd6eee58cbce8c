#include "skybake/files.h"

#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <random>
#include <unistd.h>

#include <fmt/format.h>

#include "skybake/error.h"
#include "skybake/interrupt.h"

namespace skybake {

namespace fs = std::filesystem;

namespace {

// A hidden, unique name beside `target`: ".NAME<tag>-PID-N", plus the
// target's extension when `keep_extension` (for writers that pick their format
// by extension).
fs::path path_beside(const fs::path& target, const char* tag, bool keep_extension) {
    static std::atomic<unsigned> counter{0};
    const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
    return dir / fmt::format(".{}{}-{}-{}{}", keep_extension ? target.stem().string() : target.filename().string(),
                             tag, ::getpid(), counter++, keep_extension ? target.extension().string() : "");
}

fs::path temp_path_beside(const fs::path& target) { return path_beside(target, ".tmp", false); }

void check_target(const fs::path& target) {
    if (target.empty())
        throw Error("output path is empty");
    const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
    std::error_code ec;
    if (!fs::is_directory(dir, ec))
        throw Error("output folder does not exist", dir.string());
    if (fs::is_directory(target, ec))
        throw Error("output path is a folder", target.string());
}

} // namespace

void write_file_atomic(const fs::path& target, const std::function<void(const fs::path&)>& write) {
    check_interrupted(); // after SIGINT/SIGTERM nothing more is written
    check_target(target);
    const fs::path tmp = temp_path_beside(target);
    std::error_code ec;
    try {
        write(tmp);
    } catch (const Error& e) {
        fs::remove(tmp, ec);
        if (e.where() == tmp.string()) // the temporary's name means nothing to the user
            throw Error(e.message(), target.string());
        throw;
    } catch (...) {
        fs::remove(tmp, ec);
        throw;
    }
    if (!fs::exists(tmp, ec))
        throw Error("writer produced no file", target.string());
    if (interrupt_signal() != 0) {
        fs::remove(tmp, ec);
        check_interrupted();
    }
    fs::rename(tmp, target, ec);
    if (ec) {
        fs::remove(tmp, ec);
        throw Error(fmt::format("cannot rename output into place: {}", ec.message()), target.string());
    }
}

void write_stream_atomic(const fs::path& target, const std::function<void(std::ostream&)>& write) {
    write_file_atomic(target, [&](const fs::path& tmp) {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        if (!out) // write_file_atomic names the target instead of the temporary
            throw Error(fmt::format("cannot create file: {}", std::strerror(errno)), tmp.string());
        write(out);
        out.flush();
        if (!out)
            throw Error("write failed (disk full?)", target.string());
    });
}

OutputSet::~OutputSet() {
    std::error_code ec;
    for (const auto& [staging, target] : staged_)
        fs::remove(staging, ec);
}

fs::path OutputSet::stage(const fs::path& target) {
    check_target(target);
    const fs::path staging = path_beside(target, ".staged", true);
    staged_.emplace_back(staging, target);
    return staging;
}

void OutputSet::commit() {
    check_interrupted(); // the destructor removes the staged files
    std::error_code ec;
    for (const auto& [staging, target] : staged_)
        if (!fs::exists(staging, ec))
            throw Error("a staged output was never written", target.string());
    std::string failed, failed_target;
    for (const auto& [staging, target] : staged_) {
        fs::rename(staging, target, ec);
        if (ec && failed.empty()) {
            failed = fmt::format("cannot rename output into place: {}", ec.message());
            failed_target = target.string();
        }
    }
    if (!failed.empty())
        throw Error(failed, failed_target);
    staged_.clear();
}

fs::path cache_dir() {
    if (const char* own = std::getenv("SKYBAKE_CACHE_DIR"); own && *own) {
        const std::string v(own);
        if (v == "off" || v == "none" || v == "0")
            return {};
        return fs::path(v);
    }
    if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg && fs::path(xdg).is_absolute())
        return fs::path(xdg) / "skybake";
    if (const char* home = std::getenv("HOME"); home && *home)
        return fs::path(home) / ".cache" / "skybake";
    return {};
}

std::string read_file(const fs::path& path, std::uint64_t max_bytes) {
    std::error_code ec;
    if (!fs::exists(path, ec))
        throw Error("file not found", path.string());
    if (fs::is_directory(path, ec))
        throw Error("path is a folder, not a file", path.string());
    const auto size = fs::file_size(path, ec);
    if (ec)
        throw Error(fmt::format("cannot read file: {}", ec.message()), path.string());
    if (size > max_bytes)
        throw Error(fmt::format("file is {} bytes, over the limit of {} bytes", size, max_bytes), path.string());
    std::ifstream in(path, std::ios::binary);
    if (!in)
        throw Error(fmt::format("cannot open file: {}", std::strerror(errno)), path.string());
    std::string data(size, '\0');
    in.read(data.data(), std::streamsize(size));
    if (std::uint64_t(in.gcount()) != size)
        throw Error("short read", path.string());
    return data;
}

} // namespace skybake
