// The compute rasteriser's triangle setup and per-pixel test, shared by raster.comp (small triangles, a
// thread each) and raster_large.comp (large ones, a workgroup per 32x32 tile).
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
#extension GL_EXT_nonuniform_qualifier : require
#include "raster_fetch.glsl"

// Scenes with alpha-masked materials (ComputeRaster's variant) test the mask per pixel here, as vis.frag
// does; without it a masked cluster's triangles go to the hardware hand-off. Only this variant reads:
layout(constant_id = 1) const bool kAlphaMask = false;
layout(set = 0, binding = 8, std430) readonly buffer Materials { GpuMaterial materials[]; };
layout(set = 0, binding = 9, std430) readonly buffer Texcoords { vec2 texcoords[]; };
layout(set = 1, binding = 0) uniform sampler2D textures[];

// The members of material i that the alpha test reads, one by one: a copy of the whole record loads its
// 304 bytes (the SPIR-V keeps the whole-struct load; dropping the unused parts is left to the driver).
GpuMaterial maskMaterial(uint i) {
  GpuMaterial m;
  m.baseColor = materials[i].baseColor;
  m.roughMetal = materials[i].roughMetal;
  m.textures = materials[i].textures;
  m.textures2 = materials[i].textures2;
  m.uvTransform[2 * SLOT_MASK] = materials[i].uvTransform[2 * SLOT_MASK];
  m.uvTransform[2 * SLOT_MASK + 1] = materials[i].uvTransform[2 * SLOT_MASK + 1];
  return m;
}

const int kOne = 1 << RASTER_SUBPIXEL_BITS;
const uint kSkip = 0u, kSmall = 1u, kLarge = 2u, kHardware = 3u;

struct Tri {
  ivec2 v[3];  // fixed point, ordered so that the edge functions are positive inside
  vec3 z;      // depth (z/w) at each vertex
  ivec4 box;   // pixels: min x, min y, max x, max y (inclusive)
  int64_t area2;
  uint id;
  // The alpha test (kAlphaMask): the mask's texcoords and 1/w at each vertex, the material (NO_TEXTURE:
  // no test).
  vec2 uv[3];
  vec3 invW;
  uint material;
};

// Edge function of a -> b at p: twice the signed area of (a, b, p); the top-left rule's bias makes it
// negative on edges that are neither top nor left (y down, the triangle clockwise on screen).
int64_t edge(ivec2 a, ivec2 b, ivec2 p) {
  const ivec2 d = b - a;
  const bool topLeft = d.y < 0 || (d.y == 0 && d.x > 0);
  return int64_t(d.x) * int64_t(p.y - a.y) - int64_t(d.y) * int64_t(p.x - a.x) - (topLeft ? 0l : 1l);
}

// Bounding boxes over this many pixels are rasterised tile by tile (raster_large.comp).
layout(constant_id = 0) const uint kSharedArea = RASTER_SHARED_AREA;

// From the clip-space vertices of a triangle in the view volume: kHardware where one has w <= 0 or leaves
// the guard band, else the snapped vertices, depths and box (kSkip: back-facing, zero area or no pixel
// centre; kSmall or kLarge by the box). `swapped`: vertices 1 and 2 exchanged (positive inside).
uint project(vec4 p[3], uint flags, inout Tri t, out bool swapped) {
  swapped = false;
  if (min(p[0].w, min(p[1].w, p[2].w)) <= 0.0) return kHardware;
  const vec2 size = vec2(pc.width, pc.height);
  ivec2 v[3];
  for (int i = 0; i < 3; ++i) {
    const vec2 s = (p[i].xy / p[i].w * 0.5 + 0.5) * size;  // the viewport transform
    if (any(greaterThan(abs(s - 0.5 * size), vec2(RASTER_GUARD_BAND)))) return kHardware;
    v[i] = ivec2(floor(s * float(kOne) + 0.5));
    t.z[i] = p[i].z / p[i].w;
    if (kAlphaMask) t.invW[i] = 1.0 / p[i].w;
  }
  // Vulkan's facing: counter-clockwise in framebuffer coordinates (y down) is front, i.e. area2 < 0 here;
  // the other way round for a mirrored instance (its draws' VK_FRONT_FACE_CLOCKWISE).
  t.area2 = int64_t(v[1].x - v[0].x) * int64_t(v[2].y - v[0].y) - int64_t(v[1].y - v[0].y) * int64_t(v[2].x - v[0].x);
  const bool back = (t.area2 > 0l) != ((flags & CLUSTER_MIRRORED) != 0u);
  if (t.area2 == 0l || (back && (flags & CLUSTER_DOUBLE_SIDED) == 0u)) return kSkip;
  if (t.area2 < 0l) {  // the other order: positive inside
    t.area2 = -t.area2;
    const ivec2 tv = v[1]; v[1] = v[2]; v[2] = tv;
    const float tz = t.z[1]; t.z[1] = t.z[2]; t.z[2] = tz;
    const float tw = t.invW[1]; t.invW[1] = t.invW[2]; t.invW[2] = tw;
    swapped = true;
  }
  t.v = v;
  // Pixels whose centres (x + 0.5) lie in the snapped bounding box, clipped to the image.
  const ivec2 lo = min(v[0], min(v[1], v[2])), hi = max(v[0], max(v[1], v[2]));
  t.box.xy = max((lo - kOne / 2 + kOne - 1) >> RASTER_SUBPIXEL_BITS, ivec2(0));
  t.box.zw = min((hi - kOne / 2) >> RASTER_SUBPIXEL_BITS, ivec2(pc.width, pc.height) - 1);
  if (any(greaterThan(t.box.xy, t.box.zw))) return kSkip;
  const ivec2 extent = t.box.zw - t.box.xy + 1;
  return uint(extent.x) * uint(extent.y) > kSharedArea ? kLarge : kSmall;
}

