// skybake/image_io.h: PNG, EXR and JPEG files of the images of
// skybake/image.h (the io module).
//
// [SECTION] Files
//
// EXR files keep the linear values. PNG files are 8-bit sRGB: linear values
// go through tone_map() first (see docs/images.md).
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "skybake/image.h"

namespace skybake {

// [SECTION] Files -----------------------------------------------------------------
// Writes by extension: ".exr" (linear float, lossless ZIP) or ".png" (8-bit
// sRGB through tm). Written to a temporary file and renamed when complete.
// Throws skybake::Error on an unknown extension, an empty image or I/O failure.
void save_image(const std::filesystem::path& path, const Image& image, const ToneMap& tm = {});
void save_exr(const std::filesystem::path& path, const Image& image);
void save_png(const std::filesystem::path& path, const Image& image, const ToneMap& tm = {});
// Writes an 8-bit sRGB buffer (3 bytes per pixel) as PNG.
void save_png_srgb8(const std::filesystem::path& path, int width, int height, const std::uint8_t* rgb);

// Writes one channel of linear values in [0, 1] (clamped; width * height,
// row-major, top row first) as a 16-bit greyscale PNG, without the sRGB
// curve: data such as an occlusion texture, which glTF reads linearly.
void save_png16_gray(const std::filesystem::path& path, int width, int height, const std::vector<float>& values);
// The same PNG, in memory (to embed in a .glb). Throws skybake::Error ("values").
std::string encode_png16_gray(int width, int height, const std::vector<float>& values);
// An 8-bit PNG of `channels` (1 grey, 3 RGB, 4 RGBA) interleaved samples per
// pixel, row-major, top row first, in memory. Throws skybake::Error ("values").
std::string encode_png8(int width, int height, int channels, const std::vector<std::uint8_t>& samples);

// Reads an EXR or a Radiance .hdr (linear) or a PNG/JPEG (sRGB, decoded to linear).
// Throws skybake::Error on a missing or corrupt file, and on one whose
// header claims more than kMaxImagePixels pixels.
Image load_image(const std::filesystem::path& path);

// The largest image load_image() reads (a 16384 x 8192 map): the header is
// checked before any pixel is allocated, so that a few hostile bytes cannot
// make the loader allocate gigabytes.
inline constexpr std::uint64_t kMaxImagePixels = std::uint64_t(1) << 27;

// load_image() from a file's bytes. format: the file's extension ("exr",
// "hdr", "png", "jpg"; any case, with or without the dot): EXR goes to
// tinyexr, HDR to stb_image as linear floats, anything else to stb_image as
// 8-bit sRGB. name stands for the file in errors. Throws skybake::Error on an
// empty, corrupt or too large image (more than max_pixels).
Image load_image_from_memory(const void* data, std::size_t size, const std::string& format, const std::string& name,
                             std::uint64_t max_pixels = kMaxImagePixels);

} // namespace skybake
