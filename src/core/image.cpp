#include "core/image.hpp"

#include <csetjmp>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>

#include <jpeglib.h>

#include "core/error.hpp"

#include <stb_image.h>  // the implementation is compiled in stb.cpp

namespace rtr {

namespace {

// libjpeg reports errors through a callback that must not return: jump back to the decoder.
struct JpegError {
  jpeg_error_mgr mgr;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};

// JPEG through libjpeg-turbo: stb_image 2.27 (Debian 12) writes out of bounds on some malformed Huffman
// tables (found by fuzzing), and libjpeg-turbo is the faster decoder anyway.
bool decodeJpeg(const std::vector<unsigned char>& bytes, int channels, TexelData& out, std::string& error) {
  jpeg_decompress_struct cinfo{};
  JpegError err{};
  cinfo.err = jpeg_std_error(&err.mgr);
  err.mgr.error_exit = [](j_common_ptr c) {
    JpegError* e = reinterpret_cast<JpegError*>(c->err);
    (*c->err->format_message)(c, e->message);
    std::longjmp(e->jump, 1);
  };
  err.mgr.output_message = [](j_common_ptr) {};  // warnings (corrupt data recovered from) stay quiet
  std::vector<unsigned char> rgb;  // declared before setjmp: nothing with a destructor is made after it
  if (setjmp(err.jump)) {
    jpeg_destroy_decompress(&cinfo);
    error = err.message;
    return false;
  }
  jpeg_create_decompress(&cinfo);
  jpeg_mem_src(&cinfo, bytes.data(), static_cast<unsigned long>(bytes.size()));
  jpeg_read_header(&cinfo, TRUE);
  const bool grey = channels <= 2;  // 1: grey, 2: grey + alpha, 3: RGB, 4: RGBA (alpha opaque)
  cinfo.out_color_space = grey ? JCS_GRAYSCALE : JCS_RGB;
  jpeg_start_decompress(&cinfo);
  const uint32_t w = cinfo.output_width, h = cinfo.output_height, n = uint32_t(cinfo.output_components);
  rgb.resize(size_t(w) * h * n);
  while (cinfo.output_scanline < h) {
    JSAMPROW row = rgb.data() + size_t(cinfo.output_scanline) * w * n;
    jpeg_read_scanlines(&cinfo, &row, 1);
  }
  jpeg_finish_decompress(&cinfo);
  jpeg_destroy_decompress(&cinfo);
  out = {w, h, uint32_t(channels), std::vector<uint8_t>(size_t(w) * h * channels)};
  for (size_t i = 0, p = size_t(w) * h; i < p; ++i)
    for (uint32_t c = 0; c < uint32_t(channels); ++c) out.texels[i * channels + c] = c < n ? rgb[i * n + c] : 255;
  return true;
}

}  // namespace

TexelData loadImage(const std::filesystem::path& file, int channels) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw fileError(file.string(), "", "cannot open image");
  const std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw fileError(file.string(), "", "read error");
  if (bytes.size() >= 2 && bytes[0] == 0xFF && bytes[1] == 0xD8) {  // a JPEG start-of-image marker
    TexelData out;
    std::string error;
    if (!decodeJpeg(bytes, channels, out, error)) throw fileError(file.string(), "", "cannot decode JPEG: " + error);
    return out;
  }
  int w = 0, h = 0, n = 0;
  stbi_uc* data = stbi_load_from_memory(bytes.data(), int(std::min<size_t>(bytes.size(), INT32_MAX)), &w, &h, &n, channels);
  if (!data) {  // stb can fail without a reason
    const char* why = stbi_failure_reason();
    throw fileError(file.string(), "", std::string("cannot decode image: ") + (why ? why : "not a supported image"));
  }
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
