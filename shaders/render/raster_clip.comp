#version 460
// Compute rasteriser, the triangles raster.comp could not set up (docs/raster.md): those crossing the near
// plane (w <= 0 at a vertex) or leaving the guard band. A thread per triangle clips it in clip space against
// z >= 0 (the near plane; w > 0 in front of it) and the four planes RASTER_CLIP_BAND pixels from the image
// centre (Sutherland-Hodgman, texcoords carried along the edges as the hardware's clipper carries them),
// then sets up the convex piece's fan as raster.comp sets up a triangle: small ones rasterised here, large
// ones appended to the tile list for raster_large.comp (only their tiles that touch them), which runs after
// this pass. The common setup of
// raster.comp carries none of this; the pass is dispatched indirectly, one workgroup per
// RASTER_CLIP_GROUP listed triangles (none: an empty dispatch).
#extension GL_GOOGLE_include_directive : require
#include "raster_tri.glsl"

layout(local_size_x = RASTER_CLIP_GROUP) in;

const int kMaxVertices = 8;  // a triangle clipped by five planes

int64_t floorDiv(int64_t a, int64_t b) { return a >= 0l ? a / b : -((-a + b - 1l) / b); }  // b > 0

// The tile columns of tile row `row` of t's box that hold a pixel centre on the inner side of every edge's
// extension over the row (x: first, y: last; x > y: none): exactly the tiles tileTouches accepts. Each edge
// function is affine: over the row's centres its largest value at a given x is at the row's top or bottom
// centre, and the x where that reaches 0 bounds the columns from one side.
ivec2 touchedColumns(Tri t, int row) {
  const int y0 = t.box.y + RASTER_TILE * row, y1 = min(y0 + RASTER_TILE - 1, t.box.w);
  int64_t lo = int64_t(t.box.x) * kOne + kOne / 2, hi = int64_t(t.box.z) * kOne + kOne / 2;  // fixed-point centres
  for (int k = 0; k < 3; ++k) {
    const ivec2 a = t.v[k == 2 ? 0 : k + 1], b = t.v[k == 0 ? 2 : k - 1], d = b - a;
    const bool topLeft = d.y < 0 || (d.y == 0 && d.x > 0);
    // edge(a, b, (x, y)) = m(y) - d.y (x - a.x), m(y) = d.x (y - a.y) - bias; the larger m over the row:
    const int64_t m = max(int64_t(d.x) * (int64_t(y0) * kOne + kOne / 2 - a.y), int64_t(d.x) * (int64_t(y1) * kOne + kOne / 2 - a.y)) -
                      (topLeft ? 0l : 1l);
    if (d.y == 0) {
      if (m < 0l) return ivec2(1, 0);
    } else if (d.y > 0) {
      hi = min(hi, int64_t(a.x) + floorDiv(m, int64_t(d.y)));  // m - d.y (x - a.x) >= 0
    } else {
      lo = max(lo, int64_t(a.x) - floorDiv(m, int64_t(-d.y)));  // m + |d.y| (x - a.x) >= 0
    }
  }
  // Pixels whose centres lie in [lo, hi], then their tile columns.
  const int64_t first = -floorDiv(-(lo - kOne / 2), int64_t(kOne)), last = floorDiv(hi - kOne / 2, int64_t(kOne));
  if (first > last) return ivec2(1, 0);
  return (ivec2(int(first), int(last)) - t.box.x) / RASTER_TILE;
}

// A large piece: its record and an entry for each tile that touches it only (appendLarge lists every tile
// of the box: a piece reaching the image's edge from the near plane is a long sliver whose box is mostly
// empty). A full list hands the triangle to the hardware.
void appendTouched(Tri t, uint ref) {
  const int tilesX = (t.box.z - t.box.x + RASTER_TILE) / RASTER_TILE, tilesY = (t.box.w - t.box.y + RASTER_TILE) / RASTER_TILE;
  uint n = 0u;
  for (int r = 0; r < tilesY; ++r) {
    const ivec2 c = touchedColumns(t, r);
    n += uint(max(c.y - c.x + 1, 0));
  }
  if (n == 0u) return;
  const uint first = atomicAdd(largeCount, n), record = atomicAdd(largeTriCount, 1u);
  const bool fits = first + n <= RASTER_LARGE_CAPACITY && record < RASTER_LARGE_TRIANGLES;
  if (fits) storeLarge(record, t);
  uint e = first;
  for (int r = 0; r < tilesY && e < RASTER_LARGE_CAPACITY; ++r) {
    const ivec2 c = touchedColumns(t, r);
    for (int x = c.x; x <= c.y && e < RASTER_LARGE_CAPACITY; ++x) largeTiles[e++] = uvec2(fits ? record : ~0u, uint(r * tilesX + x));
  }
  if (!fits) handOff(ref);
}

