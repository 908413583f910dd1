#version 460
// Compute rasteriser, the triangles raster.comp could not set up (docs/raster.md): those crossing the near
// plane (w <= 0 at a vertex) or leaving the guard band. A thread per triangle clips it in clip space against
// z >= 0 (the near plane; w > 0 in front of it) and the four planes RASTER_CLIP_BAND pixels from the image
// centre (Sutherland-Hodgman, texcoords carried along the edges as the hardware's clipper carries them),
// then sets up the convex piece's fan as raster.comp sets up a triangle: small ones rasterised here, large
// ones appended to the tile list for raster_large.comp, which runs after this pass. The common setup of
// raster.comp carries none of this; the pass is dispatched indirectly, one workgroup per
// RASTER_CLIP_GROUP listed triangles (none: an empty dispatch).
#extension GL_GOOGLE_include_directive : require
#include "raster_tri.glsl"

layout(local_size_x = RASTER_CLIP_GROUP) in;

const int kMaxVertices = 8;  // a triangle clipped by five planes

void main() {
  const uint e = gl_GlobalInvocationID.x;
  if (e < clipFirst || e >= min(clipCount, RASTER_CLIP_CAPACITY)) return;
  const uint ref = clipTriangles[e], clusterIndex = ref >> RASTER_LOCAL_BITS, local = ref & ((1u << RASTER_LOCAL_BITS) - 1u);
  const GpuCluster c = listedCluster(clusterIndex);
  const GpuInstance inst = instances[c.instance];
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
    m = materials[d.material];
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
      appendLarge(t, ref);
    }
  }
}
