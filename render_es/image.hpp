#pragma once
// RGBA8 images: PNG files (stb_image_write / stb_image) and the tolerant
// comparison the golden-image tests use, so llvmpipe versions do not flake.
#include <cstdint>
#include <string>
#include <vector>

namespace marionette::render {

struct Image {
    std::int32_t width = 0;
    std::int32_t height = 0;
    std::vector<std::uint8_t> rgba;  // top row first
};

// Throws std::runtime_error naming the file.
void write_png(const std::string& path, const Image& image);
// Throws std::runtime_error naming the file and what stb_image said.
Image read_png(const std::string& path);

// Box-filters down by an integer factor (so a golden image can be rendered large
// with MSAA and compared small). factor must divide both sides.
Image downsample(const Image& image, std::int32_t factor);

struct ImageDifference {
    bool same_size = false;
    std::int64_t differing_pixels = 0;   // some channel differs by more than the tolerance
    double differing_fraction = 0.0;
    int max_channel_difference = 0;
    Image diff;                          // differing pixels red over a dimmed copy of `expected`
};

ImageDifference compare_images(const Image& expected, const Image& actual, int channel_tolerance);

}  // namespace marionette::render
