#!/usr/bin/env python3
"""The rows of docs/virtual-geometry.md from tools/bench_cull/lod.sh's output: per scale, size, view and
--lod-error the triangles listed, the min ms of raster, raster large, shade and the frame, and the image
error against --lod-error 0: the ꟻLIP-style mean (docs/flip.md), the mean and max of the largest channel
difference (0-255) and the share of pixels off by > 16. Older outputs (pngdiff.py's line) have no ꟻLIP.
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
    m = re.match(r"image error shaded: (?:flip mean (\S+) .*largest channel difference )?mean (\S+) max (\S+) over16 (\S+)",
                 line)
    if m:
        cur["flip"] = m.group(1) or "–"
        cur["err"] = f"{m.group(2)} / {m.group(3)} / {m.group(4).replace('%', ' %')}"

print("| S | size | view | cull | E | triangles | raster | raster large | shade | frame | ꟻLIP mean "
      "| error mean / max / > 16 |")
print("|---|---|---|---|---:|---:|---:|---:|---:|---:|---:|---|")
for r in rows:
    f = lambda k: "–" if k not in r else f"{r[k]:.0f}" if r[k] >= 100 else f"{r[k]:.3g}"  # GPU ms and lavapipe ms
    print("| " + " | ".join(r["key"][:4]) + f" | {r['key'][4]} | {r['tris']} | {f('raster')} | {f('raster large')} | "
          f"{f('shade')} | {f('total')} | {r.get('flip', '–')} | {r.get('err', '–')} |")

# Issue 30's goal at the default threshold: the ꟻLIP-style mean against full detail ≤ 0.01.
at1 = [(r["key"], float(r["flip"])) for r in rows if r["key"][4] == "1" and r.get("flip", "–") != "–"]
if at1:
    key, worst = max(at1, key=lambda kv: kv[1])
    print(f"\nꟻLIP mean at --lod-error 1, worst of {len(at1)} rows: {worst:.4f} (S={key[0]} {key[1]} {key[2]}); "
          f"goal ≤ 0.01: {'met' if worst <= 0.01 else 'not met'}")