uint setup(uint clusterIndex, uint local, out Tri t) {
  const GpuCluster c = listedCluster(clusterIndex);
  const GpuInstance inst = placedInstance(c.instance);
  const GpuDraw d = draws[inst.info.x];
  t.id = inst.info.z + c.firstTriangle + local;
  t.material = NO_TEXTURE;
  const bool masked = (c.flags & CLUSTER_ALPHA_MASKED) != 0u;
  if (!kAlphaMask && masked) return kHardware;
  const uvec3 tri = triangleVertices(c, d, local);
  const vec4 p[3] = vec4[3](clipPosition(inst, tri.x), clipPosition(inst, tri.y), clipPosition(inst, tri.z));
  // Outside one plane of the view volume (behind the camera included): nothing to draw.
  for (int k = 0; k < 3; ++k) {
    if (p[0][k] > p[0].w && p[1][k] > p[1].w && p[2][k] > p[2].w) return kSkip;
    if (k < 2 && p[0][k] < -p[0].w && p[1][k] < -p[1].w && p[2][k] < -p[2].w) return kSkip;
  }
  if (p[0].z < 0.0 && p[1].z < 0.0 && p[2].z < 0.0) return kSkip;
  bool swapped;
  const uint kind = project(p, c.flags, t, swapped);
  if (kAlphaMask && masked && (kind == kSmall || kind == kLarge)) {
    const GpuMaterial m = maskMaterial(d.material);
    if (m.textures.w != NO_TEXTURE) {
      t.material = d.material;
      const uvec3 order = swapped ? tri.xzy : tri;
      for (int i = 0; i < 3; ++i) t.uv[i] = maskTexcoord(m, texcoords[order[i]]);
    }
  }
  return kind;
}

// A large triangle's setup, kept for its tiles (raster.h's RasterLargeTri), and read back.
void storeLarge(uint k, Tri t) {
  largeTris[k].box = t.box;
  largeTris[k].v01 = ivec4(t.v[0], t.v[1]);
  largeTris[k].v2 = ivec4(t.v[2], int(t.id), int(t.material));
  largeTris[k].z = vec4(t.z, 0.0);
  if (kAlphaMask) {
    largeTris[k].invW = vec4(t.invW, 0.0);
    largeTris[k].uv01 = vec4(t.uv[0], t.uv[1]);
    largeTris[k].uv2 = vec4(t.uv[2], 0.0, 0.0);
  }
}

// Past the list's capacity a triangle is counted, not stored (the draw skips those entries).
void handOff(uint ref) {
  const uint n = atomicAdd(vertexCount, 3u) / 3u;
  if (n < pc.handOffCapacity) hwTriangles[n] = ref;
}

// A large triangle: its record and one tile-list entry per tile of its box; a full list hands it to the
// hardware (its reserved entries that fit are marked empty).
void appendLarge(Tri t, uint ref) {
  const ivec2 tiles = (t.box.zw - t.box.xy + RASTER_TILE) / RASTER_TILE;
  const uint n = uint(tiles.x * tiles.y), first = atomicAdd(largeCount, n), record = atomicAdd(largeTriCount, 1u);
  const bool fits = first + n <= RASTER_LARGE_CAPACITY && record < RASTER_LARGE_TRIANGLES;
  if (fits) storeLarge(record, t);
  for (uint i = 0u; i < n && first + i < RASTER_LARGE_CAPACITY; ++i) largeTiles[first + i] = uvec2(fits ? record : ~0u, i);
  if (!fits) handOff(ref);
}

Tri loadLarge(uint k) {
  Tri t;
  t.box = largeTris[k].box;
  const ivec4 v01 = largeTris[k].v01, v2 = largeTris[k].v2;
  t.v = ivec2[3](v01.xy, v01.zw, v2.xy);
  t.id = uint(v2.z);
  t.material = uint(v2.w);
  t.z = largeTris[k].z.xyz;
  t.area2 = int64_t(t.v[1].x - t.v[0].x) * int64_t(t.v[2].y - t.v[0].y) - int64_t(t.v[1].y - t.v[0].y) * int64_t(t.v[2].x - t.v[0].x);
  if (kAlphaMask && t.material != NO_TEXTURE) {
    t.invW = largeTris[k].invW.xyz;
    const vec4 uv01 = largeTris[k].uv01;
    t.uv = vec2[3](uv01.xy, uv01.zw, largeTris[k].uv2.xy);
  }
  return t;
}

