#!/usr/bin/env python3
"""Image error of B against A (PNG, 8-bit RGB or RGBA, not interlaced): the mean over pixels of the
largest channel difference (0-255), its maximum, and the share of pixels off by more than 16 and 64.
Standard library only (the level-of-detail rows, tools/bench_cull/lod.sh)."""
import struct
import sys
import zlib


def read_png(path):
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        sys.exit(f"{path}: not a PNG")
    pos, idat, w = 8, b"", None
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            w, h, depth, color, _, _, interlace = struct.unpack(">IIBBBBB", body)
            if depth != 8 or color not in (2, 6) or interlace:
                sys.exit(f"{path}: only 8-bit RGB/RGBA, not interlaced")
            bpp = 3 if color == 2 else 4
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    raw, stride = zlib.decompress(idat), w * bpp
    rows, prev = [], bytearray(stride)
    for y in range(h):
        f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b, c = prev[i], prev[i - bpp] if i >= bpp else 0
            if f == 1: line[i] = (line[i] + a) & 255
            elif f == 2: line[i] = (line[i] + b) & 255
            elif f == 3: line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(line)
        prev = line
    return w, h, bpp, rows


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: pngdiff.py A.png B.png")
    wa, ha, ba, a = read_png(sys.argv[1])
    wb, hb, bb, b = read_png(sys.argv[2])
    if (wa, ha) != (wb, hb):
        sys.exit("sizes differ")
    total, worst, over16, over64 = 0, 0, 0, 0
    for y in range(ha):
        ra, rb = a[y], b[y]
        for x in range(wa):
            d = max(abs(ra[x * ba + k] - rb[x * bb + k]) for k in range(3))
            total += d
            worst = max(worst, d)
            over16 += d > 16
            over64 += d > 64
    n = wa * ha
    print(f"mean {total / n:.4f} max {worst} over16 {100 * over16 / n:.3f}% over64 {100 * over64 / n:.3f}%")


if __name__ == "__main__":
    main()
