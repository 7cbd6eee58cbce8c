// libFuzzer target: sky sample CSV (read_sky_samples_csv, what
// `sky eval --input` reads). Whatever parses must be valid samples.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "skybake/error.h"
#include "skybake/sky.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size > (1 << 20))
        return 0;
    try {
        for (const skybake::SkySample& s :
             skybake::read_sky_samples_csv(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz"))
            if (!skybake::is_valid_sky_sample(s, 1e-6) || !(s.density > 0.0f && s.density <= 1.0f))
                std::abort();
    } catch (const skybake::Error&) {
    }
    return 0;
}
