// Image files out: PNG (our own zlib encoder, strips compressed in parallel), JPEG and Radiance HDR
// (stb), OpenEXR (tinyexr). Every one is written through AtomicFile.
#include <zlib.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <thread>

#include <unistd.h>

#include <stb_image_write.h>
#include <tinyexr.h>

#include "core/error.hpp"
#include "core/image.hpp"
#include "core/parallel.hpp"

namespace rtr {
namespace {

// After a second of writing, a line on stderr that says how far it is (a 16384² PNG takes seconds).
class ProgressLine {
 public:
  ProgressLine(bool on, const std::filesystem::path& file) {
    if (on) watcher_ = std::thread([this, name = file.string()] { watch(name); });
  }
  ~ProgressLine() {
    {
      std::lock_guard l(m_);
      done_ = true;
    }
    cv_.notify_all();
    if (watcher_.joinable()) watcher_.join();
  }
  std::atomic<double> fraction{0.0};

 private:
  void watch(const std::string& name) {
    using namespace std::chrono;
    const auto start = steady_clock::now();
    std::unique_lock l(m_);
    if (cv_.wait_for(l, seconds(1), [&] { return done_; })) return;
    const bool tty = ::isatty(STDERR_FILENO);  // a log gets one line, not a percentage every 250 ms
    if (!tty) std::fprintf(stderr, "writing %s ...\n", name.c_str());
    do
      if (tty) std::fprintf(stderr, "\rwriting %s: %3.0f%%", name.c_str(), fraction.load() * 100.0);
    while (!cv_.wait_for(l, milliseconds(250), [&] { return done_; }));
    std::fprintf(stderr, "%swriting %s: done in %.1f s\n", tty ? "\r" : "", name.c_str(),
                 duration<double>(steady_clock::now() - start).count());
  }
  std::thread watcher_;
  std::mutex m_;
  std::condition_variable cv_;
  bool done_ = false;
};

void put32(std::string& s, uint32_t v) {
  const char b[4] = {char(v >> 24), char(v >> 16), char(v >> 8), char(v)};
  s.append(b, 4);
}

void chunk(AtomicFile& f, const char type[4], const void* data, size_t size) {
  std::string head;
  put32(head, uint32_t(size));
  head.append(type, 4);
  uLong crc = crc32(0, reinterpret_cast<const Bytef*>(type), 4);
  crc = crc32_z(crc, static_cast<const Bytef*>(data), size);
  f.write(head.data(), head.size());
  f.write(data, size);
  std::string tail;
  put32(tail, uint32_t(crc));
  f.write(tail.data(), tail.size());
}

// PNG with the "up" filter on every row and zlib level 1: measured the fastest at a size within a few
// per cent of adaptive filtering (docs/viewer.md). Horizontal strips are deflated on all cores as
// independent pieces of one zlib stream (each ends on a sync flush; their Adler-32s are combined). The
// strips are as many whatever the core count, so the file's bytes do not depend on the machine.
void writePng(AtomicFile& f, const ImageRGBA8& img, ProgressLine& progress) {
  const size_t row = size_t(img.width) * 4, h = img.height;
  const size_t strips = std::min<size_t>(h, 64);
  std::vector<std::string> out(strips);
  std::vector<uLong> adler(strips);
  std::atomic<size_t> rowsDone{0};
  std::atomic<bool> failed{false};
  parallelFor(strips, std::min(threadCount(), 16u), [&](size_t s) {
    std::vector<Bytef> buf((row + 1) * 16);
    const size_t y0 = h * s / strips, y1 = h * (s + 1) / strips;
    z_stream z{};
    if (deflateInit2(&z, 1, Z_DEFLATED, -15, 8, Z_DEFAULT_STRATEGY) != Z_OK)
      throw fileError(f.target().string(), "", "PNG compression failed");
    out[s].resize(deflateBound(&z, (row + 1) * (y1 - y0)) + 64);
    z.next_out = reinterpret_cast<Bytef*>(out[s].data());
    z.avail_out = uInt(out[s].size());
    adler[s] = adler32(0, nullptr, 0);
    for (size_t y = y0; y < y1; y += 16) {
      const size_t ye = std::min(y1, y + 16);
      Bytef* o = buf.data();
      for (size_t yy = y; yy < ye; ++yy, o += row + 1) {
        const uint8_t* c = img.pixels.data() + row * yy;
        o[0] = yy ? 2 : 0;  // up; the first row has nothing above
        if (yy)
          for (size_t i = 0; i < row; ++i) o[1 + i] = Bytef(c[i] - c[i - row]);
        else std::memcpy(o + 1, c, row);
      }
      z.next_in = buf.data();
      z.avail_in = uInt(o - buf.data());
      adler[s] = adler32_z(adler[s], buf.data(), z.avail_in);
      const int flush = ye < y1 ? Z_NO_FLUSH : s + 1 == strips ? Z_FINISH : Z_SYNC_FLUSH;
      const int r = deflate(&z, flush);
      if (r == Z_STREAM_ERROR || z.avail_in != 0) failed = true;
      progress.fraction = double(rowsDone += ye - y) / double(h);
    }
    out[s].resize(z.total_out);
    deflateEnd(&z);
  });
  if (failed) throw fileError(f.target().string(), "", "PNG compression failed");

  static const uint8_t signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  f.write(signature, 8);
  std::string ihdr;
  put32(ihdr, img.width);
  put32(ihdr, img.height);
  ihdr += {8, 6, 0, 0, 0};  // 8 bits, RGBA, deflate, adaptive filtering, no interlace
  chunk(f, "IHDR", ihdr.data(), ihdr.size());
  uLong total = adler32(0, nullptr, 0);
  const std::string zhead = {0x78, 0x01};  // deflate, 32 KiB window, "fastest" level
  chunk(f, "IDAT", zhead.data(), zhead.size());
  for (size_t s = 0; s < strips; ++s) {
    const size_t len = h * (s + 1) / strips - h * s / strips;
    total = adler32_combine(total, adler[s], z_off_t(len * (row + 1)));
    for (size_t at = 0; at < out[s].size(); at += size_t(1) << 30)  // chunks hold < 2^31 bytes
      chunk(f, "IDAT", out[s].data() + at, std::min(out[s].size() - at, size_t(1) << 30));
    std::string().swap(out[s]);
  }
  std::string ztail;
  put32(ztail, uint32_t(total));
  chunk(f, "IDAT", ztail.data(), ztail.size());
  chunk(f, "IEND", "", 0);
}

struct StbSink {
  AtomicFile* file;
  bool failed = false;
  std::string error;
};
extern "C" void stbWrite(void* ctx, void* data, int size) {
  auto* s = static_cast<StbSink*>(ctx);
  if (s->failed) return;
  try {
    s->file->write(data, size_t(size));
  } catch (const std::exception& e) {
    s->failed = true;
    s->error = e.what();
  }
}

void checkStb(int ok, const StbSink& sink, AtomicFile& f, const char* what) {
  if (sink.failed) throw Error(sink.error);
  if (!ok) throw fileError(f.target().string(), "", std::string("cannot encode ") + what);
}

// Linear RGB(A) floats, 4 channels a pixel.
void writeFloat(AtomicFile& f, ImageFormat fmt, uint32_t w, uint32_t h, const float* rgba) {
  if (fmt == ImageFormat::Hdr) {
    StbSink sink{&f};
    checkStb(stbi_write_hdr_to_func(stbWrite, &sink, int(w), int(h), 4, rgba), sink, f, "Radiance HDR");
    return;
  }
  // OpenEXR: 32-bit float channels, stored in the A, B, G, R order readers expect.
  const size_t n = size_t(w) * h;
  std::vector<float> planes[4];
  for (int c = 0; c < 4; ++c) {
    planes[c].resize(n);
    for (size_t i = 0; i < n; ++i) planes[c][i] = rgba[i * 4 + (3 - c)];
  }
  float* ptrs[4] = {planes[0].data(), planes[1].data(), planes[2].data(), planes[3].data()};
  EXRImage image;
  InitEXRImage(&image);
  image.images = reinterpret_cast<unsigned char**>(ptrs);
  image.width = int(w);
  image.height = int(h);
  image.num_channels = 4;
  EXRHeader header;
  InitEXRHeader(&header);
  EXRChannelInfo channels[4]{};
  int types[4], requested[4];
  for (int c = 0; c < 4; ++c) {
    channels[c].name[0] = "ABGR"[c];
    types[c] = requested[c] = TINYEXR_PIXELTYPE_FLOAT;
  }
  header.num_channels = 4;
  header.channels = channels;
  header.pixel_types = types;
  header.requested_pixel_types = requested;
  header.compression_type = TINYEXR_COMPRESSIONTYPE_ZIP;
  unsigned char* mem = nullptr;
  const char* err = nullptr;
  const size_t size = SaveEXRImageToMemory(&image, &header, &mem, &err);
  if (size == 0) {
    const std::string why = err ? err : "unknown error";
    if (err) FreeEXRErrorMessage(err);
    throw fileError(f.target().string(), "", "cannot encode OpenEXR: " + why);
  }
  try {
    f.write(mem, size);
  } catch (...) {
    std::free(mem);
    throw;
  }
  std::free(mem);
}

void checkSize(const std::filesystem::path& file, uint32_t w, uint32_t h) {
  if (w == 0 || h == 0 || w > (1u << 20) || h > (1u << 20))
    throw fileError(file.string(), "", "cannot write an image of " + std::to_string(w) + "x" + std::to_string(h));
}

}  // namespace

ImageFormat imageFormatFor(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".png") return ImageFormat::Png;
  if (ext == ".jpg" || ext == ".jpeg") return ImageFormat::Jpg;
  if (ext == ".exr") return ImageFormat::Exr;
  if (ext == ".hdr") return ImageFormat::Hdr;
  throw UsageError(file.string() + ": unknown image format '" + ext + "'; supported: " + kImageExtensions);
}

