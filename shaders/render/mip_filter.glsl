// What both mip shaders share: bindings, source reads, level stores, the box-filter taps.
// A dispatch reads its source level either from the image (level 0, through the image's own view, so
// the sampler hardware does the sRGB decode) or from the float copy of its source level that the
// previous dispatch left in scratch memory: levels are never re-read from 8 bits, so rounding errors do
// not pile up from one dispatch to the next. It writes its last level's float copy for the next one.
#ifndef RTR_RENDER_MIP_FILTER_GLSL
#define RTR_RENDER_MIP_FILTER_GLSL

layout(set = 0, binding = 0) uniform texture2D srcImage;  // level 0 (view of the image's own format)
layout(set = 0, binding = 1, std430) readonly buffer SrcScratch { vec4 srcTexels[]; };  // row-major
layout(set = 0, binding = 2) writeonly uniform image2D dstLevels[MIP_MAX_LEVELS_PER_DISPATCH];
layout(set = 0, binding = 3, std430) writeonly buffer DstScratch { vec4 dstTexels[]; };
layout(push_constant) uniform Push { MipPush pc; };

// A texel of the dispatch's source level as linear colour.
vec4 loadSource(ivec2 q) {
  if (pc.fromScratch != 0) return srcTexels[q.y * pc.srcWidth + q.x];
  return texelFetch(srcImage, q, 0);
}

// Level j (1-based) of the dispatch; constant indices only (dynamic indexing of storage image arrays is
// an optional feature).
void storeLevel(int j, ivec2 p, vec4 linear) {
  const vec4 v = encode8(linear, pc.srgb != 0);
  switch (j) {
    case 1: imageStore(dstLevels[0], p, v); break;
    case 2: imageStore(dstLevels[1], p, v); break;
    case 3: imageStore(dstLevels[2], p, v); break;
    case 4: imageStore(dstLevels[3], p, v); break;
    case 5: imageStore(dstLevels[4], p, v); break;
    case 6: imageStore(dstLevels[5], p, v); break;
  }
}

// The float copy of the dispatch's last level (of size `size`), for the next dispatch.
void storeLastLevel(ivec2 p, ivec2 size, vec4 linear) { dstTexels[p.y * size.x + p.x] = linear; }

// The box-filter taps of one axis of a mip reduction (the rule of src/core/mip_reference.hpp):
// destination texel x of a level of size m covers [x*n/m, (x+1)*n/m) of its source of size n. In units
// of 1/m source texel k covers [k*m, (k+1)*m) and gets weight |overlap| / n. n = 2m gives the plain
// (0.5, 0.5); odd n = 2m+1 gives three taps with split boundary texels; n = m = 1 copies.
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

// Level sizes as Vulkan defines them.
ivec2 mipNext(ivec2 size) { return max(size >> 1, ivec2(1)); }

#endif