// Perspective-correct mask texcoords where the (unnormalised) screen-space weights are `e`.
vec2 maskUv(Tri t, vec3 e) {
  const vec3 q = e * t.invW;
  return (q.x * t.uv[0] + q.y * t.uv[1] + q.z * t.uv[2]) / (q.x + q.y + q.z);
}

// The alpha test at pixel `px` (edge functions `e` at its centre), sampled at the level the hardware's
// implicit LOD picks: the texcoords' differences to the other pixel of its 2x2 quad in x and in y (what
// fine dFdx/dFdy give; extrapolated off the triangle as a helper invocation's are), scaled by 2^bias as
// vis_shade.comp does, through textureGrad, so the device's own LOD formula and sampler decide the rest.
bool cutOut(Tri t, ivec2 px, vec3 e) {
  // The edge functions' steps per pixel in x and y (edge(a, b, p) = d.x (p.y - a.y) - d.y (p.x - a.x)).
  const ivec2 d0 = t.v[2] - t.v[1], d1 = t.v[0] - t.v[2], d2 = t.v[1] - t.v[0];
  const vec3 stepX = -float(kOne) * vec3(d0.y, d1.y, d2.y), stepY = float(kOne) * vec3(d0.x, d1.x, d2.x);
  const vec2 side = vec2(1 - 2 * (px & 1));
  const vec2 uv = maskUv(t, e);
  const float scale = exp2(frame.params.y);
  const vec2 gx = (maskUv(t, e + side.x * stepX) - uv) * (side.x * scale);
  const vec2 gy = (maskUv(t, e + side.y * stepY) - uv) * (side.y * scale);
  const GpuMaterial m = maskMaterial(t.material);
  return maskCuts(m, textureGrad(textures[nonuniformEXT(m.textures.w)], uv, gx, gy));
}

// Whether the tile at `lo` (RASTER_TILE² pixels, clipped to the box) holds a pixel centre inside all three
// edges. Each edge function is affine, so its largest value over the tile's centres is at a corner: a tile
// all of whose corners lie outside one edge has nothing to draw (large triangles' boxes are up to half empty).
bool tileTouches(Tri t, ivec2 lo) {
  const ivec2 c0 = lo * kOne + kOne / 2, c1 = min(lo + RASTER_TILE - 1, t.box.zw) * kOne + kOne / 2;
  for (int k = 0; k < 3; ++k) {
    const ivec2 a = t.v[k == 2 ? 0 : k + 1], b = t.v[k == 0 ? 2 : k - 1];
    if (max(max(edge(a, b, c0), edge(a, b, ivec2(c1.x, c0.y))), max(edge(a, b, ivec2(c0.x, c1.y)), edge(a, b, c1))) < 0l)
      return false;
  }
  return true;
}

// Measuring only (RTR_RASTER_MEASURE, docs/raster.md "What bounds each pass"; raster.comp's variant, never
// the default): RASTER_MEASURE_NO_ATOMICS leaves out the per-pixel atomicMin, RASTER_MEASURE_SETUP the
// whole pixel loop. What is left is kept by a store no real id takes (~0u is never an id).
layout(constant_id = 2) const uint kMeasure = RASTER_MEASURE_OFF;

// Pixel px, whose centre has edge functions e0, e1, e2 (t's edges opposite vertices 0, 1, 2).
void rasterCovered(Tri t, ivec2 px, int64_t e0, int64_t e1, int64_t e2) {
  if (e0 < 0l || e1 < 0l || e2 < 0l) return;
  // The bias is at most 1 of area2 (>= 1): barycentrics from the unbiased edges are not worth the cost.
  // Depth as z0 plus the weighted differences: depths crowd just below 1 (z/w of a far-away model), and
  // the sum of the three weighted depths lost the few units in the last place that separate a shell from
  // the parts inside it (2CylinderEngine showed its inner parts); the differences keep them.
  const float z = t.z[0] + (float(e1) * (t.z[1] - t.z[0]) + float(e2) * (t.z[2] - t.z[0])) / float(t.area2);
  if (z < 0.0 || z > 1.0) return;  // the hardware's near and far clipping (w > 0 everywhere here)
  const int i = px.y * int(pc.width) + px.x;
  if (kAlphaMask && t.material != NO_TEXTURE) {
    // Behind what is drawn already (depths only fall): the mask's fetch would change nothing.
    if (z > uintBitsToFloat(uint(vis[i] >> 32))) return;
    if (cutOut(t, px, vec3(float(e0), float(e1), float(e2)))) return;
  }
  if (kMeasure == RASTER_MEASURE_NO_ATOMICS) {
    if (t.id == ~0u) vis[i] = packVis(z, t.id);
    return;
  }
  atomicMin(vis[i], packVis(z, t.id));
}

void rasterPixel(Tri t, ivec2 px) {
  const ivec2 c = px * kOne + kOne / 2;
  rasterCovered(t, px, edge(t.v[1], t.v[2], c), edge(t.v[2], t.v[0], c), edge(t.v[0], t.v[1], c));
}
