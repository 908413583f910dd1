#include "core/image.hpp"

#include <cmath>

#include "core/error.hpp"

#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STBI_FAILURE_USERMSG
#include <stb_image.h>
#include <stb_image_write.h>

namespace rtr {

TexelData loadImage(const std::filesystem::path& file, int channels) {
  int w = 0, h = 0, n = 0;
  stbi_uc* data = stbi_load(file.c_str(), &w, &h, &n, channels);
  if (!data) throw fileError(file.string(), "", std::string("cannot decode image: ") + stbi_failure_reason());
  TexelData out{uint32_t(w), uint32_t(h), uint32_t(channels), {}};
  out.texels.assign(data, data + size_t(w) * h * channels);
  stbi_image_free(data);
  return out;
}

float srgbToLinear(float c) { return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f); }
float linearToSrgb(float c) { return c <= 0.0031308f ? c * 12.92f : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f; }

ImageRGBA8 toSrgb8(const ImageF& linear) {
  ImageRGBA8 out{linear.width, linear.height, std::vector<uint8_t>(size_t(linear.width) * linear.height * 4)};
  auto q = [](float v) { return uint8_t(std::lround(std::fmin(std::fmax(v, 0.0f), 1.0f) * 255.0f)); };
  for (size_t i = 0; i < linear.pixels.size(); ++i) {
    const glm::vec4 p = linear.pixels[i];
    for (int c = 0; c < 3; ++c) out.pixels[i * 4 + c] = q(linearToSrgb(std::fmin(std::fmax(p[c], 0.0f), 1.0f)));
    out.pixels[i * 4 + 3] = q(p.a);
  }
  return out;
}

}  // namespace rtr
