#!/usr/bin/python3
"""rtr-lod-cut computes the cut rtr-view's culling pass chooses: for the baked temple, three views and
two thresholds, the clusters and triangles it lists equal those the GPU's pass counts (lavapipe,
--cull off, so the cut alone decides).

    lod_cut_test.py BIN_DIR SCENE"""
import re
import subprocess
import sys

bin_dir, scene = sys.argv[1], sys.argv[2]
views = {"stored": [], "inside": ["--camera", "0,1.5,0,30,-5"], "outside": ["--camera", "16.34,17.74,16.06,30,-25"]}
failures = 0
for name, cam in views.items():
    for lod in ("1", "4"):
        common = ["--size", "640x400", "--lod-error", lod] + cam
        gpu = subprocess.run([f"{bin_dir}/rtr-view", scene, "--headless", "--bench", "1", "--raster", "compute",
                              "--shading-path", "visibility", "--cull", "off"] + common,
                             capture_output=True, text=True, timeout=600)
        m = re.search(r"^cull: \d+ clusters; listed early (\d+), late (\d+);.* (\d+) triangles listed$", gpu.stdout + gpu.stderr, re.M)
        if gpu.returncode != 0 or not m:
            sys.exit(f"rtr-view {name} {lod} px: exit {gpu.returncode}, no cull line:\n{gpu.stdout}{gpu.stderr}")
        gpu_clusters, gpu_tris = int(m[1]) + int(m[2]), int(m[3])
        cpu = subprocess.run([f"{bin_dir}/rtr-lod-cut", scene] + common, capture_output=True, text=True, timeout=600)
        m = re.search(rf"^cut at {lod} px: (\d+) triangles listed .* (\d+) clusters listed", cpu.stdout, re.M)
        if cpu.returncode != 0 or not m:
            sys.exit(f"rtr-lod-cut {name} {lod} px: exit {cpu.returncode}:\n{cpu.stdout}{cpu.stderr}")
        cpu_tris, cpu_clusters = int(m[1]), int(m[2])
        ok = (cpu_tris, cpu_clusters) == (gpu_tris, gpu_clusters)
        failures += not ok
        print(f"{name} {lod} px: GPU {gpu_tris} triangles in {gpu_clusters} clusters, CPU {cpu_tris} in {cpu_clusters}"
              f"{'' if ok else '  MISMATCH'}")
sys.exit(1 if failures else 0)
