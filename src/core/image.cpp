#include "core/image.hpp"

#include <algorithm>
#include <csetjmp>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <new>
#include <span>

#include <jpeglib.h>
#include <jerror.h>
#include <png.h>

#include "core/error.hpp"
#include "core/input_file.hpp"

#include <stb_image.h>  // the implementation is compiled in stb.cpp

namespace rtr {

namespace {

// libjpeg reports errors through a callback that must not return: jump back to the decoder.
struct JpegError {
  jpeg_error_mgr mgr;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};

#ifdef FUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION
constexpr uint32_t kMaxImageSide = 128;  // as stb.cpp: large images only slow the fuzzers down
#else
constexpr uint32_t kMaxImageSide = 32768;
#endif

// JPEG through libjpeg-turbo: stb_image 2.27 (Debian 12) writes out of bounds on some malformed Huffman
// tables (found by fuzzing), and libjpeg-turbo is the faster decoder anyway. A file whose data ends early
// is refused, not padded with grey: libjpeg calls that a warning, and a 650-byte file declaring 30000²
// pixels then decoded into gigabytes of filler (found by fuzzing). The texels grow row by row, so such a
// header costs no more than the rows its data really holds.
bool decodeJpeg(std::span<const uint8_t> bytes, int channels, TexelData& out, std::string& error) {
  jpeg_decompress_struct cinfo{};
  JpegError err{};
  cinfo.err = jpeg_std_error(&err.mgr);
  err.mgr.error_exit = [](j_common_ptr c) {
    JpegError* e = reinterpret_cast<JpegError*>(c->err);
    (*c->err->format_message)(c, e->message);
    std::longjmp(e->jump, 1);
  };
  err.mgr.emit_message = [](j_common_ptr c, int level) {  // other warnings (recovered damage) stay quiet
    if (level < 0 && (c->err->msg_code == JWRN_JPEG_EOF || c->err->msg_code == JWRN_HIT_MARKER)) c->err->error_exit(c);
  };
  std::vector<unsigned char> rgb;  // declared before setjmp: nothing with a destructor is made after it
  if (setjmp(err.jump)) {
    jpeg_destroy_decompress(&cinfo);
    error = err.message;
    return false;
  }
  jpeg_create_decompress(&cinfo);
  jpeg_mem_src(&cinfo, bytes.data(), static_cast<unsigned long>(bytes.size()));
  jpeg_read_header(&cinfo, TRUE);
  if (cinfo.image_width > kMaxImageSide || cinfo.image_height > kMaxImageSide) {
    std::snprintf(err.message, sizeof err.message, "%ux%u is larger than %u a side", cinfo.image_width, cinfo.image_height,
                  kMaxImageSide);
    std::longjmp(err.jump, 1);
  }
  const bool grey = channels <= 2;  // 1: grey, 2: grey + alpha, 3: RGB, 4: RGBA (alpha opaque)
  cinfo.out_color_space = grey ? JCS_GRAYSCALE : JCS_RGB;
  jpeg_start_decompress(&cinfo);
  const uint32_t w = cinfo.output_width, h = cinfo.output_height, n = uint32_t(cinfo.output_components);
  const size_t row = size_t(w) * n;
  rgb.reserve(std::min(row * h, bytes.size() * 64 + (size_t(16) << 20)));  // the rest grows as rows come
  while (cinfo.output_scanline < h) {
    rgb.resize(rgb.size() + row);
    JSAMPROW p = rgb.data() + size_t(cinfo.output_scanline) * row;
    jpeg_read_scanlines(&cinfo, &p, 1);
  }
  jpeg_finish_decompress(&cinfo);
  jpeg_destroy_decompress(&cinfo);
  out = {w, h, uint32_t(channels), std::vector<uint8_t>(size_t(w) * h * channels)};
  for (size_t i = 0, p = size_t(w) * h; i < p; ++i)
    for (uint32_t c = 0; c < uint32_t(channels); ++c) out.texels[i * channels + c] = c < n ? rgb[i * n + c] : 255;
  return true;
}

// PNG through libpng: stb_image 2.27 reads past the end of a zlib stream as zero bits, so a 50-byte PNG
// (found by fuzzing) decodes "forever", growing its buffer to 1.7 GB. libpng stops at the end of the data.
// The transforms give what stb gave: palette and tRNS expanded, 1/2/4-bit grey scaled, 16 bits truncated
// to 8, gamma ignored; the channel count is then converted by stb's rules (convertChannels).

struct PngReader {
  std::span<const uint8_t> bytes;
  size_t at = 0;
  std::string error;
};

// stb's luma (stbi__compute_y) and channel conversion, so PNG texels stay what they were under stb.
uint8_t luma(uint8_t r, uint8_t g, uint8_t b) { return uint8_t((r * 77 + g * 150 + 29 * b) >> 8); }

void convertChannels(const std::vector<uint8_t>& in, uint32_t n, TexelData& out) {
  const uint32_t m = out.channels;
  for (size_t i = 0, p = size_t(out.width) * out.height; i < p; ++i) {
    const uint8_t* s = &in[i * n];
    uint8_t* d = &out.texels[i * m];
    const bool grey = n <= 2;
    const uint8_t y = grey ? s[0] : luma(s[0], s[1], s[2]);
    const uint8_t a = n == 2 ? s[1] : n == 4 ? s[3] : 255;
    if (m <= 2) {
      d[0] = y;
    } else {
      for (int c = 0; c < 3; ++c) d[c] = grey ? s[0] : s[c];
    }
    if (m == 2) d[1] = a;
    if (m == 4) d[3] = a;
  }
}

bool decodePng(std::span<const uint8_t> bytes, int channels, TexelData& out, std::string& error) {
  PngReader reader{bytes};
  png_structp png = png_create_read_struct(
      PNG_LIBPNG_VER_STRING, &reader,
      [](png_structp p, png_const_charp msg) {
        static_cast<PngReader*>(png_get_error_ptr(p))->error = msg;
        png_longjmp(p, 1);
      },
      [](png_structp, png_const_charp) {});  // warnings (recoverable damage) stay quiet
  if (!png) return error = "out of memory", false;
  png_infop info = png_create_info_struct(png);
  std::vector<uint8_t> decoded;  // declared before setjmp: nothing with a destructor is made after it
  std::vector<png_bytep> rows;
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    error = reader.error.empty() ? "not a valid PNG" : reader.error;
    return false;
  }
  if (!info) png_error(png, "out of memory");
  png_set_read_fn(png, &reader, [](png_structp p, png_bytep data, size_t size) {
    PngReader& r = *static_cast<PngReader*>(png_get_io_ptr(p));
    if (size > r.bytes.size() - r.at) png_error(p, "the file ends inside the image data");
    std::memcpy(data, r.bytes.data() + r.at, size);
    r.at += size;
  });
  png_set_user_limits(png, kMaxImageSide, kMaxImageSide);
#ifdef FUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION
  // Mutated files almost never carry valid checksums: let the fuzzers past them to the decoder.
  png_set_crc_action(png, PNG_CRC_QUIET_USE, PNG_CRC_QUIET_USE);
  png_set_option(png, PNG_IGNORE_ADLER32, PNG_OPTION_ON);
#endif
  png_read_info(png, info);
  png_set_palette_to_rgb(png);
  png_set_expand_gray_1_2_4_to_8(png);
  if (png_get_valid(png, info, PNG_INFO_tRNS)) png_set_tRNS_to_alpha(png);
  png_set_strip_16(png);
  const int passes = png_set_interlace_handling(png);
  (void)passes;
  png_read_update_info(png, info);
  const uint32_t w = png_get_image_width(png, info), h = png_get_image_height(png, info);
  const uint32_t n = png_get_channels(png, info);
  if (n < 1 || n > 4 || png_get_rowbytes(png, info) != size_t(w) * n) png_error(png, "unsupported PNG layout");
  // Deflate packs at most about 1032 bytes into one: a header declaring more rows than the file can hold
  // is refused before its texels are allocated (a 100-byte file may declare 32768² pixels).
  if ((size_t(w) * n + 1) * h / 1032 > bytes.size()) {
    reader.error = std::to_string(w) + "x" + std::to_string(h) + " pixels cannot come from a file of " +
                   std::to_string(bytes.size()) + " bytes";
    png_error(png, reader.error.c_str());
  }
  out = {w, h, uint32_t(channels), {}};
  std::vector<uint8_t>& target = n == uint32_t(channels) ? out.texels : decoded;  // converted after, if need be
  target.resize(size_t(w) * h * n);
  rows.resize(h);
  for (uint32_t y = 0; y < h; ++y) rows[y] = target.data() + size_t(y) * w * n;
  png_read_image(png, rows.data());
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  if (n != uint32_t(channels)) {
    out.texels.resize(size_t(w) * h * channels);
    convertChannels(decoded, n, out);
  }
  return true;
}

}  // namespace

