#version 460
// raster_columns.glsl's touchedColumns against brute force, for every tile row of the given triangles:
// the tile columns holding a pixel column whose centre is on the inner side of each edge at the row's top
// or bottom centre (what touchedColumns computes in closed form), and the first, last and number of the
// tiles raster_tri.glsl's tileTouches accepts (RasterTest.TouchedColumnsAreExact).
#extension GL_GOOGLE_include_directive : require
#include "render/raster_tri.glsl"
#include "render/raster_columns.glsl"

layout(local_size_x = 64) in;

const int kRows = 8;  // tile rows per triangle: the test's image is 8 tiles high
layout(set = 0, binding = 16, std430) readonly buffer Triangles { ivec4 triangles[]; };  // v0 v1, v2 -, box
layout(set = 0, binding = 17, std430) writeonly buffer Columns { ivec4 columns[]; };    // touchedColumns, brute force
layout(set = 0, binding = 18, std430) writeonly buffer Touches { ivec4 touches[]; };    // first, last, count, -

void main() {
  const uint i = gl_GlobalInvocationID.x, k = i / kRows;
  if (3u * k + 2u >= uint(triangles.length())) return;
  const int row = int(i % kRows);
  Tri t;
  t.v = ivec2[3](triangles[3 * k].xy, triangles[3 * k].zw, triangles[3 * k + 1].xy);
  t.box = triangles[3 * k + 2];
  const int tilesX = (t.box.z - t.box.x + RASTER_TILE) / RASTER_TILE, tilesY = (t.box.w - t.box.y + RASTER_TILE) / RASTER_TILE;
  if (row >= tilesY) {
    columns[i] = ivec4(1, 0, 1, 0);
    touches[i] = ivec4(1, 0, 0, 0);
    return;
  }
  const int y0 = t.box.y + RASTER_TILE * row, y1 = min(y0 + RASTER_TILE - 1, t.box.w);
  int first = t.box.z + 1, last = t.box.x - 1;
  for (int x = t.box.x; x <= t.box.z; ++x) {
    bool passes = true;
    for (int e = 0; e < 3; ++e) {
      const ivec2 a = t.v[e == 2 ? 0 : e + 1], b = t.v[e == 0 ? 2 : e - 1];
      passes = passes && max(edge(a, b, ivec2(x, y0) * kOne + kOne / 2), edge(a, b, ivec2(x, y1) * kOne + kOne / 2)) >= 0l;
    }
    if (passes) first = min(first, x), last = x;
  }
  columns[i] = ivec4(touchedColumns(t, row), first <= last ? (ivec2(first, last) - t.box.x) / RASTER_TILE : ivec2(1, 0));
  int tileFirst = tilesX, tileLast = -1, n = 0;
  for (int x = 0; x < tilesX; ++x)
    if (tileTouches(t, t.box.xy + RASTER_TILE * ivec2(x, row))) tileFirst = min(tileFirst, x), tileLast = x, ++n;
  touches[i] = ivec4(tileFirst, tileLast, n, 0);
}
