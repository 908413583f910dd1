#version 460
// Compute rasteriser, the triangles raster.comp could not set up (docs/raster.md): those crossing the near
// plane (w <= 0 at a vertex) or leaving the guard band. A workgroup per (listed triangle, fan piece): its
// threads all clip the triangle in clip space (the same inputs, the same result, no shared copy) against
// z >= 0 (the near plane; w > 0 in front of it) and the four planes RASTER_CLIP_BAND pixels from the image
// centre (Sutherland-Hodgman, texcoords carried along the edges as the hardware's clipper carries them),
// then set up fan triangle gl_WorkGroupID.y + 1 of the convex piece as raster.comp sets up a triangle and
// share its work: a small one's pixels, a large one's tile rows (only the tiles that touch it) appended to
// the tile list for raster_large.comp, which runs after this pass. Dispatched indirectly from raster.comp's
// count (none: an empty dispatch), so the common setup carries none of this.
#extension GL_GOOGLE_include_directive : require
#include "raster_tri.glsl"
#include "raster_columns.glsl"

layout(local_size_x = RASTER_CLIP_THREADS) in;

const int kMaxVertices = int(RASTER_CLIP_PIECES) + 2;  // a triangle clipped by five planes

shared uint tileCount, firstTile, record;  // the piece's tile entries, their place in the list, its record

// A large piece: its record and an entry for each tile that touches it only (appendLarge lists every tile
// of the box: a piece reaching the image's edge from the near plane is a long sliver whose box is mostly
// empty). The workgroup's threads take a tile row each, count, reserve the piece's entries at once and
// write their rows' entries. A full list hands the triangle to the hardware.
void appendTouched(Tri t, uint ref) {
  const int tilesX = (t.box.z - t.box.x + RASTER_TILE) / RASTER_TILE, tilesY = (t.box.w - t.box.y + RASTER_TILE) / RASTER_TILE;
  const int local = int(gl_LocalInvocationID.x);
  if (local == 0) tileCount = 0u;
  barrier();
  uint n = 0u;
  for (int r = local; r < tilesY; r += RASTER_CLIP_THREADS) {
    const ivec2 c = touchedColumns(t, r);
    n += uint(max(c.y - c.x + 1, 0));
  }
  uint e = n > 0u ? atomicAdd(tileCount, n) : 0u;
  barrier();
  const uint total = tileCount;
  if (total == 0u) return;
  if (local == 0) {
    firstTile = atomicAdd(largeCount, total);
    record = atomicAdd(largeTriCount, 1u);
  }
  barrier();
  const bool fits = firstTile + total <= RASTER_LARGE_CAPACITY && record < RASTER_LARGE_TRIANGLES;
  if (fits && local == 0) storeLarge(record, t);
  e += firstTile;
  for (int r = local; r < tilesY && n > 0u; r += RASTER_CLIP_THREADS) {
    const ivec2 c = touchedColumns(t, r);
    for (int x = c.x; x <= c.y && e < RASTER_LARGE_CAPACITY; ++x) largeTiles[e++] = uvec2(fits ? record : ~0u, uint(r * tilesX + x));
  }
  if (!fits && local == 0) handOff(ref);
}

// Every branch below depends only on the workgroup's triangle and piece: uniform, as the barriers need.
void main() {
  const uint e = gl_WorkGroupID.x, piece = gl_WorkGroupID.y + 1u, local = gl_LocalInvocationID.x;
  if (e < clipFirst || e >= min(clipCount, RASTER_CLIP_CAPACITY)) return;
  const uint ref = clipTriangles[e], clusterIndex = ref >> RASTER_LOCAL_BITS, triangle = ref & ((1u << RASTER_LOCAL_BITS) - 1u);
  const GpuCluster c = listedCluster(clusterIndex);
  const GpuInstance inst = placedInstance(c.instance);
  const GpuDraw d = draws[inst.info.x];
  const bool masked = (c.flags & CLUSTER_ALPHA_MASKED) != 0u;
  if (!kAlphaMask && masked) {
    if (piece == 1u && local == 0u) handOff(ref);
    return;
  }
  Tri t;
  t.id = inst.info.z + c.firstTriangle + triangle;
  t.material = NO_TEXTURE;
  const uvec3 tri = triangleVertices(c, d, triangle);
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
  // This workgroup's triangle of the fan over the convex piece, set up as raster.comp sets one up, with the
  // same id. A piece the hardware must draw hands it the whole triangle (drawn by the piece's workgroup)
  // and ends the fan: the pieces before it are drawn, those after it not.
  const int i = int(piece);
  if (i + 1 >= n) return;
  bool swapped;
  for (int j = 1; j < i; ++j) {
    Tri s = t;
    const vec4 q[3] = vec4[3](poly[0], poly[j], poly[j + 1]);
    if (project(q, c.flags, s, swapped) == kHardware) return;
  }
  const vec4 p[3] = vec4[3](poly[0], poly[i], poly[i + 1]);
  const uint kind = project(p, c.flags, t, swapped);
  if (kind == kHardware) {  // a vertex rounded past the band or w = 0: the hardware draws the whole triangle
    if (local == 0u) handOff(ref);
    return;
  }
  if (kind == kSkip) return;
  if (t.material != NO_TEXTURE) {
    const vec2 u[3] = vec2[3](uv[0], swapped ? uv[i + 1] : uv[i], swapped ? uv[i] : uv[i + 1]);
    for (int v = 0; v < 3; ++v) t.uv[v] = maskTexcoord(m, u[v]);
  }
  if (kind == kSmall) {  // at most RASTER_SHARED_AREA pixels, spread over the threads
    const int w = t.box.z - t.box.x + 1, area = w * (t.box.w - t.box.y + 1);
    for (int j = int(local); j < area; j += RASTER_CLIP_THREADS) rasterPixel(t, t.box.xy + ivec2(j % w, j / w));
  } else {
    appendTouched(t, ref);
  }
}
