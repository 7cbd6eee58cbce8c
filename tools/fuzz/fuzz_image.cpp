// libFuzzer target: the light-map and texture loader (load_image_from_memory,
// what load_image() does for `prt relight --light-map` and base colour
// images). The first byte picks the format (EXR, Radiance HDR, PNG, JPEG);
// the rest is the file. Images are limited to 4 Mpixel here: a header that
// claims more must be an Error before anything that size is allocated.
// Whatever loads must have its claimed size, and finite pixels (EXR may hold
// any float).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "skybake/error.h"
#include "skybake/image_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size < 1 || size > (1 << 20))
        return 0;
    static const char* const formats[] = {"exr", "hdr", "png", "jpg"};
    const char* format = formats[data[0] % 4];
    constexpr std::uint64_t max_pixels = std::uint64_t(1) << 22;
    try {
        const skybake::Image img = skybake::load_image_from_memory(data + 1, size - 1, format, "fuzz", max_pixels);
        if (img.width <= 0 || img.height <= 0 || std::uint64_t(img.width) * std::uint64_t(img.height) > max_pixels ||
            img.rgb.size() != std::size_t(img.width) * std::size_t(img.height) * 3)
            std::abort();
        if (data[0] % 4 != 0)
            for (float x : img.rgb)
                if (!std::isfinite(x))
                    std::abort();
    } catch (const skybake::Error&) {
    }
    return 0;
}
