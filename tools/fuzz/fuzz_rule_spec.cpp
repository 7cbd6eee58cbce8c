// libFuzzer target: sphere rule specs (parse_rule, what `--rule` and the
// sphere commands read). Whatever parses must be a rule whose weights are
// finite and whose points are unit vectors.
#include <cctype>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include <glm/geometric.hpp>

#include "skybake/error.h"
#include "skybake/sphere.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size > 64) // a spec is short; longer inputs only repeat what shorter ones find
        return 0;
    const std::string spec(reinterpret_cast<const char*>(data), size);
    // Designs above t = 12 are computed by an optimisation that takes seconds
    // (and is cached on disk), and rules of millions of points take their
    // time to fill: slow by nature, not parser bugs. Counts up to 999,999 and
    // small designs keep every branch of the parser reachable.
    // Names are case-insensitive ("design:T40" is design:t40).
    std::string lower = spec;
    for (char& c : lower)
        c = char(std::tolower(static_cast<unsigned char>(c)));
    if (const auto d = lower.find("design:"); d != std::string::npos) { // "design:tT" or "design:T"
        const char* t = lower.c_str() + d + 7;
        if (std::strtol(*t == 't' ? t + 1 : t, nullptr, 10) > 12)
            return 0;
    }
    // Phong rules solve an n × n eigenproblem (O(n³)): at n = 444 that takes
    // two minutes under the sanitizers and half a second in a release build.
    // n up to 64, and n above the limit of 512 (an error), stay reachable.
    for (std::size_t k = lower.find("n="); k != std::string::npos; k = lower.find("n=", k + 2)) {
        const long n = std::strtol(lower.c_str() + k + 2, nullptr, 10); // strtol saturates; atoi would overflow
        if (lower.find("phong") != std::string::npos && n > 64 && n <= 512)
            return 0;
    }
    int digits = 0;
    for (char c : spec) {
        digits = c >= '0' && c <= '9' ? digits + 1 : 0;
        if (digits > 6)
            return 0;
    }
    try {
        const skybake::SphereRule r = skybake::parse_rule(spec);
        if (r.points.size() != r.weights.size() || r.points.empty())
            std::abort();
        for (std::size_t k = 0; k < r.size(); ++k)
            if (!std::isfinite(r.weights[k]) || std::abs(glm::length(r.points[k]) - 1.0) > 1e-9)
                std::abort();
        (void)skybake::parse_rule(r.spec); // the canonical spec parses back
    } catch (const skybake::Error&) {
    }
    return 0;
}
