// Image files: PNG and Radiance HDR through stb_image(_write), JPEG through
// libjpeg-turbo, EXR through tinyexr.
// Tone curve: K. Narkowicz, "ACES Filmic Tone Mapping Curve", 2015.
#include "skybake/image_io.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <csetjmp>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <vector>

#include <fmt/format.h>
#include <jpeglib.h>
#include <tinyexr.h>

#include "skybake/error.h"
#include "skybake/files.h"
#include "skybake/names.h"

#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC
#include <stb_image_write.h>
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_STATIC
#define STBI_ONLY_PNG
#define STBI_ONLY_HDR
#include <stb_image.h>

namespace skybake {

namespace fs = std::filesystem;

namespace {

std::string lower_extension(const fs::path& p) {
    std::string ext = p.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

void check_image(const Image& image, const fs::path& path) {
    if (image.width <= 0 || image.height <= 0)
        throw Error("cannot write an empty image", path.string());
    if (image.rgb.size() != std::size_t(image.width) * std::size_t(image.height) * 3)
        throw Error("image buffer size does not match width * height * 3", path.string());
}

} // namespace

void save_png_srgb8(const fs::path& path, int width, int height, const std::uint8_t* rgb) {
    if (width <= 0 || height <= 0)
        throw Error("cannot write an empty image", path.string());
    write_file_atomic(path, [&](const fs::path& tmp) {
        if (!stbi_write_png(tmp.c_str(), width, height, 3, rgb, width * 3))
            throw Error("cannot write PNG", path.string());
    });
}

void save_png(const fs::path& path, const Image& image, const ToneMap& tm) {
    check_image(image, path);
    const auto bytes = to_srgb8(image, tm);
    save_png_srgb8(path, image.width, image.height, bytes.data());
}

void save_exr(const fs::path& path, const Image& image) {
    check_image(image, path);
    // tinyexr's SaveEXR takes interleaved RGB and writes half floats by default;
    // use the full API to keep 32-bit floats.
    const std::size_t n = std::size_t(image.width) * std::size_t(image.height);
    std::vector<float> planes[3];
    for (int c = 0; c < 3; ++c) {
        planes[c].resize(n);
        for (std::size_t i = 0; i < n; ++i)
            planes[c][i] = image.rgb[i * 3 + std::size_t(c)];
    }
    EXRHeader header;
    InitEXRHeader(&header);
    EXRImage exr;
    InitEXRImage(&exr);
    // EXR stores channels in alphabetical order: B, G, R.
    float* ptrs[3] = {planes[2].data(), planes[1].data(), planes[0].data()};
    exr.images = reinterpret_cast<unsigned char**>(ptrs);
    exr.num_channels = 3;
    exr.width = image.width;
    exr.height = image.height;
    EXRChannelInfo channels[3];
    const char* names[3] = {"B", "G", "R"};
    int pixel_types[3] = {TINYEXR_PIXELTYPE_FLOAT, TINYEXR_PIXELTYPE_FLOAT, TINYEXR_PIXELTYPE_FLOAT};
    for (int c = 0; c < 3; ++c) {
        std::snprintf(channels[c].name, sizeof(channels[c].name), "%s", names[c]);
        channels[c].pixel_type = TINYEXR_PIXELTYPE_FLOAT;
        channels[c].p_linear = 0;
    }
    header.num_channels = 3;
    header.channels = channels;
    header.pixel_types = pixel_types;
    header.requested_pixel_types = pixel_types;
    header.compression_type = TINYEXR_COMPRESSIONTYPE_ZIP;
    write_file_atomic(path, [&](const fs::path& tmp) {
        const char* err = nullptr;
        if (SaveEXRImageToFile(&exr, &header, tmp.c_str(), &err) != TINYEXR_SUCCESS) {
            std::string msg = err ? err : "unknown tinyexr error";
            if (err)
                FreeEXRErrorMessage(err);
            throw Error(fmt::format("cannot write EXR: {}", msg), path.string());
        }
    });
}

void save_image(const fs::path& path, const Image& image, const ToneMap& tm) {
    const std::string ext = lower_extension(path);
    if (ext == ".exr")
        save_exr(path, image);
    else if (ext == ".png")
        save_png(path, image, tm);
    else
        throw Error(fmt::format("unknown image extension '{}'; use .png or .exr", ext), path.string());
}

namespace {

void check_pixels(std::int64_t w, std::int64_t h, std::uint64_t max_pixels, const char* what, const std::string& name) {
    if (w <= 0 || h <= 0)
        throw Error(fmt::format("{} image of {} x {} pixels", what, w, h), name);
    if (std::uint64_t(w) * std::uint64_t(h) > max_pixels)
        throw Error(fmt::format("{} image of {} x {} pixels is larger than the limit of {} pixels", what, w, h,
                                max_pixels),
                    name);
}

// JPEG through libjpeg-turbo (Debian's stb_image 2.27 writes past its
// Huffman tables on corrupt files, decodes with undefined tables and shifts
// by 32 bits when a scan runs out of bits). libjpeg reports errors through a
// callback that must not return: it jumps back here, past C frames only. A
// warning (corrupt data, a premature end) is an error too: no half-decoded
// image. Pixels are sRGB, decoded to linear like PNG's.
struct JpegErrors {
    jpeg_error_mgr mgr;
    std::jmp_buf jump;
    char message[JMSG_LENGTH_MAX];
};

[[noreturn]] void jpeg_fail(j_common_ptr c) {
    auto* e = reinterpret_cast<JpegErrors*>(c->err);
    (*c->err->format_message)(c, e->message);
    std::longjmp(e->jump, 1);
}

void jpeg_message(j_common_ptr c, int level) {
    if (level < 0) // a warning: the data is corrupt
        jpeg_fail(c);
}

// Decodes into rgb8 (width × height × 3), unless the header's size is over
// max_pixels (rgb8 stays empty: nothing that size is allocated). Returns an
// empty string, or libjpeg's message.
std::string decode_jpeg(const unsigned char* data, std::size_t size, std::uint64_t max_pixels,
                        std::vector<unsigned char>& rgb8, int& width, int& height) {
    jpeg_decompress_struct cinfo;
    JpegErrors errors;
    cinfo.err = jpeg_std_error(&errors.mgr);
    errors.mgr.error_exit = jpeg_fail;
    errors.mgr.emit_message = jpeg_message;
    if (setjmp(errors.jump)) {
        jpeg_destroy_decompress(&cinfo);
        return errors.message;
    }
    jpeg_create_decompress(&cinfo);
    jpeg_mem_src(&cinfo, data, static_cast<unsigned long>(size));
    jpeg_read_header(&cinfo, TRUE);
    width = int(cinfo.image_width);
    height = int(cinfo.image_height);
    if (width <= 0 || height <= 0 || std::uint64_t(width) * std::uint64_t(height) > max_pixels) {
        jpeg_destroy_decompress(&cinfo);
        return {};
    }
    cinfo.out_color_space = JCS_RGB;
    jpeg_start_decompress(&cinfo);
    rgb8.resize(std::size_t(width) * std::size_t(height) * 3);
    while (cinfo.output_scanline < cinfo.output_height) {
        JSAMPROW row = rgb8.data() + std::size_t(cinfo.output_scanline) * std::size_t(width) * 3;
        jpeg_read_scanlines(&cinfo, &row, 1);
    }
    jpeg_finish_decompress(&cinfo);
    jpeg_destroy_decompress(&cinfo);
    return {};
}

Image load_jpeg_from_memory(const unsigned char* data, std::size_t size, const std::string& name,
                            std::uint64_t max_pixels) {
    std::vector<unsigned char> rgb8;
    int w = 0, h = 0;
    const std::string message = decode_jpeg(data, size, max_pixels, rgb8, w, h);
    if (!message.empty())
        throw Error(fmt::format("cannot decode image: corrupt JPEG ({})", message), name);
    check_pixels(w, h, max_pixels, "the", name); // throws when decode_jpeg stopped at the header
    Image img(w, h);
    for (std::size_t i = 0; i < img.rgb.size(); ++i)
        img.rgb[i] = srgb_to_linear(float(rgb8[i]) / 255.0f);
    return img;
}

// stb_image allocates a PNG chunk's stated length before it reads the chunk:
// a 70-byte file that says its IDAT holds 1.4 GB allocates 1.4 GB. Every
// chunk must fit in the file, and the first IDAT must not be empty.
void check_png_chunks(const unsigned char* d, std::size_t size, const std::string& name) {
    std::size_t i = 8; // after the signature
    bool image_data = false;
    while (i + 8 <= size) {
        const std::uint64_t length = std::uint64_t(d[i]) << 24 | std::uint64_t(d[i + 1]) << 16 |
                                     std::uint64_t(d[i + 2]) << 8 | std::uint64_t(d[i + 3]);
        if (length + 12 > size - i)
            throw Error(fmt::format("truncated PNG: a chunk of {} bytes at byte {} of a file of {}", length, i, size),
                        name);
        if (std::memcmp(d + i + 4, "IEND", 4) == 0)
            return;
        // stb_image copies an empty first IDAT to a null buffer (memcpy(nullptr, p, 0)).
        if (std::memcmp(d + i + 4, "IDAT", 4) == 0) {
            if (length == 0 && !image_data)
                throw Error("PNG with an empty IDAT chunk before the image data: not supported", name);
            image_data = true;
        }
        i += std::size_t(length) + 12;
    }
}

Image load_exr_from_memory(const unsigned char* data, std::size_t size, const std::string& name,
                           std::uint64_t max_pixels) {
    // The header first: its data window says how much LoadEXRFromMemory allocates.
    EXRVersion version;
    if (ParseEXRVersionFromMemory(&version, data, size) != TINYEXR_SUCCESS)
        throw Error("cannot read EXR: not an OpenEXR file", name);
    if (version.multipart || version.non_image)
        throw Error("cannot read EXR: multi-part and deep images are not supported", name);
    EXRHeader header;
    InitEXRHeader(&header);
    const char* err = nullptr;
    if (ParseEXRHeaderFromMemory(&header, &version, data, size, &err) != TINYEXR_SUCCESS) {
        const std::string msg = err ? err : "unknown tinyexr error";
        if (err)
            FreeEXRErrorMessage(err);
        throw Error(fmt::format("cannot read EXR: {}", msg), name);
    }
    const std::int64_t w = std::int64_t(header.data_window.max_x) - header.data_window.min_x + 1;
    const std::int64_t h = std::int64_t(header.data_window.max_y) - header.data_window.min_y + 1;
    FreeEXRHeader(&header);
    check_pixels(w, h, max_pixels, "EXR", name);
    float* rgba = nullptr;
    int iw = 0, ih = 0;
    if (LoadEXRFromMemory(&rgba, &iw, &ih, data, size, &err) != TINYEXR_SUCCESS) {
        const std::string msg = err ? err : "unknown tinyexr error";
        if (err)
            FreeEXRErrorMessage(err);
        throw Error(fmt::format("cannot read EXR: {}", msg), name);
    }
    std::unique_ptr<float, decltype(&std::free)> guard(rgba, &std::free);
    check_pixels(iw, ih, max_pixels, "EXR", name);
    Image img(iw, ih);
    for (std::size_t i = 0; i < std::size_t(iw) * std::size_t(ih); ++i)
        for (int c = 0; c < 3; ++c)
            img.rgb[i * 3 + std::size_t(c)] = rgba[i * 4 + std::size_t(c)];
    return img;
}

} // namespace

Image load_image_from_memory(const void* data, std::size_t size, const std::string& format, const std::string& name,
                             std::uint64_t max_pixels) {
    std::string f = format;
    std::transform(f.begin(), f.end(), f.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    if (!f.empty() && f[0] == '.')
        f.erase(0, 1);
    if (size == 0)
        throw Error("the image file is empty", name);
    const auto* bytes = static_cast<const unsigned char*>(data);
    if (f == "exr")
        return load_exr_from_memory(bytes, size, name, max_pixels);
    if (size > std::size_t(INT_MAX))
        throw Error(fmt::format("an image file of {} bytes is too large", size), name);
    if (size >= 2 && bytes[0] == 0xFF && bytes[1] == 0xD8)
        return load_jpeg_from_memory(bytes, size, name, max_pixels);
    if (size >= 8 && std::memcmp(bytes, "\x89PNG\r\n\x1a\n", 8) == 0)
        check_png_chunks(bytes, size, name);
    int w = 0, h = 0, comp = 0;
    // The header first: stb_image allocates what it says before reading the pixels.
    if (!stbi_info_from_memory(bytes, int(size), &w, &h, &comp))
        throw Error(fmt::format("cannot decode image: {}", stbi_failure_reason()), name);
    check_pixels(w, h, max_pixels, f == "hdr" ? "Radiance HDR" : "the", name);
    if (f == "hdr") { // Radiance RGBE: linear radiance
        // stb_image reads the pixels of a truncated file as zeros: a header
        // alone would be a black map of any size. Each scanline takes at
        // least 4 bytes a pixel, or run-length encoded 4 bytes and 2 per run
        // of up to 127 pixels in each of 4 channels (8 to 32767 pixels wide).
        const std::uint64_t flat = 4 * std::uint64_t(w);
        const std::uint64_t rle = w >= 8 && w < 32768 ? 4 + 8 * ((std::uint64_t(w) + 126) / 127) : flat;
        const std::uint64_t least = std::uint64_t(h) * std::min(flat, rle);
        if (size < least)
            throw Error(fmt::format("truncated Radiance HDR image: {} x {} pixels take at least {} bytes; the file "
                                    "has {}",
                                    w, h, least, size),
                        name);
        float* px = stbi_loadf_from_memory(bytes, int(size), &w, &h, &comp, 3);
        if (!px)
            throw Error(fmt::format("cannot decode Radiance HDR image: {}", stbi_failure_reason()), name);
        std::unique_ptr<float, void (*)(void*)> guard(px, stbi_image_free);
        check_pixels(w, h, max_pixels, "Radiance HDR", name);
        Image img(w, h);
        std::copy(px, px + img.rgb.size(), img.rgb.begin());
        return img;
    }
    unsigned char* px = stbi_load_from_memory(bytes, int(size), &w, &h, &comp, 3);
    if (!px)
        throw Error(fmt::format("cannot decode image: {}", stbi_failure_reason()), name);
    std::unique_ptr<unsigned char, void (*)(void*)> guard(px, stbi_image_free);
    check_pixels(w, h, max_pixels, "the", name);
    Image img(w, h);
    for (std::size_t i = 0; i < img.rgb.size(); ++i)
        img.rgb[i] = srgb_to_linear(float(px[i]) / 255.0f);
    return img;
}

Image load_image(const fs::path& path) {
    const std::string ext = lower_extension(path);
    std::error_code ec;
    if (!fs::exists(path, ec))
        throw Error("file not found", path.string());
    const std::string data = read_file(path, std::uint64_t(1) << 30);
    return load_image_from_memory(data.data(), data.size(), ext, path.string());
}

} // namespace skybake
