// The box-filter taps of one axis of a mip reduction (the rule of src/core/mip_reference.hpp):
// destination texel x of a level of size m covers [x*n/m, (x+1)*n/m) of its source of size n. In units
// of 1/m source texel k covers [k*m, (k+1)*m) and gets weight |overlap| / n. n = 2m gives the plain
// (0.5, 0.5); odd n = 2m+1 gives three taps with split boundary texels; n = m = 1 copies.
#ifndef RTR_RENDER_MIP_FILTER_GLSL
#define RTR_RENDER_MIP_FILTER_GLSL

struct MipTaps {
  int first;  // first source texel
  int count;  // 1 .. 3
  float w[3];
};

MipTaps mipTaps(int x, int n, int m) {
  MipTaps t;
  if (n == 2 * m) {  // exact halving: the general rule below gives the same taps, without divisions
    t.first = 2 * x;
    t.count = 2;
    t.w[0] = 0.5;
    t.w[1] = 0.5;
    t.w[2] = 0.0;
    return t;
  }
  int lo = x * n, hi = (x + 1) * n;
  t.first = lo / m;
  t.count = (hi + m - 1) / m - t.first;
  for (int i = 0; i < 3; ++i) {
    int k = t.first + i;
    t.w[i] = i < t.count ? float(min(hi, (k + 1) * m) - max(lo, k * m)) / float(n) : 0.0;
  }
  return t;
}

// sRGB decode of the 256 byte values, built once per workgroup (both mip shaders have 256 threads):
// one pow per thread instead of three per texel read.
shared float srgbDecodeLut[256];
void initSrgbDecodeLut() {
  srgbDecodeLut[gl_LocalInvocationIndex] = srgbToLinear(float(gl_LocalInvocationIndex) / 255.0);
  barrier();
}
vec4 decodeLut(vec4 stored, bool srgb) {
  if (!srgb) return stored;
  const ivec4 b = ivec4(stored * 255.0 + 0.5);
  return vec4(srgbDecodeLut[b.r], srgbDecodeLut[b.g], srgbDecodeLut[b.b], stored.a);
}

// Level sizes as Vulkan defines them.
ivec2 mipNext(ivec2 size) { return max(size >> 1, ivec2(1)); }

#endif
