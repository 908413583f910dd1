// The tile columns of a large triangle's tile row that hold a covered pixel centre (raster_clip.comp's
// pieces, listed tile by tile; shaders/test/tile_columns.comp holds it to raster_tri.glsl's tileTouches).

// Pixel column x of tile row `row` passes an edge whose largest value over the row's centres is
// m - dy (cx - ax) (cx: x's centre): the tile holding x has a centre on the edge's inner side there.
bool passes(int64_t m, int dy, int ax, int x) { return m >= int64_t(dy) * int64_t(x * kOne + kOne / 2 - ax); }

// The tile columns of tile row `row` of t's box holding a pixel column whose centre is on the inner side of
// every edge at the row's top or bottom centre (x: first, y: last; x > y: none): every tile with a covered
// centre, and only tiles tileTouches accepts (it may accept one more, whose centres pass each edge but none
// passes all three). Each edge function is affine: over the row's centres its largest value at a given x
// is at the row's top or bottom centre, and the x where that reaches 0 bounds the columns from one side.
// That x is estimated in float and made exact by the integer test: the two loops step from the estimate
// until the test holds on one side and fails on the other, whatever the float rounding was (it saves steps
// only); no 64-bit division, which NVIDIA emulates in hundreds of instructions.
ivec2 touchedColumns(Tri t, int row) {
  const int y0 = t.box.y + RASTER_TILE * row, y1 = min(y0 + RASTER_TILE - 1, t.box.w);
  int lo = t.box.x, hi = t.box.z;  // pixel columns
  for (int k = 0; k < 3 && lo <= hi; ++k) {
    const ivec2 a = t.v[k == 2 ? 0 : k + 1], b = t.v[k == 0 ? 2 : k - 1], d = b - a;
    const bool topLeft = d.y < 0 || (d.y == 0 && d.x > 0);
    // edge(a, b, (x, y)) = m(y) - d.y (x - a.x), m(y) = d.x (y - a.y) - bias; the larger m over the row:
    const int64_t m = max(int64_t(d.x) * (y0 * kOne + kOne / 2 - a.y), int64_t(d.x) * (y1 * kOne + kOne / 2 - a.y)) -
                      (topLeft ? 0l : 1l);
    if (d.y == 0) {
      if (m < 0l) return ivec2(1, 0);
      continue;
    }
    // Where m - d.y (cx - a.x) = 0, in pixels; within a unit in the last place of a 24-bit float.
    const float x = (float(a.x) + float(m) / float(d.y) - float(kOne / 2)) / float(kOne);
    if (d.y > 0) {  // passes for x <= X: the last column that does, in [lo - 1, hi]
      int c = int(clamp(floor(x), float(lo - 1), float(hi)));
      while (c < hi && passes(m, d.y, a.x, c + 1)) ++c;
      while (c >= lo && !passes(m, d.y, a.x, c)) --c;
      hi = c;
    } else {  // passes for x >= X: the first column that does, in [lo, hi + 1]
      int c = int(clamp(ceil(x), float(lo), float(hi + 1)));
      while (c > lo && passes(m, d.y, a.x, c - 1)) --c;
      while (c <= hi && !passes(m, d.y, a.x, c)) ++c;
      lo = c;
    }
  }
  if (lo > hi) return ivec2(1, 0);
  return (ivec2(lo, hi) - t.box.x) / RASTER_TILE;
}
