// libFuzzer target: sphere rule specs (parse_rule, what `--rule` and the
// sphere commands read). Whatever parses must be a rule whose weights are
// finite and whose points are unit vectors.
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
    try {
        const skybake::SphereRule r = skybake::parse_rule(std::string(reinterpret_cast<const char*>(data), size));
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
