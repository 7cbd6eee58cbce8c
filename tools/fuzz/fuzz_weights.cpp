// libFuzzer target: the neural sky weights file (neural_sky_from_json, what
// `sky eval/render/error/export --model` read). Whatever parses must
// validate, evaluate to finite radiance and export.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "skybake/error.h"
#include "skybake/neural.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size > (1 << 20))
        return 0;
    try {
        const skybake::NeuralSky net =
            skybake::neural_sky_from_json(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz");
        net.validate("fuzz");
        const glm::vec3 c = skybake::neural_sky_radiance(net, {0.5f, 0.2f, 0.7f, 0.3f});
        if (!(std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z)))
            std::abort(); // a valid network must give finite radiance
        (void)skybake::export_neural_sky(net, skybake::ExportLanguage::Glsl);
    } catch (const skybake::Error&) {
    }
    return 0;
}
