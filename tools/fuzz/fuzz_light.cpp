// libFuzzer target: the SH light file (light_from_json, what load_light()
// reads for `prt relight --light` and `skybake sky sh` writes). Whatever
// parses must be a finite light of the right size, and survive a round trip
// through light_json unchanged.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "skybake/error.h"
#include "skybake/prt.h"

namespace {

bool finite(const glm::vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size > (1 << 20))
        return 0;
    try {
        const skybake::ShLight l =
            skybake::light_from_json(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz");
        if (l.order < 0 || l.order > skybake::kShMaxL || l.coeffs.size() != std::size_t(skybake::sh_count(l.order)))
            std::abort();
        for (const glm::vec3& c : l.coeffs)
            if (!finite(c))
                std::abort();
        if (!finite(l.sun_direction) || !finite(l.sun_irradiance))
            std::abort();
        const skybake::ShLight back =
            skybake::light_from_json(skybake::light_json(l, "fuzz", "lebedev:590"), "round trip");
        if (back.order != l.order || back.coeffs != l.coeffs || back.sun_direction != l.sun_direction ||
            back.sun_irradiance != l.sun_irradiance)
            std::abort(); // the writer and the reader disagree
    } catch (const skybake::Error&) {
    }
    return 0;
}