TexelData decodeImage(std::span<const uint8_t> bytes, const std::string& name, int channels) try {
  if (bytes.size() >= 2 && bytes[0] == 0xFF && bytes[1] == 0xD8) {  // a JPEG start-of-image marker
    TexelData out;
    std::string error;
    if (!decodeJpeg(bytes, channels, out, error)) throw fileError(name, "", "cannot decode JPEG: " + error);
    return out;
  }
  if (bytes.size() >= 8 && png_sig_cmp(bytes.data(), 0, 8) == 0) {
    TexelData out;
    std::string error;
    if (!decodePng(bytes, channels, out, error)) throw fileError(name, "", "cannot decode PNG: " + error);
    return out;
  }
  const int size = int(std::min<size_t>(bytes.size(), INT32_MAX));
  int w = 0, h = 0, n = 0;
  if (stbi_info_from_memory(bytes.data(), size, &w, &h, &n) && (uint32_t(w) > kMaxImageSide || uint32_t(h) > kMaxImageSide))
    throw fileError(name, "",
                    "cannot decode image: " + std::to_string(w) + "x" + std::to_string(h) + " is larger than " +
                        std::to_string(kMaxImageSide) + " a side");
  stbi_uc* data = stbi_load_from_memory(bytes.data(), size, &w, &h, &n, channels);
  if (!data) {  // stb can fail without a reason
    const char* why = stbi_failure_reason();
    throw fileError(name, "", std::string("cannot decode image: ") + (why ? why : "not a supported image"));
  }
  TexelData out{uint32_t(w), uint32_t(h), uint32_t(channels), {}};
  try {
    out.texels.assign(data, data + size_t(w) * h * channels);
  } catch (...) {
    stbi_image_free(data);
    throw;
  }
  stbi_image_free(data);
  return out;
} catch (const std::bad_alloc&) { throw fileError(name, "", "out of memory while decoding the image"); }

TexelData loadImage(const std::filesystem::path& file, int channels) {
  const MappedFile mapped(file, "image");  // a regular file; pages read only as the decoder gets to them
  return decodeImage(mapped.bytes(), file.string(), channels);
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
