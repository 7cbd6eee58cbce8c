// libFuzzer target: the atmosphere file (atmosphere_from_json, what
// `--atmosphere FILE` reads). Whatever parses must validate and survive a
// round trip through atmosphere_to_json unchanged.
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
        const skybake::Atmosphere a =
            skybake::atmosphere_from_json(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz");
        a.validate();
        const std::string once = skybake::atmosphere_to_json(a);
        if (skybake::atmosphere_to_json(skybake::atmosphere_from_json(once, "round trip")) != once)
            std::abort(); // the writer and the reader disagree
    } catch (const skybake::Error&) {
    }
    return 0;
}
