#include "render_es/image.hpp"

#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#include <stb/stb_image.h>

#include <algorithm>
#include <cstdlib>
#include <stdexcept>

namespace marionette::render {

void write_png(const std::string& path, const Image& image) {
    if (image.width <= 0 || image.height <= 0 ||
        image.rgba.size() != static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height) * 4)
        throw std::runtime_error(path + ": cannot write an empty or mis-sized image");
    if (stbi_write_png(path.c_str(), image.width, image.height, 4, image.rgba.data(), image.width * 4) == 0)
        throw std::runtime_error(path + ": cannot write PNG");
}

Image read_png(const std::string& path) {
    int w = 0;
    int h = 0;
    int channels = 0;
    stbi_uc* pixels = stbi_load(path.c_str(), &w, &h, &channels, 4);
    if (pixels == nullptr) throw std::runtime_error(path + ": cannot read PNG (" + stbi_failure_reason() + ")");
    Image image;
    image.width = w;
    image.height = h;
    image.rgba.assign(pixels, pixels + static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 4);
    stbi_image_free(pixels);
    return image;
}

Image downsample(const Image& image, std::int32_t factor) {
    if (factor <= 1) return image;
    if (image.width % factor != 0 || image.height % factor != 0)
        throw std::invalid_argument("downsample factor must divide the image size");
    Image out;
    out.width = image.width / factor;
    out.height = image.height / factor;
    out.rgba.resize(static_cast<std::size_t>(out.width) * static_cast<std::size_t>(out.height) * 4);
    const int area = factor * factor;
    for (int y = 0; y < out.height; ++y)
        for (int x = 0; x < out.width; ++x)
            for (int c = 0; c < 4; ++c) {
                int sum = 0;
                for (int dy = 0; dy < factor; ++dy)
                    for (int dx = 0; dx < factor; ++dx)
                        sum += image.rgba[(static_cast<std::size_t>(y * factor + dy) * static_cast<std::size_t>(image.width) +
                                           static_cast<std::size_t>(x * factor + dx)) * 4 + static_cast<std::size_t>(c)];
                out.rgba[(static_cast<std::size_t>(y) * static_cast<std::size_t>(out.width) + static_cast<std::size_t>(x)) * 4 +
                         static_cast<std::size_t>(c)] = static_cast<std::uint8_t>((sum + area / 2) / area);
            }
    return out;
}

ImageDifference compare_images(const Image& expected, const Image& actual, int tolerance) {
    ImageDifference d;
    d.same_size = expected.width == actual.width && expected.height == actual.height &&
                  expected.rgba.size() == actual.rgba.size();
    if (!d.same_size) return d;
    d.diff = expected;
    const std::size_t pixels = expected.rgba.size() / 4;
    for (std::size_t i = 0; i < pixels; ++i) {
        int worst = 0;
        for (std::size_t c = 0; c < 4; ++c)
            worst = std::max(worst, std::abs(int(expected.rgba[i * 4 + c]) - int(actual.rgba[i * 4 + c])));
        d.max_channel_difference = std::max(d.max_channel_difference, worst);
        std::uint8_t* out = &d.diff.rgba[i * 4];
        if (worst > tolerance) {
            ++d.differing_pixels;
            out[0] = 255;
            out[1] = 0;
            out[2] = 0;
        } else {
            for (int c = 0; c < 3; ++c) out[c] = static_cast<std::uint8_t>(out[c] / 3);
        }
        out[3] = 255;
    }
    d.differing_fraction = pixels ? static_cast<double>(d.differing_pixels) / static_cast<double>(pixels) : 0.0;
    return d;
}

}  // namespace marionette::render
