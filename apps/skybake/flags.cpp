#include "flags.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <vector>

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include "core/parse_number.h"
#include "skybake/visibility.h"

namespace skybake::cli {

namespace fs = std::filesystem;

std::string readable(double x) {
    if (std::isnan(x))
        return "nan";
    if (std::isinf(x))
        return x > 0 ? "inf" : "-inf";
    if (x == std::floor(x) && std::abs(x) < 1e9)
        return fmt::format("{:.0f}", x);
    return fmt::format("{:.6g}", x);
}

namespace {

std::string range_text(double lo, double hi, End lo_end, End hi_end, const std::string& unit) {
    std::string r;
    if (std::isinf(lo) && std::isinf(hi))
        r = "a finite number";
    else if (std::isinf(hi))
        r = fmt::format("a finite number {} {}", lo_end == End::Open ? ">" : "≥", readable(lo));
    else if (std::isinf(lo))
        r = fmt::format("a finite number {} {}", hi_end == End::Open ? "<" : "≤", readable(hi));
    else
        r = fmt::format("a number in {}{}, {}{}", lo_end == End::Open ? "(" : "[", readable(lo), readable(hi),
                        hi_end == End::Open ? ")" : "]");
    return unit.empty() ? r : r + " " + unit;
}

std::string check_real(const std::string& text, double lo, double hi, End lo_end, End hi_end, const std::string& unit) {
    double v = 0.0;
    const std::string expected = "expected " + range_text(lo, hi, lo_end, hi_end, unit);
    if (!parse_decimal(text, v)) {
        // from_chars reports out-of-range doubles (1e400) as errors too.
        return fmt::format("'{}' is not a number; {}", text.size() > 40 ? text.substr(0, 40) + "..." : text, expected);
    }
    if (!std::isfinite(v))
        return fmt::format("{} is not a finite number; {}", readable(v), expected);
    const bool below = lo_end == End::Open ? !(v > lo) : !(v >= lo);
    const bool above = hi_end == End::Open ? !(v < hi) : !(v <= hi);
    if (below || above)
        return fmt::format("{} is out of range; {}", readable(v), expected);
    return {};
}

} // namespace

CLI::Validator real_in(double lo, double hi, const std::string& unit, End lo_end, End hi_end) {
    return CLI::Validator([=](std::string& text) { return check_real(text, lo, hi, lo_end, hi_end, unit); },
                          "(" + range_text(lo, hi, lo_end, hi_end, unit) + ")", "real_in");
}

CLI::Validator auto_or_real_in(double lo, double hi, const std::string& unit, End lo_end, End hi_end) {
    return CLI::Validator(
        [=](std::string& text) {
            if (text == "auto")
                return std::string();
            const std::string e = check_real(text, lo, hi, lo_end, hi_end, unit);
            return e.empty() ? e : e + ", or auto";
        },
        "(auto, or " + range_text(lo, hi, lo_end, hi_end, unit) + ")", "auto_or_real_in");
}

CLI::Validator integer_in(std::int64_t lo, std::int64_t hi, const std::string& unit) {
    const std::string expected =
        fmt::format("expected a whole number from {} to {}{}", lo, hi, unit.empty() ? "" : " " + unit);
    return CLI::Validator(
        [=](std::string& text) -> std::string {
            std::int64_t v = 0;
            const char* first = text.data();
            if (!text.empty() && *first == '+')
                ++first;
            const auto r = std::from_chars(first, text.data() + text.size(), v);
            if (text.empty() || r.ptr != text.data() + text.size() || r.ec == std::errc::invalid_argument)
                return fmt::format("'{}' is not a whole number; {}",
                                   text.size() > 40 ? text.substr(0, 40) + "..." : text, expected);
            if (r.ec == std::errc::result_out_of_range || v < lo || v > hi)
                return fmt::format("{} is out of range; {}", text.size() > 40 ? text.substr(0, 40) + "..." : text,
                                   expected);
            return {};
        },
        fmt::format("({} to {}{})", lo, hi, unit.empty() ? "" : " " + unit), "integer_in");
}

std::string lower_extension(const std::string& path) {
    std::string e = fs::path(path).extension().string();
    std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return e;
}

void check_output_path(const std::string& path, std::initializer_list<const char*> extensions, const char* flag) {
    if (path.empty())
        throw UsageError("the output path is empty", flag);
    if (path == "-")
        return; // stdout, where the command allows it
    if (extensions.size() > 0) {
        const std::string ext = lower_extension(path);
        std::string list;
        bool known = false;
        for (const char* e : extensions) {
            known |= ext == e;
            list += (list.empty() ? "" : " or ") + std::string(e);
        }
        if (!known)
            throw UsageError(fmt::format("cannot write '{}' files; use {}", ext.empty() ? "(no extension)" : ext, list),
                             flag);
    }
    const fs::path p(path);
    const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
    std::error_code ec;
    if (!fs::is_directory(dir, ec))
        throw Error(fmt::format("the output folder {} does not exist", dir.string()), flag);
    // Creating a file is the only test that holds for every user and file
    // system (root passes access() on read-only mounts such as /proc).
    const fs::path probe = dir / fmt::format(".skybake-probe-{}", ::getpid());
    const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0600);
    if (fd < 0 && errno != EEXIST) // a probe left by a killed run proves little either way
        throw Error(fmt::format("cannot write in the output folder {}: {}", dir.string(), std::strerror(errno)), flag);
    if (fd >= 0) {
        ::close(fd);
        ::unlink(probe.c_str());
    }
    if (fs::is_directory(p, ec))
        throw Error(fmt::format("the output path {} is a folder", path), flag);
}

