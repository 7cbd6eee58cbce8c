// 16-bit greyscale PNG output through libpng (W3C, "Portable Network
// Graphics (PNG) Specification", second edition, 2003: bit depth 16, colour
// type 0, big-endian samples).
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

} // namespace

std::string encode_png16_gray(int width, int height, const std::vector<float>& values) {
    if (width <= 0 || height <= 0 || values.size() != std::size_t(width) * std::size_t(height))
        throw Error(fmt::format("{} values for a {}x{} image", values.size(), width, height), "values");
    std::string bytes;
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    png_infop info = png ? png_create_info_struct(png) : nullptr;
    std::vector<png_byte> row(std::size_t(width) * 2);
    bool ok = png && info;
    if (ok && setjmp(png_jmpbuf(png)) == 0) {
        png_set_write_fn(png, &bytes, append_bytes, flush_nothing);
        png_set_IHDR(png, info, png_uint_32(width), png_uint_32(height), 16, PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE,
                     PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
        png_write_info(png, info);
        for (int y = 0; y < height; ++y) {
            for (int x = 0; x < width; ++x) {
                const float v = values[std::size_t(y) * std::size_t(width) + std::size_t(x)];
                const auto q =
                    std::uint16_t(std::lround(std::clamp(std::isfinite(v) ? v : 0.0f, 0.0f, 1.0f) * 65535.0f));
                row[2 * std::size_t(x)] = png_byte(q >> 8);
                row[2 * std::size_t(x) + 1] = png_byte(q & 0xff);
            }
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
