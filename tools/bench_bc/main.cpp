// bench-bc FILE...: level 0 of each image encoded by every BC encoder at hand, on one thread: seconds per
// image (best of --runs; the thread's CPU time, which other processes on the machine hardly change), and the decoded image's error against the texels (mean and max per channel in
// 8-bit steps, and the ꟻLIP-style mean of core/flip). Colour images: BC1 (BC3 where any alpha is below 255);
// --channel also encodes the first channel as BC4. The decoder is ours for every encoder's blocks.
#include <algorithm>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

#ifdef RTR_HAVE_SQUISH
#include <squish.h>
#endif

#include "core/error.hpp"
#include "core/flip.hpp"
#include "core/image.hpp"
#include "scene/baked_texels.hpp"

using namespace rtr;

namespace {

struct Encoder {
  const char* name;
  std::function<std::vector<uint8_t>(BakedFormat, uint32_t, uint32_t, const uint8_t*)> encode;
};

void measure(const Encoder& e, BakedFormat f, const TexelData& t, int runs, const char* file) {
  std::vector<uint8_t> blocks;
  double best = 1e30;
  for (int r = 0; r < runs; ++r) {
    timespec t0, t1;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t0);
    blocks = e.encode(f, t.width, t.height, t.texels.data());
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t1);
    best = std::min(best, double(t1.tv_sec - t0.tv_sec) + 1e-9 * double(t1.tv_nsec - t0.tv_nsec));
  }
  const std::vector<uint8_t> back = decodeBakedLevel(f, t.width, t.height, blocks.data());
  const uint32_t ch = bakedChannels(f);
  double sum = 0;
  int max = 0;
  ImageRGBA8 a{t.width, t.height, {}}, b{t.width, t.height, {}};
  a.pixels.resize(size_t(t.width) * t.height * 4, 255);
  b.pixels = a.pixels;
  for (size_t i = 0; i < back.size(); ++i) {
    const int d = std::abs(int(back[i]) - int(t.texels[i]));
    sum += d;
    max = std::max(max, d);
    const size_t px = i / ch, c = i % ch;
    for (size_t k = ch == 1 ? 0 : c; k < (ch == 1 ? 3 : c + 1); ++k)
      a.pixels[px * 4 + k] = t.texels[i], b.pixels[px * 4 + k] = back[i];
  }
  const double flipMean = flip(a, b).stats().mean;
  const char* fname = f == BakedFormat::Bc1 ? "BC1" : f == BakedFormat::Bc3 ? "BC3" : "BC4";
  std::printf("%-20s %4ux%-4u %s %-18s %7.3f s CPU %7.2f Mtexel/s  mean %.3f  max %3d LSB  flip %.4f\n", file, t.width, t.height,
              fname, e.name, best, double(t.width) * t.height / best / 1e6, sum / double(back.size()), max, flipMean);
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  int runs = 1;
  bool channel = false;
  std::vector<std::string> files;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--runs" && i + 1 < argc) runs = std::max(1, std::atoi(argv[++i]));
    else if (a == "--channel") channel = true;
    else if (a.starts_with("--")) {
      std::fprintf(stderr, "usage: bench-bc [--runs N] [--channel] FILE...\n");
      return 2;
    } else files.push_back(a);
  }
  if (files.empty()) {
    std::fprintf(stderr, "usage: bench-bc [--runs N] [--channel] FILE...\n");
    return 2;
  }
  std::vector<Encoder> encoders{
      {"ours", [](BakedFormat f, uint32_t w, uint32_t h, const uint8_t* t) { return encodeBakedLevel(f, w, h, t, 1); }}};
#ifdef RTR_HAVE_SQUISH
  // squish handles BC1 and BC3 (bookworm's 1.15 writes its BC4 as BC1).
  auto squishFit = [](int fit) {
    return [fit](BakedFormat f, uint32_t w, uint32_t h, const uint8_t* t) {
      std::vector<uint8_t> out(bakedLevelBytes(f, w, h));
      squish::CompressImage(t, int(w), int(h), out.data(), (f == BakedFormat::Bc1 ? squish::kDxt1 : squish::kDxt5) | fit);
      return out;
    };
  };
  encoders.push_back({"squish range fit", squishFit(squish::kColourRangeFit)});
  encoders.push_back({"squish cluster fit", squishFit(squish::kColourClusterFit)});
#endif
  try {
    for (const std::string& file : files) {
      const std::string name = file.substr(file.find_last_of('/') + 1);
      const TexelData rgba = loadImage(file, 4);
      bool opaque = true;
      for (size_t k = 3; k < rgba.texels.size(); k += 4) opaque &= rgba.texels[k] == 255;
      const BakedFormat f = opaque ? BakedFormat::Bc1 : BakedFormat::Bc3;
      for (const Encoder& e : encoders) measure(e, f, rgba, runs, name.c_str());
      if (channel) measure(encoders[0], BakedFormat::Bc4, loadImage(file, 1), runs, name.c_str());
    }
  } catch (const Error& e) {
    std::fprintf(stderr, "bench-bc: %s\n", e.what());
    return 1;
  }
}