OutputFolder::OutputFolder(const std::string& path, const char* flag) : path_(path) {
    if (path.empty())
        throw UsageError("the output folder is empty", flag);
    std::error_code ec;
    if (fs::is_directory(path, ec)) {
        check_output_path((fs::path(path) / "probe").string(), {}, flag); // writable
        return;
    }
    fs::path p(path);
    if (!p.has_filename()) // "frames/": its parent is the folder above
        p = p.parent_path();
    check_output_path(p.string(), {}, flag); // an existing, writable parent; not a file in the way
    if (fs::exists(p, ec))
        throw Error(fmt::format("the output folder {} is a file", path), flag);
    if (!fs::create_directory(p, ec))
        throw Error(fmt::format("cannot create the output folder {}: {}", path,
                                ec ? ec.message() : std::string("a file of that name is in the way")),
                    flag);
    created_ = true;
}

OutputFolder::~OutputFolder() {
    if (!created_)
        return;
    std::error_code ec;
    if (fs::is_empty(path_, ec) && !ec)
        fs::remove(path_, ec);
}

bool given(const CLI::App& sub, const char* flag) {
    const CLI::Option* o = sub.get_option_no_throw(flag);
    return o && o->count() > 0;
}

void refuse_if_given(const CLI::App& sub, const char* flag, const std::string& reason) {
    if (given(sub, flag))
        throw UsageError(fmt::format("{} does not apply {}", flag, reason), flag);
}

std::string flag_for_field(const std::string& where) {
    // API field (library Error::where()) → flag. A field that several
    // commands share ("samples") is set by the same flag in each.
    static const std::pair<const char*, const char*> kFields[] = {
        {"max_distance", "--max-distance"},
        {"ray_offset", "--offset"},
        {"rule", "--rule"},
        {"method", "--method"},
        {"backend", "--backend"},
        {"resolution", "--resolution"},
        {"device", "--device"},
        {"back_faces", "--back-faces"},
        {"preset", "--preset"},
        {"paper_r/paper_m", "--paper-r/--paper-m"},
        {"table_rule", "--table-rule"},
        {"scattering", "--scattering"},
        {"multiple_method", "--multiple-method"},
        {"scattering_orders", "--scattering-orders"},
        {"altitude_km", "--altitude-km"},
        {"sun_elevation_deg", "--sun-elevation-deg"},
        {"sun_azimuth_deg", "--sun-azimuth-deg"},
        {"fov_deg", "--fov"},
        {"yaw_deg/pitch_deg", "--yaw/--pitch"},
        {"width/height", "--size"},
        {"view_width/view_height", "--size"},
        {"topology", "--topology"},
        {"samples", "--samples"},
        {"heldout_samples", "--heldout"},
        {"adam_epochs/lm_iterations", "--epochs/--lm-iterations"},
        {"batch", "--batch"},
        {"learning_rate", "--learning-rate"},
        {"log_range", "--log-range"},
        {"brightness", "--brightness"},
        {"inputs", "--inputs"},
        {"outputs", "--outputs"},
        {"family_component", "--aerosol-range"},
        {"hard_share", "--hard-share"},
        {"flight_share", "--flight-share"},
        {"aerosol", "--aerosol"},
        {"name", "--name"},
        {"kind", "--kind"},
        {"target_triangles", "--triangles"},
        {"order", "--order"},
        {"bounces", "--bounces"},
        {"model", "--model"},
        {"albedo", "--albedo"},
        {"light", "--light"},
        {"texture_size", "--texture"},
        {"uv_set", "--uv"},
        {"dilate_texels", "--dilate"},
    };
    for (const auto& [field, flag] : kFields)
        if (where == field)
            return flag;
    return where;
}

std::string device_help() {
    std::string devices;
    for (const TracerBackend& b : tracer_backends())
        if (devices.find(b.device) == std::string::npos)
            devices += ", " + b.device;
    return fmt::format("Where the bake runs: auto (a CUDA GPU when one answers, else the CPU){}; the device's first "
                       "backend unless --backend names one",
                       devices);
}

std::string backend_help() {
    std::string text = "Visibility backend (default: the device's first):";
    for (const TracerBackend& b : tracer_backends()) {
        std::string methods;
        for (TraceMethod m : b.methods)
            methods += std::string(methods.empty() ? "" : ", ") + trace_method_name(m);
        text += fmt::format(" {} [on {}; methods {}]: {}", b.name, b.device, methods, b.summary);
        text += &b == &tracer_backends().back() ? "." : ";";
    }
    return text;
}

// "0.8" or "0.8,0.6,0.4": a linear RGB reflectance in [0, 1].
glm::vec3 parse_albedo(const std::string& text, const char* flag) {
    std::vector<float> v;
    std::stringstream s(text);
    std::string part;
    while (std::getline(s, part, ',')) {
        std::size_t used = 0;
        float x = 0.0f;
        try {
            x = std::stof(part, &used);
        } catch (const std::exception&) {
            used = 0;
        }
        if (used != part.size() || part.empty() || !(x >= 0.0f && x <= 1.0f))
            throw UsageError(fmt::format("albedo '{}' is not a reflectance; give one or three numbers in [0, 1], "
                                         "e.g. 0.8 or 0.8,0.6,0.4",
                                         text),
                             flag);
        v.push_back(x);
    }
    if (v.size() == 1)
        return glm::vec3(v[0]);
    if (v.size() == 3)
        return {v[0], v[1], v[2]};
    throw UsageError(fmt::format("albedo '{}' needs one or three numbers", text), flag);
}


} // namespace skybake::cli