void main() {
  const uint e = gl_GlobalInvocationID.x;
  if (e < clipFirst || e >= min(clipCount, RASTER_CLIP_CAPACITY)) return;
  const uint ref = clipTriangles[e], clusterIndex = ref >> RASTER_LOCAL_BITS, local = ref & ((1u << RASTER_LOCAL_BITS) - 1u);
  const GpuCluster c = listedCluster(clusterIndex);
  const GpuInstance inst = placedInstance(c.instance);
  const GpuDraw d = draws[inst.info.x];
  const bool masked = (c.flags & CLUSTER_ALPHA_MASKED) != 0u;
  if (!kAlphaMask && masked) {
    handOff(ref);
    return;
  }
  Tri t;
  t.id = inst.info.z + c.firstTriangle + local;
  t.material = NO_TEXTURE;
  const uvec3 tri = triangleVertices(c, d, local);
  vec4 poly[kMaxVertices];
  vec2 uv[kMaxVertices];
  int n = 3;
  for (int i = 0; i < 3; ++i) {
    poly[i] = clipPosition(inst, tri[i]);
    uv[i] = vec2(0.0);
  }
  GpuMaterial m;
  if (kAlphaMask && masked) {
    m = maskMaterial(d.material);
    if (m.textures.w != NO_TEXTURE) {
      t.material = d.material;
      for (int i = 0; i < 3; ++i) uv[i] = texcoords[tri[i]];
    }
  }
  // Planes as dot(plane, vertex) >= 0: the near plane, then x and y within the band (|x| <= k w).
  const vec2 k = 2.0 * float(RASTER_CLIP_BAND) / vec2(pc.width, pc.height);
  const vec4 planes[5] = vec4[5](vec4(0, 0, 1, 0), vec4(-1, 0, 0, k.x), vec4(1, 0, 0, k.x), vec4(0, -1, 0, k.y), vec4(0, 1, 0, k.y));
  for (int j = 0; j < 5 && n >= 3; ++j) {
    vec4 outPoly[kMaxVertices];
    vec2 outUv[kMaxVertices];
    int count = 0;
    for (int i = 0; i < n; ++i) {
      const int i1 = i + 1 == n ? 0 : i + 1;
      const float da = dot(planes[j], poly[i]), db = dot(planes[j], poly[i1]);
      if (da >= 0.0) {
        outPoly[count] = poly[i];
        outUv[count++] = uv[i];
      }
      if ((da >= 0.0) != (db >= 0.0)) {
        const float s = da / (da - db);  // where the edge meets the plane
        outPoly[count] = mix(poly[i], poly[i1], s);
        outUv[count++] = mix(uv[i], uv[i1], s);
      }
    }
    poly = outPoly;
    uv = outUv;
    n = count;
  }
  // The fan over the convex piece: each triangle set up as raster.comp sets one up, with the same id.
  for (int i = 1; i + 1 < n; ++i) {
    const vec4 p[3] = vec4[3](poly[0], poly[i], poly[i + 1]);
    bool swapped;
    const uint kind = project(p, c.flags, t, swapped);
    if (kind == kHardware) {  // a vertex rounded past the band or w = 0: the hardware draws the whole triangle
      handOff(ref);
      return;
    }
    if (kind == kSkip) continue;
    if (t.material != NO_TEXTURE) {
      const vec2 u[3] = vec2[3](uv[0], swapped ? uv[i + 1] : uv[i], swapped ? uv[i] : uv[i + 1]);
      for (int v = 0; v < 3; ++v) t.uv[v] = maskTexcoord(m, u[v]);
    }
    if (kind == kSmall) {
      for (int y = t.box.y; y <= t.box.w; ++y)
        for (int x = t.box.x; x <= t.box.z; ++x) rasterPixel(t, ivec2(x, y));
    } else {
      appendTouched(t, ref);
    }
  }
}
