#!/usr/bin/env python3
"""The rows of docs/virtual-geometry.md from tools/bench_cull/lod.sh's output: per scale, size, view and
--lod-error the triangles listed, the min ms of raster, raster large, shade and the frame, and the image
error against --lod-error 0 (mean of the largest channel difference, 0-255; share of pixels off by > 16).
Usage: lod_rows.py out.txt [--median]"""
import re
import sys

col = 2 if "--median" in sys.argv else 1
rows, cur = [], None
for line in open(sys.argv[1]):
    m = re.match(r"== S=(\S+) (\S+) (\S+) --cull (\S+) --lod-error (\S+)", line)
    if m:
        cur = {"key": m.groups(), "tris": "all"}
        rows.append(cur)
        continue
    if cur is None:
        continue
    m = re.match(r"\| (raster|raster large|shade|total) \| ([\d.]+) \| ([\d.]+) \|", line)
    if m:
        cur[m.group(1)] = float(m.group(1 + col))
    m = re.search(r"; (\d+) triangles listed", line)
    if m:
        cur["tris"] = f"{int(m.group(1)):,}".replace(",", " ")
    m = re.match(r"image error shaded: mean (\S+) max \S+ over16 (\S+)", line)
    if m:
        cur["err"] = f"{m.group(1)} / {m.group(2).replace('%', ' %')}"

print("| S | size | view | cull | E | triangles | raster | raster large | shade | frame | error mean / > 16 |")
print("|---|---|---|---|---:|---:|---:|---:|---:|---:|---|")
for r in rows:
    f = lambda k: f"{r[k]:.0f}" if k in r else "–"
    print("| " + " | ".join(r["key"][:4]) + f" | {r['key'][4]} | {r['tris']} | {f('raster')} | {f('raster large')} | "
          f"{f('shade')} | {f('total')} | {r.get('err', '–')} |")