void saveImage(const std::filesystem::path& file, const ImageRGBA8& image, const ImageWriteOptions& opt) {
  const ImageFormat fmt = imageFormatFor(file);
  checkSize(file, image.width, image.height);
  if (fmt == ImageFormat::Exr || fmt == ImageFormat::Hdr) {
    ImageF linear{image.width, image.height, std::vector<glm::vec4>(image.pixels.size() / 4)};
    for (size_t i = 0; i < linear.pixels.size(); ++i)
      for (int c = 0; c < 4; ++c) {
        const float v = image.pixels[i * 4 + c] / 255.0f;
        linear.pixels[i][c] = c < 3 ? srgbToLinear(v) : v;
      }
    return saveImage(file, linear, opt);
  }
  AtomicFile f(file);
  {
    ProgressLine progress(opt.progress, file);
    if (fmt == ImageFormat::Png) {
      writePng(f, image, progress);
    } else {
      StbSink sink{&f};
      checkStb(stbi_write_jpg_to_func(stbWrite, &sink, int(image.width), int(image.height), 4, image.pixels.data(), 95), sink, f,
               "JPEG");
    }
  }
  f.commit(opt.replace);
}

void saveImage(const std::filesystem::path& file, const ImageF& linear, const ImageWriteOptions& opt) {
  const ImageFormat fmt = imageFormatFor(file);
  if (fmt == ImageFormat::Png || fmt == ImageFormat::Jpg) return saveImage(file, toSrgb8(linear), opt);
  checkSize(file, linear.width, linear.height);
  AtomicFile f(file);
  {
    ProgressLine progress(opt.progress, file);
    writeFloat(f, fmt, linear.width, linear.height, &linear.pixels.data()->x);
  }
  f.commit(opt.replace);
}

void writePng(AtomicFile& f, const ImageRGBA8& image) {
  checkSize(f.target(), image.width, image.height);
  ProgressLine none(false, f.target());
  writePng(f, image, none);
}

void savePng(const std::filesystem::path& file, const ImageRGBA8& image) {
  AtomicFile f(file);
  writePng(f, image);
  f.commit();
}

}  // namespace rtr
