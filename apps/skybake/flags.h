// The command line's contract, in one place: every numeric flag is checked
// where it is parsed (finite, in range, in readable numbers), every output
// path before any work starts, and a bad flag value is a usage error (exit 2)
// whether CLI11 or the library finds it.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <utility>

#include <CLI/CLI.hpp>
#include <glm/vec3.hpp>

#include "skybake/error.h"

namespace skybake::cli {

// A flag's value is wrong, or flags do not go together: main() prints one line
// with the usage hint and exits 2, as for CLI11's own parse errors.
class UsageError : public Error {
public:
    using Error::Error;
};

// How a range end is meant.
enum class End { Closed, Open };

// Validators on the option's text, run before conversion. Each rejects NaN,
// infinities, trailing garbage and values out of range, naming the value and
// the range: "value nan is not a number; expected a finite number in [-90, 90] degrees".
// `unit` may be empty.
CLI::Validator real_in(double lo, double hi, const std::string& unit, End lo_end = End::Closed,
                       End hi_end = End::Closed);
CLI::Validator integer_in(std::int64_t lo, std::int64_t hi, const std::string& unit = {});
// "auto", or a real number as real_in.
CLI::Validator auto_or_real_in(double lo, double hi, const std::string& unit, End lo_end = End::Closed,
                               End hi_end = End::Closed);

// A number for messages: 0.5, 1e+300, 50000000 (never 300 digits).
std::string readable(double x);

// Runs a parse of a flag's value (a rule spec, a method name, a size): its
// skybake::Error becomes a UsageError naming the flag.
template <class F>
auto parse_flag(const char* flag, F&& parse) -> decltype(parse()) {
    try {
        return parse();
    } catch (const UsageError&) {
        throw;
    } catch (const Error& e) {
        throw UsageError(e.message(), flag);
    }
}

// Runs a library check of several flags at once (resolve_tracer()): its
// skybake::Error becomes a UsageError naming the flag of the field at fault.
std::string flag_for_field(const std::string& where);
template <class F>
auto parse_flags(F&& parse) -> decltype(parse()) {
    try {
        return parse();
    } catch (const UsageError&) {
        throw;
    } catch (const Error& e) {
        throw UsageError(e.message(), flag_for_field(e.where()));
    }
}

// The library names the API field at fault in Error::where() (e.g.
// "max_distance"); the CLI speaks of flags. The flag that sets `where`, from
// the one table of the CLI (flags.cpp), or `where` itself when no flag sets
// it (a file name, "mesh"). main() applies it to every error it prints.
std::string flag_for_field(const std::string& where);

// Checks an output path before any work: a known extension (a usage error
// otherwise), an existing, writable folder, and not a folder itself (exit 1:
// the file system is in the way, not the command line). `extensions` are
// lower case with the dot, e.g. {".glb", ".ply"}; empty accepts any.
void check_output_path(const std::string& path, std::initializer_list<const char*> extensions, const char* flag);

// An output folder (fly -o, ao --out-dir, sky error --views-dir): a command
// whose output is a folder creates it. The folder may exist (it must be
// writable), or be new in an existing, writable folder (exit 1 otherwise, as
// check_output_path). Checked and created before any work; a folder created
// here is removed again if the command fails before keep() and it is still
// empty, so a failure leaves nothing behind.
class OutputFolder {
public:
    OutputFolder(const std::string& path, const char* flag);
    OutputFolder(const OutputFolder&) = delete;
    OutputFolder& operator=(const OutputFolder&) = delete;
    ~OutputFolder();
    void keep() { created_ = false; }

private:
    std::string path_;
    bool created_ = false;
};

// Lower-case extension with the dot ("" when there is none).
std::string lower_extension(const std::string& path);

// A usage error if `flag` was given on the command line: it does not apply,
// for `reason` ("with --view fisheye").
void refuse_if_given(const CLI::App& sub, const char* flag, const std::string& reason);
// Whether `flag` was given.
bool given(const CLI::App& sub, const char* flag);

// --help of --device and --backend, from the registered backends
// (skybake/visibility.h, [SECTION] Backends).
std::string device_help();
std::string backend_help();

// "0.8" or "0.8,0.6,0.4": a linear RGB reflectance in [0, 1]. Throws
// UsageError naming `flag`.
glm::vec3 parse_albedo(const std::string& text, const char* flag = "--albedo");

} // namespace skybake::cli
