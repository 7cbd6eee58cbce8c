// PNG output in memory through libpng (W3C, "Portable Network Graphics (PNG)
// Specification", second edition, 2003): 16-bit greyscale (colour type 0,
// big-endian samples) for data textures, 8-bit grey, RGB or RGBA.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include <fmt/format.h>
#include <png.h>

#include "skybake/error.h"
#include "skybake/files.h"
#include "skybake/image.h"
#include "skybake/image_io.h"

namespace skybake {

namespace {

void append_bytes(png_structp png, png_bytep data, png_size_t length) {
    auto* out = static_cast<std::string*>(png_get_io_ptr(png));
    out->append(reinterpret_cast<const char*>(data), length);
}

void flush_nothing(png_structp) {}

// One PNG in memory: `bit_depth` 8 or 16, libpng colour type `type`,
// `fill(y, row)` writes row y (top first) into `row`.
template <class Fill>
std::string encode_png(int width, int height, int bit_depth, int type, std::size_t row_bytes, Fill fill) {
    std::string bytes;
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    png_infop info = png ? png_create_info_struct(png) : nullptr;
    std::vector<png_byte> row(row_bytes);
    volatile bool ok = png && info; // read after a longjmp
    if (ok && setjmp(png_jmpbuf(png)) == 0) {
        png_set_write_fn(png, &bytes, append_bytes, flush_nothing);
        png_set_IHDR(png, info, png_uint_32(width), png_uint_32(height), bit_depth, type, PNG_INTERLACE_NONE,
                     PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
        png_write_info(png, info);
        for (int y = 0; y < height; ++y) {
            fill(y, row.data());
            png_write_row(png, row.data());
        }
        png_write_end(png, nullptr);
    } else {
        ok = false;
    }
    png_destroy_write_struct(png ? &png : nullptr, info ? &info : nullptr);
    if (!ok)
        throw Error("cannot encode PNG (out of memory?)", "values");
    return bytes;
}

} // namespace

std::string encode_png16_gray(int width, int height, const std::vector<float>& values) {
    if (width <= 0 || height <= 0 || values.size() != std::size_t(width) * std::size_t(height))
        throw Error(fmt::format("{} values for a {}x{} image", values.size(), width, height), "values");
    return encode_png(width, height, 16, PNG_COLOR_TYPE_GRAY, std::size_t(width) * 2, [&](int y, png_byte* row) {
        for (int x = 0; x < width; ++x) {
            const float v = values[std::size_t(y) * std::size_t(width) + std::size_t(x)];
            const auto q = std::uint16_t(std::lround(std::clamp(std::isfinite(v) ? v : 0.0f, 0.0f, 1.0f) * 65535.0f));
            row[2 * std::size_t(x)] = png_byte(q >> 8);
            row[2 * std::size_t(x) + 1] = png_byte(q & 0xff);
        }
    });
}

std::string encode_png8(int width, int height, int channels, const std::vector<std::uint8_t>& samples) {
    const int type = channels == 1   ? PNG_COLOR_TYPE_GRAY
                     : channels == 3 ? PNG_COLOR_TYPE_RGB
                     : channels == 4 ? PNG_COLOR_TYPE_RGBA
                                     : -1;
    if (type < 0)
        throw Error(fmt::format("{} channels; a PNG here has 1, 3 or 4", channels), "values");
    const std::size_t row_bytes = std::size_t(width) * std::size_t(channels);
    if (width <= 0 || height <= 0 || samples.size() != row_bytes * std::size_t(height))
        throw Error(fmt::format("{} samples for a {}x{} image of {} channels", samples.size(), width, height, channels),
                    "values");
    return encode_png(width, height, 8, type, row_bytes, [&](int y, png_byte* row) {
        std::copy_n(samples.data() + std::size_t(y) * row_bytes, row_bytes, row);
    });
}

void save_png16_gray(const std::filesystem::path& path, int width, int height, const std::vector<float>& values) {
    if (width <= 0 || height <= 0 || values.size() != std::size_t(width) * std::size_t(height))
        throw Error(fmt::format("{} values for a {}x{} image", values.size(), width, height), path.string());
    const std::string bytes = encode_png16_gray(width, height, values);
    write_file_atomic(path, [&](const std::filesystem::path& tmp) {
        std::FILE* f = std::fopen(tmp.c_str(), "wb");
        if (!f)
            throw Error("cannot create file", tmp.string());
        const bool written = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
        const bool closed = std::fclose(f) == 0;
        if (!written || !closed)
            throw Error("cannot write PNG (disk full?)", tmp.string());
    });
}

} // namespace skybake
