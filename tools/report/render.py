#!/usr/bin/python3
"""Writes docs/BENCHMARKS.md and its plots from the raw outputs that tools/report/collect.sh kept.

    tools/report/render.py [DATA_DIR [DOC]]    (defaults: docs/bench/data, docs/BENCHMARKS.md)

DATA_DIR holds one folder per machine (e.g. h200/, lavapipe-vm/), each with meta.txt and one <row>.txt per
command. Every number in the report comes from those files; a row that a machine did not produce is
reported as missing with the reason (the command failed, or was not run there).
"""
import math
import os
import re
import sys

import scale  # noqa: E402  (tools/report/scale.py)
from tables import col, md_tables, num  # noqa: E402  (tools/report/tables.py)

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


# ---------------------------------------------------------------- reading the raw outputs


class Machine:
    def __init__(self, folder):
        self.folder, self.label = folder, os.path.basename(folder)
        self.meta = {}
        with open(os.path.join(folder, "meta.txt")) as f:
            for line in f:
                k, _, v = line.partition(":")
                self.meta[k.strip()] = v.strip()

    def raw(self, row):
        p = os.path.join(self.folder, row + ".txt")
        return open(p).read() if os.path.exists(p) else None

    def command(self, row):
        t = self.raw(row)
        return t.splitlines()[0].lstrip("$ ") if t else None

    def failed(self, row):
        t = self.raw(row)
        if t is None:
            return "not run on this machine"
        m = re.search(r"# exit (\d+)", t)
        return None if m and m.group(1) == "0" else "the command failed: see " + self.rel(row)

    def rel(self, row):
        return os.path.relpath(os.path.join(self.folder, row + ".txt"), os.path.join(ROOT, "docs"))

    @property
    def gpu(self):  # a lent GPU machine (the goals were set for the H200; an H100 is measured against them too)
        return self.label.startswith(("h200", "h100"))

    @property
    def device(self):
        m = re.search(r" on (.+?): \d+ meshes", self.meta.get("vulkan", ""))
        return m.group(1) if m else "unknown Vulkan device"

    def caption(self):
        gpu = self.meta.get("gpu")
        return (f"{self.device}" + (f" (nvidia-smi: {gpu})" if gpu else "") +
                f"; CPU {self.meta.get('cpu', '?')}; {self.meta.get('date', '?')}; commit {self.meta.get('commit', '?')}" +
                (f"; tracer rows: commit {self.meta['trace-commit']}" if "trace-commit" in self.meta else "") +
                (f"; environment rows: commit {self.meta['env-commit']}" if "env-commit" in self.meta else "") +
                (f"; texture rows: commit {self.meta['textures-commit']}" if "textures-commit" in self.meta else "") +
                (f"; rows by commit: {self.meta['rows-commit']}" if "rows-commit" in self.meta else ""))


# ---------------------------------------------------------------- the sections

class Report:
    def __init__(self, machines, plots_dir):
        self.m, self.plots, self.out, self.goals = machines, plots_dir, [], []
        os.makedirs(plots_dir, exist_ok=True)

    def w(self, s=""):
        self.out.append(s)

    def table(self, header, rows):
        """A parsed table written back as Markdown, followed by a blank line."""
        self.w("| " + " | ".join(header) + " |")
        self.w("|" + "---|" * len(header))
        for r in rows:
            self.w("| " + " | ".join(r) + " |")
        self.w()

    def plot(self, fig, name, caption):
        path = os.path.join(self.plots, name)
        fig.tight_layout()
        fig.savefig(path, dpi=110)
        plt.close(fig)
        self.w(f"![{caption}](bench/plots/{name})")
        self.w()

    def source(self, m, row):
        cmd = m.command(row)
        if cmd:
            self.w(f"<sub>{m.label}: `{cmd}` — raw output `{m.rel(row)}`</sub>")
            self.w()

    def scatter_done(self, fig, ax, plotted, name, caption, title, xlabel, ylabel, xlog=False):
        """Labels a speed-vs-error scatter and writes it; drops the figure when nothing was plotted."""
        if not plotted:
            plt.close(fig)
            return False
        if xlog:
            ax.set_xscale("log")
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        ax.set_title(title, fontsize=10)
        ax.grid(alpha=0.3)
        self.plot(fig, name, caption)
        return True

    def ratio_bars(self, bars, ylabel, title, name, caption):
        """(label, ratio, ...) bars against 1.0, the goal: green where met."""
        fig, ax = plt.subplots(figsize=(max(6, 0.5 * len(bars)), 4))
        ax.bar(range(len(bars)), [b[1] for b in bars], color=["tab:green" if b[1] >= 1 else "tab:red" for b in bars])
        ax.axhline(1.0, color="k", lw=0.8)
        ax.set_xticks(range(len(bars)), [b[0] for b in bars], rotation=90, fontsize=7)
        ax.set_ylabel(ylabel)
        ax.set_title(title, fontsize=10)
        self.plot(fig, name, caption)

    def missing(self, what, m, row):
        self.w(f"- {what} on **{m.label}**: not measured — {m.failed(row)}.")

    def trace_sections(self, m):
        """bench-trace's output split at its '## ' headings: {title: text}."""
        t = m.raw("trace")
        if not t or m.failed("trace"):
            return None
        return {p.split("\n", 1)[0].strip(): p for p in re.split(r"^## ", t, flags=re.M)[1:]}

    # 1. ray–triangle routines: speed against miss rate
    def routines(self):
        self.w("## Ray–triangle tests: speed against misses on a closed mesh")
        self.w()
        self.w("Each routine alone (scalar, 1 thread) on the same triangles, and its misses for rays shot from "
               "inside a closed sphere (every ray must hit: a miss is a crack). `bench-trace`.")
        self.w()
        fig, ax = plt.subplots(figsize=(6, 3.6))
        any_point = False
        for m in self.m:
            secs = self.trace_sections(m)
            sec = next((v for k, v in (secs or {}).items() if k.startswith("Ray/triangle routines")), None)
            if not sec:
                self.missing("ray–triangle routines", m, "trace")
                continue
            for header, rows in md_tables(sec):
                ci, cm = col(header, "tests/s"), col(header, "misses")
                if ci is None or cm is None:
                    continue
                self.w(f"**{m.label}**")
                self.w()
                self.w("| routine | M tests/s | closed-sphere misses |")
                self.w("|---|---:|---|")
                for r in rows:
                    self.w(f"| {r[0]} | {r[ci]} | {r[cm]} |")
                    pct = re.search(r"\(([\d.]+) %\)", r[cm])
                    x, y = num(r[ci]), float(pct.group(1)) if pct else None
                    if x is not None and y is not None:
                        ax.scatter(x, y, marker="o" if m.gpu else "s")
                        ax.annotate(f"{r[0]} ({m.label})", (x, y), fontsize=7, xytext=(4, 4), textcoords="offset points")
                        any_point = True
                self.w()
                self.source(m, "trace")
        self.scatter_done(fig, ax, any_point, "routines.png", "ray-triangle routines: speed vs miss rate",
                          "Ray–triangle routines: speed vs misses", "speed: M ray–triangle tests/s (1 thread)",
                          "error: % of rays that miss a closed mesh")

    # 2. CPU tracer vs Embree
    def tracer(self):
        self.w("## CPU ray tracer against Embree 3 (same meshes, same rays, one run)")
        self.w()
        self.w("Watertight test, 8-wide BVH (AVX-512VL or AVX2 where the CPU has it); Embree 3.13.5 `rtcIntersect1`/"
               "`rtcOccluded1`, build quality high. Rays: primary through the pixel centres of a 1024² image (and "
               "the same view orthographic: every ray parallel to two axes), shadow (any hit) to a point light from "
               "the primary hits, mirror rays reflected there. Ours one ray at a time (`Bvh::closest`) and two rays "
               "in flight (`Bvh::closestPair`, two walks interleaved on one thread, as the tracer traces primary "
               "rays), and packets of eight neighbouring rays (`Bvh::closest8`/`occluded8`) against Embree's "
               "(`rtcIntersect8`/`rtcOccluded8`). \"ours / Embree\" is two in flight against `rtcIntersect1`. Ratios come from one run in which all take turns (each runs twice a "
               "turn, so it finds its own BVH in the caches), best of 3 turns; docs/bench/trace.md has the other "
               "runs, the work per ray counted, and what bounds each row.")
        self.w()
        bars, packet_ratios, packet_bars = [], [], []
        for m in self.m:
            secs = self.trace_sections(m)
            if secs is None:
                self.missing("tracer vs Embree", m, "trace")
                continue
            packet_rows, builds = [], []  # this machine's packets against Embree's, and the builds
            for title, sec in secs.items():
                if title.startswith("Ray/triangle"):
                    continue
                name = "1M-triangle UV sphere" if title.startswith("UV sphere") else "generated temple, Sun-Temple size"
                short = "sphere" if title.startswith("UV sphere") else "temple"
                build = re.search(r"BVH build: (.+)", sec)
                agree = re.findall(r"agreement with Embree[^\n]*|Our packets of 8[^\n]*|Embree's packets of 8[^\n]*", sec)
                times = build and re.search(r"ours ([\d.]+) s.*Embree \(quality high\) ([\d.]+) s", build.group(1))
                if times:
                    builds.append((short, float(times.group(1)), float(times.group(2))))
                for header, rows in md_tables(sec):
                    if col(header, "rays") != 0 or col(header, "Embree") is None:
                        continue
                    cr = col(header, "ours /")
                    cp = col(header, "our packets /")
                    co, ce = col(header, "packets of 8 ("), col(header, "rtcIntersect8")
                    self.w(f"**{m.label}, {name}** ({title.split(':', 1)[1].strip()})")
                    self.w()
                    if build:
                        self.w(f"BVH build: {build.group(1)}")
                        self.w()
                    self.table(header, rows)
                    for r in rows:
                        if cr is not None and num(r[cr]) is not None:
                            kind = {"shadow (any hit)": "shadow", "primary, orthographic": "ortho"}.get(r[0], r[0])
                            bars.append((f"{short} {kind} {r[1]}t\n{m.label}", num(r[cr]), m.label))
                        if cp is not None and num(r[cp]) is not None:
                            if r[0] != "mirror":
                                packet_ratios.append((num(r[cp]), m.label))
                            packet_rows.append([short, r[0], r[1], r[co] if co is not None else "–",
                                                r[ce] if ce is not None else "–", r[cp]])
                            kind = {"shadow (any hit)": "shadow", "primary, orthographic": "ortho"}.get(r[0], r[0])
                            packet_bars.append((f"{short} {kind} {r[1]}t\n{m.label}", num(r[cp]), m.label))
                    for a in agree:
                        self.w(f"- {a}")
                    self.w()
            if packet_rows:  # the packet columns of both scenes side by side, and the builds
                self.w(f"**{m.label}: packets of eight, ours (`Bvh::closest8`/`occluded8`) against Embree "
                       "(`rtcIntersect8`/`rtcOccluded8`)** (Mrays/s; ≥ 1.0× is the goal on primary, orthographic "
                       "and shadow rays; mirror rays for comparison)")
                self.w()
                self.table(["scene", "rays", "threads", "ours, packets", "Embree, packets", "ours / Embree"], packet_rows)
            if builds:
                self.w("| BVH build, all threads | ours (s) | Embree, quality high (s) | ours / Embree time |")
                self.w("|---|---:|---:|---:|")
                for short, ours, theirs in builds:
                    self.w(f"| {short} | {ours:.3f} | {theirs:.3f} | {ours / theirs:.2f}× |")
                self.w()
                worst = max(b[1] / b[2] for b in builds)
                self.goals.append((f"BVH build ≤ 1.0× Embree's high-quality build time, all threads ({m.label})",
                                   f"{worst:.2f}× (worst scene)", worst <= 1.0))
            self.source(m, "trace")
        if bars:
            self.ratio_bars(bars, "ours / Embree (Mrays/s)",
                            "CPU tracer (two rays in flight) relative to Embree rtcIntersect1 (≥ 1 is the goal)",
                            "tracer_vs_embree.png", "tracer vs Embree throughput ratio")
            for label in sorted({b[2] for b in bars}):
                mine = [b[1] for b in bars if b[2] == label]
                self.goals.append((f"CPU tracer ≥ 1.0× Embree `rtcIntersect1` (watertight, two rays in flight), every row ({label})",
                                   f"{min(mine):.2f}–{max(mine):.2f}×", min(mine) >= 1.0))
        if packet_bars:
            self.ratio_bars(packet_bars, "our packets / Embree packets (Mrays/s)",
                            "CPU tracer's packets of 8 relative to Embree rtcIntersect8/Occluded8 (≥ 1 is the goal)",
                            "tracer_packets_vs_embree.png", "tracer packets vs Embree packets throughput ratio")
        for label in sorted({p[1] for p in packet_ratios}):
            mine = [p[0] for p in packet_ratios if p[1] == label]
            self.goals.append((f"CPU tracer's packets ≥ 1.0× Embree `rtcIntersect8`, primary, orthographic and shadow rays ({label})",
                               f"{min(mine):.2f}–{max(mine):.2f}×", min(mine) >= 1.0))

    # 3. and 4. GPU passes: mips and mosaic
    def gpu_passes(self):
        rows_by_machine = {}
        for m in self.m:
            t = m.raw("gpu-passes")
            if t and not m.failed("gpu-passes"):
                for header, rows in md_tables(t):
                    if col(header, "pass") == 0:
                        rows_by_machine[m.label] = (header, rows, m)
        self.w("## Mipmaps: blit chain against compute, GPU time against error")
        self.w()
        self.w("64 textures per submission (all chains of a set in one batch), GPU time by timestamp queries. "
               "Error: against a float64 linear-light box filter (`src/core/mip_reference.hpp`), in 8-bit steps "
               "(LSB), over every texel of every level of the set's first texture.")
        self.w()
        fig, ax = plt.subplots(figsize=(6.5, 3.8))
        plotted = False
        for m in self.m:
            if m.label not in rows_by_machine:
                self.missing("mips", m, "gpu-passes")
                continue
            header, rows, _ = rows_by_machine[m.label]
            mips = [r for r in rows if r[0] == "mips"]
            self.w(f"**{m.label}**")
            self.w()
            self.table(header[1:], [r[1:] for r in mips])
            self.source(m, "gpu-passes")
            cmed, cerr = col(header, "median"), col(header, "error")
            for r in mips:
                e = re.search(r"max ([\d.]+)", r[cerr]) if cerr is not None else None
                if e:
                    x, y = num(r[cmed]), float(e.group(1))
                    ax.scatter(x, y, marker="o" if "1024" in r[1] else "s")
                    ax.annotate(f"{r[2]}, {'POT' if '1024' in r[1] else 'NPOT'}, {m.label}", (x, y),
                                fontsize=7, xytext=(4, 3), textcoords="offset points")
                    plotted = True
            if m.gpu:
                for size in ("1024x1024", "1000x600"):
                    by = {r[2]: num(r[cmed]) for r in mips if size in r[1]}
                    blit = by.get("blit")
                    comp = min((v for k, v in by.items() if k != "blit" and v is not None), default=None)
                    if blit and comp:
                        goal = 0.1 if size == "1024x1024" else 1.0
                        self.goals.append((f"compute mips ≤ {goal}× blit, 64 × {size} sRGB ({m.label})",
                                           f"{comp:.3f} vs {blit:.3f} ms = {comp / blit:.3f}×", comp / blit <= goal))
        if not self.scatter_done(fig, ax, plotted, "mips.png", "mip chains: GPU time vs max error",
                                 "Mip chains: time vs error", "speed: GPU ms per set of 64 chains (log)",
                                 "error: max |chain − float64 reference| (LSB)", xlog=True):
            self.w("- The error columns were not in these runs' output.")
            self.w()

        self.w("## Mosaic 5×3: graphics full-screen triangle against compute")
        self.w()
        self.w("RGBA16F input, RGBA8 output with explicit sRGB encode. `identical` compares the two paths' "
               "outputs byte for byte in the same run (also a test: `tests/render/mosaic_test.cpp`).")
        self.w()
        fig, ax = plt.subplots(figsize=(6, 3.4))
        bars = []
        for m in self.m:
            if m.label not in rows_by_machine:
                self.missing("mosaic", m, "gpu-passes")
                continue
            header, rows, _ = rows_by_machine[m.label]
            mos = [r for r in rows if r[0].startswith("mosaic")]
            self.w(f"**{m.label}**")
            self.w()
            self.table(header, mos)
            self.source(m, "gpu-passes")
            cmed = col(header, "median")
            by = {(r[1], r[2]): num(r[cmed]) for r in mos}
            for (size, mode), v in sorted(by.items()):
                if mode in ("compute", "graphics"):
                    bars.append((f"{mode}\n{size}\n{m.label}", v))
            if m.gpu and by.get(("3840x2160", "compute")) and by.get(("3840x2160", "graphics")):
                c, g = by[("3840x2160", "compute")], by[("3840x2160", "graphics")]
                self.goals.append((f"mosaic compute ≤ 0.05× graphics at 4K ({m.label})", f"{c:.3f} vs {g:.3f} ms = {c / g:.3f}×",
                                   c / g <= 0.05))
                self.goals.append((f"mosaic compute ≤ 0.04 ms at 4K ({m.label})", f"{c:.3f} ms", c <= 0.04))
        if bars:
            ax.bar(range(len(bars)), [b[1] for b in bars], color="tab:blue")
            ax.set_yscale("log")
            ax.set_xticks(range(len(bars)), [b[0] for b in bars], fontsize=6)
            ax.set_ylabel("GPU ms (median, log)")
            ax.set_title("Mosaic: compute vs graphics (error: 0, bit-identical)", fontsize=10)
            self.plot(fig, "mosaic.png", "mosaic GPU time, compute vs graphics")
        else:
            plt.close(fig)

    # 5. whole frame per pass
    def frames(self):
        self.w("## Whole frame per pass (`rtr-view --headless --bench`)")
        self.w()
        self.w("PBR = the brief's Beckmann/Cook-Torrance shading with alpha masking and the mosaic, on the "
               "visibility path (ids rasterised, shading in compute; the default) or the forward path "
               "(`--shading-path forward`); plain textured = mode 13 (unlit base colour, forward, same geometry, "
               "same textures, same post pass). Median GPU ms per pass over the frames.")
        self.w()
        for m in self.m:
            rows = sorted(r[:-4] for r in os.listdir(m.folder) if r.startswith("frame-") and r != "frame-compare.txt")
            if not rows:
                self.missing("frame timings", m, "frame-default-1920x1080-pbr")
                continue
            self.w(f"**{m.label}**")
            self.w()
            passes, table = [], []
            for row in rows:
                t = m.raw(row)
                _, scene, size, *variant = row.split("-")
                vals = {}
                for header, rs in md_tables(t or ""):
                    if col(header, "pass") == 0:
                        cm = col(header, "median")
                        for r in rs:
                            vals[r[0]] = num(r[cm])
                            if r[0] not in passes and r[0] != "total":
                                passes.append(r[0])
                table.append((scene, size, "-".join(variant), vals, m.failed(row)))
            names = {"pbr": "PBR, visibility path (default) + mosaic compute",
                     "pbr-forward": "PBR, forward path + mosaic compute",
                     "pbr-env": "PBR + environment (`--env sky`), visibility path + mosaic compute",
                     "pbr-graphics": "PBR, visibility path + mosaic graphics", "textured": "plain textured (mode 13)",
                     "display": "rtr-view's defaults (compute raster, no mosaic), stored view",
                     "display-inside": "rtr-view's defaults, inside view", "display-outside": "rtr-view's defaults, outside view"}
            scenes = {"default": "default (11k triangles)", "big": "Sun-Temple size (1M triangles)"}
            self.w("| scene | size | frame | " + " | ".join(passes) + " | total |")
            self.w("|---|---|---|" + "---:|" * (len(passes) + 1))
            for scene, size, variant, vals, fail in table:
                cells = [f"{vals[p]:.3f}" if p in vals else "–" for p in passes + ["total"]]
                self.w(f"| {scenes.get(scene, scene)} | {size} | {names.get(variant, variant)} | " + " | ".join(cells) +
                       " |" + (f" {fail}" if fail else ""))
            self.w()
            self.source(m, rows[0])
            if m.gpu:
                for scene in ("default", "big"):
                    tot = {(s, v): vals.get("total") for s_, s, v, vals, _ in [(x[0], x[1], x[2], x[3], 0) for x in table]
                           if s_ == scene}
                    pbr, tex = tot.get(("3840x2160", "pbr")), tot.get(("3840x2160", "textured"))
                    env = tot.get(("3840x2160", "pbr-env"))
                    if pbr and env and scene == "default":
                        self.goals.append((f"environment on adds ≤ 0.05 ms to the 4K default-scene frame ({m.label})",
                                           f"{env:.3f} vs {pbr:.3f} ms: +{env - pbr:.3f} ms", env - pbr <= 0.05))
                    t = tot.get(("3840x2160", "display"))  # issue 30's goal: the stored view
                    if t and scene == "default":
                        self.goals.append((f"default temple ≤ 0.35 ms at 4K with rtr-view's defaults, stored view ({m.label})",
                                           f"{t:.3f} ms", t <= 0.35))
                    if pbr and tex:
                        self.goals.append((f"whole frame ≤ 1.1× plain textured at 4K, {scene} scene ({m.label})",
                                           f"{pbr:.3f} vs {tex:.3f} ms = {pbr / tex:.2f}×", pbr / tex <= 1.1))

    # 6. GPU raster vs CPU trace
    def frame_compare(self):
        self.w("## Whole frame: GPU raster time against CPU trace time, with the error between them")
        self.w()
        self.w("`rtr-frame-compare`: every case of `tests/reference/poses.txt` at 1920×1080, the same shading "
               "model on both sides (PBR, no shadows, no reflections). Error: 8-bit sRGB steps, GPU against the "
               "CPU reference; failing = beyond 3 steps even against the 3×3 neighbours (docs/reference-tests.md); "
               "ꟻLIP: the ꟻLIP-style perceptual error in [0, 1] at 67 pixels per degree, mean / 99th percentile / "
               "max over the image (docs/flip.md).")
        self.w()
        fig, ax = plt.subplots(figsize=(6.5, 3.8))
        plotted = False
        for m in self.m:
            t = m.raw("frame-compare")
            if not t or m.failed("frame-compare"):
                self.missing("raster vs trace", m, "frame-compare")
                continue
            for header, rows in md_tables(t):
                self.w(f"**{m.label}**")
                self.w()
                self.table(header, rows)
                self.source(m, "frame-compare")
                cg, cc, ce = col(header, "GPU frame"), col(header, "CPU trace ms"), col(header, "mean error")
                for r in rows:
                    g, c, e = num(r[cg]), num(r[cc]), num(r[ce])
                    ax.plot([c, g], [0, e], color="0.7", lw=0.8)
                    ax.scatter([g], [e], color="tab:red", s=12)
                    ax.scatter([c], [0], color="tab:blue", s=12)
                    ax.annotate(r[0], (g, e), fontsize=6, xytext=(3, 3), textcoords="offset points")
                    plotted = True
        self.scatter_done(fig, ax, plotted, "raster_vs_trace.png", "GPU raster vs CPU trace time and error",
                          "Raster vs ray trace: time vs error",
                          "speed: ms per 1920×1080 frame (red: GPU raster, blue: CPU trace; log)",
                          "error: mean |GPU − CPU| (8-bit steps)", xlog=True)

    # The goal, sphere by sphere of the grid (with and without the sun): within 2 % of the converged tracer,
    # or the split sum itself is the cause — the exactly evaluated split sum is > 2 % off the tracer while
    # the GPU is within 2 % of that exact split sum (env_split.cpp; docs/environment.md).
    def env_goal(self, m, header, rows):
        cc, cs, ce = col(header, "case"), col(header, "sphere"), col(header, "% of mean pixel")
        co, ci = col(header, "exact split sum vs tracer"), col(header, "GPU vs exact split sum")
        if cs is None or None in (co, ci, ce):
            return
        grid = [r for r in rows if r[cc].startswith("env_sphere_grid")]
        if not grid:
            return
        within = [r for r in grid if num(r[ce]) <= 2.0]
        rest = [r for r in grid if num(r[ce]) > 2.0]
        # The GPU within 2 % of the exact split sum: what it misses the tracer by beyond that is the
        # approximation's (|GPU - tracer| <= |GPU - split sum| + |split sum - tracer|); docs/environment.md.
        caused = [r for r in rest if num(r[ci]) <= 2.0]
        text = f"{len(within)} of {len(grid)} spheres ≤ 2 %"
        if rest:
            text += (f"; the other {len(rest)} ({min(num(r[ce]) for r in rest):.1f}–{max(num(r[ce]) for r in rest):.1f} %): "
                     f"split sum's own error {min(num(r[co]) for r in rest):.1f}–{max(num(r[co]) for r in rest):.1f} %, "
                     f"GPU vs exact split sum ≤ {max(num(r[ci]) for r in rest):.1f} %")
        self.goals.append((f"mean GPU-vs-converged-CPU error ≤ 2 % of the pixel value on every sphere of the grid "
                           f"(with and without the sun) where the split sum itself is not the cause (it is where the "
                           f"GPU is within 2 % of the exact split sum; docs/environment.md; "
                           f"{m.label})", text, len(within) + len(caused) == len(grid)))

    # 6b. environment light: the GPU's split sum against the tracer, and the tracer against its sample count
    def env_compare(self):
        self.w("## Light from an environment: split sum (GPU) against Monte Carlo (CPU)")
        self.w()
        self.w("`rtr-frame-compare --env-cases`: the `env_*` cases of `tests/reference/poses.txt` lit by the generated "
               "sky alone (`--env sky`; `_nosun`: the same sky without its sun texel), GGX, no shadows on either side. "
               "Errors in linear radiance over the pixels both sides cover; `% of mean pixel` = mean |GPU − CPU| / mean "
               "CPU pixel (the goal's measure), per-pixel = the mean of |GPU − CPU| / CPU; the tracer's own noise is "
               "estimated from its image at a quarter of the samples; ꟻLIP: the ꟻLIP-style perceptual error in [0, 1] "
               "of what a display shows (both clamped to [0, 1]) over the same pixels, at 67 pixels per degree "
               "(docs/flip.md; older raw files have no such columns). Where the split sum itself is wrong and by "
               "how much: docs/environment.md.")
        self.w()
        # Where the split sum is visibly wrong: the ꟻLIP-style mean per sphere against roughness.
        curves = {}
        for m in self.m:
            t = m.raw("env-compare")
            if not t or m.failed("env-compare"):
                self.missing("split sum vs tracer", m, "env-compare")
                self.w()
                continue
            self.w(f"**{m.label}**")
            self.w()
            for header, rows in md_tables(t):
                self.table(header, rows)
                cs, cf = col(header, "sphere"), col(header, "ꟻLIP mean")
                for r in rows if cs is not None and cf is not None else []:
                    rough, metal = re.search(r"rough ([\d.]+)", r[cs]), re.search(r"metal ([\d.]+)", r[cs])
                    if rough and (r[0] in ("env_metal_spheres", "env_dielectric_spheres") or
                                  (r[0] == "env_sphere_grid_nosun" and metal and metal.group(1) in ("0.00", "1.00"))):
                        key = f"{m.label}: {r[0]}" + (f" metal {metal.group(1)}" if metal else "")
                        curves.setdefault(key, []).append((float(rough.group(1)), num(r[cf])))
                self.env_goal(m, header, rows)
            self.source(m, "env-compare")
        fig, ax = plt.subplots(figsize=(6, 3.6))
        for key, pts in curves.items():
            ax.plot([p[0] for p in pts], [p[1] for p in pts], "o-", label=key)
        if curves:
            ax.legend(fontsize=6)
        self.scatter_done(fig, ax, bool(curves), "env_flip.png", "ꟻLIP-style mean per sphere against roughness",
                          "Split sum against the tracer: ꟻLIP-style mean per sphere", "roughness",
                          "ꟻLIP-style mean (0-1)")
        fig, ax = plt.subplots(figsize=(6, 3.6))
        plotted = False
        for m in self.m:
            t = m.raw("env-spp")
            if not t or m.failed("env-spp"):
                self.missing("the tracer's error against its sample count", m, "env-spp")
                self.w()
                continue
            for header, rows in md_tables(t):
                self.w(f"**{m.label}**: the tracer's error against its sample count (against its own image at the "
                       "largest count)")
                self.w()
                self.table(header, rows)
                cs, ce, cp = col(header, "spp"), col(header, "mean abs"), col(header, "per-pixel")
                xs = [num(r[cs]) for r in rows]
                ax.plot(xs, [num(r[ce]) for r in rows], "o-", label=f"{m.label}: mean abs error")
                ax.plot(xs, [num(r[cp]) / 100 for r in rows], "s--", label=f"{m.label}: mean per-pixel relative")
                y0 = num(rows[0][ce])
                ax.plot(xs, [y0 / math.sqrt(x) for x in xs], color="0.6", lw=0.8, label="1/√N")
                plotted = True
            self.source(m, "env-spp")
        if plotted:
            ax.set_yscale("log")
            ax.legend(fontsize=7)
        self.scatter_done(fig, ax, plotted, "env_spp.png", "tracer error against samples per pixel",
                          "Tracer (MIS) error against its sample count", "sample pairs per pixel (log)",
                          "error (log)", xlog=True)

    # 7. bake
    def bake(self):
        self.w("## Bake: ours against a tinyobjloader baseline")
        self.w()
        self.w("`bench_bake` (Google Benchmark) on the generated temple at `--scale 300` (175 MB OBJ, 1.54 M "
               "vertices after welding): end to end, OBJ text to `.rtrscene` on disk. MB/s = OBJ bytes per second "
               "of wall time.")
        self.w()
        bars = []
        for m in self.m:
            t = m.raw("bake")
            if not t or m.failed("bake"):
                self.missing("bake", m, "bake")
                continue
            self.w(f"**{m.label}**")
            self.w()
            self.w("| benchmark | wall ms | MB/s | other counters |")
            self.w("|---|---:|---:|---|")
            res = {}
            for line in t.splitlines():
                mm = re.match(r"^(BM_\w+)\S*\s+([\d.]+) ms\s+([\d.]+) ms\s+\d+\s*(.*)$", line)
                if not mm:
                    continue
                counters = dict(re.findall(r"(\S+)=(\S+)", mm.group(4)))
                mbs = counters.pop("MB/s", "–")
                res[mm.group(1)] = num(mbs)
                self.w(f"| {mm.group(1)} | {mm.group(2)} | {mbs} | " + ", ".join(f"{k} {v}" for k, v in counters.items()) + " |")
                bars.append((f"{mm.group(1).replace('BM_', '')}\n{m.label}", num(mbs)))
            self.w()
            self.source(m, "bake")
            ours, base = res.get("BM_OursBake"), res.get("BM_BaselineBake")
            if ours and base and not self.goals_has("bake"):
                self.goals.append((f"bake ≥ 100 MB/s and ≥ 2× tinyobjloader ({m.label})",
                                   f"{ours:.0f} MB/s, {ours / base:.2f}×", ours >= 100 and ours / base >= 2))
        if bars:
            fig, ax = plt.subplots(figsize=(6, 3.2))
            ax.bar(range(len(bars)), [b[1] or 0 for b in bars], color="tab:purple")
            ax.set_xticks(range(len(bars)), [b[0] for b in bars], fontsize=7)
            ax.set_ylabel("MB/s of OBJ text (wall)")
            ax.set_title("Bake throughput", fontsize=10)
            self.plot(fig, "bake.png", "bake throughput")

    # 8. start-up
    def startup(self):
        self.w("## Start-up: process start to the first frame (`rtr-view --headless --timings`, 3840×2160)")
        self.w()
        self.w("The phases `--timings` prints (docs/startup.md), in ms. The critical path's rows tile the time and add "
               "up to the total; since session 15 the scene file read runs beside instance and device (its own "
               "duration is shown; \"waiting\" is what it took beyond them, on the critical path); since session 16 the first frame's pipelines are made beside the geometry upload (likewise). Cold: an empty pipeline cache; warm: the next start, the cache filled. Generated scenes: "
               "`scenegen --scale N` baked with a stored view. PNG writing is not included.")
        self.w()
        cols = [("instance and device", "instance"), ("scene file read", "scene file"), ("waiting for the read", "waiting for the scene file read"),
                ("texture decode", "texture decode"),
                ("geometry upload", "geometry upload"), ("texture upload", "texture upload"), ("mips", "mips"),
                ("renderer setup", "renderer setup"), ("pipelines ahead, beside the upload (made, cached)", "pipelines made ahead"),
                ("waiting for the pipelines", "waiting for the pipelines"), ("pipelines (made, cached)", "pipeline creation"),
                ("first frame", "first frame"), ("total", "total from process start")]
        names = {"default": "default temple (11k triangles)", "100": "scale 100 (1M)", "300": "scale 300 (3M)",
                 "1000": "scale 1000 (10M)", "10000": "scale 10000 (100M, the scale group)"}
        for m in self.m:
            rows = [r[:-4] for r in os.listdir(m.folder) if r.startswith("startup-")]
            if not rows:
                self.missing("start-up phases", m, "startup-default-cold")
                continue
            order = {"default": 0, "100": 1, "300": 2, "1000": 3, "10000": 4}
            rows.sort(key=lambda r: (order.get(r.split("-")[1], 9), r.split("-")[2] != "cold"))
            self.w(f"**{m.label}**")
            self.w()
            self.w("| scene | run | " + " | ".join(c[0] for c in cols) + " | geometry GB/s |")
            self.w("|---|---|" + "---:|" * (len(cols) + 1))
            for row in rows:
                _, scene, run = row.split("-")
                t, fail = m.raw(row) or "", m.failed(row)
                phases = dict((n.strip(), float(v)) for n, v in re.findall(r"^  (\S.*?\S) +(-?[\d.]+)$", t, flags=re.M))
                cells = []
                for _, key in cols:
                    hit = [(n, v) for n, v in phases.items() if n.startswith(key)]
                    if not hit:
                        cells.append("–")
                    elif key in ("pipeline creation", "pipelines made ahead"):
                        made = re.search(r"\((\d+), (\d+) from", hit[0][0])
                        cells.append(f"{hit[0][1]:.1f} ({made.group(1)}, {made.group(2)})" if made else f"{hit[0][1]:.1f}")
                    else:
                        cells.append(f"{hit[0][1]:.1f}")
                gb = re.search(r"geometry [\d.]+ ms \(([\d.]+) GB/s\)", t)
                self.w(f"| {names.get(scene, scene)} | {run} | " + " | ".join(cells) + f" | {gb.group(1) if gb else '–'} |" +
                       (f" {fail}" if fail else ""))
                total = phases.get("total from process start")
                if m.gpu and total and run == "warm" and scene in ("100", "1000", "10000"):
                    goal = {"100": 500, "1000": 1000, "10000": 600}[scene]
                    self.goals.append((f"first frame ≤ {goal / 1000:.1f} s from process start, {names[scene]}, warm ({m.label})",
                                       f"{total:.0f} ms", total <= goal))
                    if scene == "1000" and gb:
                        self.goals.append((f"geometry upload ≥ 10 GB/s, 10M triangles ({m.label})", f"{gb.group(1)} GB/s",
                                           float(gb.group(1)) >= 10))
            self.w()
            self.source(m, rows[0])

    # 9. scene load per format (issue 26)
    def load(self):
        self.w("## Scene load: the 1M-triangle temple as `.rtrscene`, OBJ, GLB and meshopt GLB")
        self.w()
        self.w("`bench-load`: `rtr::loadScene` split into the format's reader and the clusters built for formats that "
               "store none (`.rtrscene` stores them); GLBs made with Debian's `gltfpack` (`-cc`: EXT_meshopt_compression) "
               "from `scenegen --scale 100 --plain`; the meshopt decode alone in GB/s of output; `assimp info` (Debian "
               "assimp) on the GLBs, process start included. Seconds, median of the runs.")
        self.w()
        for m in self.m:
            t = m.raw("load")
            if not t or m.failed("load"):
                self.missing("scene load", m, "load")
                continue
            self.w(f"**{m.label}**")
            self.w()
            tables = md_tables(t)
            if tables:
                self.table(*tables[0])
                rows = {r[0]: r for r in tables[0][1]}
                h = tables[0][0]
                ci, cr = col(h, "scene in memory"), col(h, "read s")
                rt, glb = rows.get("temple.rtrscene"), rows.get("temple.glb")
                if rt and glb and ci is not None and cr is not None:
                    ratio = num(glb[cr]) / max(num(rt[cr]), 1e-9)
                    whole = num(glb[ci]) / max(num(rt[ci]), 1e-9)
                    self.goals.append((f"GLB read ≤ 2× the .rtrscene read ({m.label})",
                                       f"{ratio:.2f}× (with the clusters GLB lacks: {whole:.1f}×)", ratio <= 2))
                    a = re.search(r"^assimp info temple\.glb: ([\d.]+) s", t, flags=re.M)
                    if a:
                        speedup = float(a.group(1)) / max(num(glb[ci]), 1e-9)
                        self.goals.append((f"GLB scene in memory ≥ 10× faster than assimp ({m.label})", f"{speedup:.1f}×",
                                           speedup >= 10))
            mo = re.search(r"^meshopt decode .*?: ([\d.]+) GB/s on 1 core, ([\d.]+) GB/s on (\d+) cores", t, flags=re.M)
            if mo and m.gpu:
                best = max(float(mo.group(1)), float(mo.group(2)))
                self.goals.append((f"meshopt GLB decoded at ≥ 1 GB/s of output ({m.label})", f"{best:.2f} GB/s", best >= 1))
            for line in t.splitlines():
                if line.startswith("meshopt decode") or line.startswith("assimp") or line.startswith("# gltfpack"):
                    self.w(f"- {line.lstrip('# ')}")
            self.w()
            self.source(m, "load")

    # 10. textures ready for the GPU (issue 29)
    def textures(self):
        self.w("## Textures: a 200-texture scene as PNG files, lossless and BC baked chains")
        self.w()
        self.w("`scenegen --textures 200` (200 generated 1024² textures beside the temple's 13) baked by `rtr-bake "
               "--textures files|lossless|bc`, then `rtr-view --headless --size 1920x1080 --timings --wait-textures` "
               "three times each, the pipeline cache warm. ms; \"texture decode\" is the PNG decode (files) or the "
               "chains' unpack (baked; no mip pass). Bake seconds and the output's size (file plus texture folder).")
        self.w()
        for m in self.m:
            if not m.raw("textures-files-1"):
                self.missing("texture start-up", m, "textures-files-1")
                continue
            self.w(f"**{m.label}**")
            self.w()
            self.w("| textures as | bake s | output MB | texture decode | texture upload | mips | total (min of 3) |")
            self.w("|---|---:|---:|---:|---:|---:|---:|")
            for form in ("files", "lossless", "bc"):
                runs = []
                for k in (1, 2, 3):
                    t = m.raw(f"textures-{form}-{k}") or ""
                    ph = dict((n.strip(), float(v)) for n, v in re.findall(r"^  (\S.*?\S) +(-?[\d.]+)$", t, flags=re.M))
                    if "total from process start" in ph:
                        runs.append(ph)
                b = m.raw(f"textures-bake-{form}") or ""
                bt = re.search(r"total ([\d.]+) s", b)
                size = re.search(r"^(\d+)\s", b, flags=re.M)
                if not runs:
                    self.w(f"| {form} | – | – | – | – | – | failed |")
                    continue
                best = min(runs, key=lambda ph: ph["total from process start"])
                cell = lambda key: f"{best[key]:.0f}" if key in best else "–"
                mb = f"{int(size.group(1)) / 1e6:.0f}" if size else "–"
                self.w(f"| {form} | {bt.group(1) if bt else '–'} | {mb} | {cell('texture decode')} | "
                       f"{cell('texture upload')} | {cell('mips')} | {cell('total from process start')} |")
                if form == "bc":  # the goals: 0.35 s on the GPU machines, 0.6 s on lavapipe (2 cores)
                    total, goal = best["total from process start"], 600 if m.label.startswith("vm") else 350
                    self.goals.append((f"200-texture scene, first frame with textures ≤ {goal / 1000:.2f} s ({m.label}, bc)",
                                       f"{total:.0f} ms", total <= goal))
            self.direct_open(m)
            self.w()
            self.source(m, "textures-bc-1")

    # The OBJ opened directly, first open (decodes, fills the texture cache) against the second (reads it).
    def direct_open(self, m):
        part_keys = ("texture decode", "texture upload", "mips", "texture cache read-back")
        rows = {}
        for open_ in ("first", "second"):
            for k in (1, 2, 3):
                t = m.raw(f"textures-direct-{open_}-{k}") or ""
                ph = dict((n.strip(), float(v)) for n, v in re.findall(r"^  (\S.*?\S) +(-?[\d.]+)$", t, flags=re.M))
                if "total from process start" in ph:
                    rows.setdefault(open_, []).append((sum(ph.get(key, 0.0) for key in part_keys), ph["total from process start"]))
        if len(rows) < 2:
            return
        for open_, what in (("first", "OBJ opened directly, first open (decoded, cache filled)"),
                            ("second", "OBJ opened directly, second open (texture cache read)")):
            parts = [p for p, _ in rows[open_]]
            totals = [t for _, t in rows[open_]]
            self.w(f"| {what} | – | – | texture part {min(parts):.0f}–{max(parts):.0f} | | | {min(totals):.0f} |")
        first, second = min(p for p, _ in rows["first"]), min(p for p, _ in rows["second"])
        if second > 0:
            self.goals.append((f"second direct open of a textured OBJ ≥ 3× faster than the first (texture part: decode, "
                               f"upload, mips, cache read-back; best of 3 each; {m.label})",
                               f"{first:.0f} vs {second:.0f} ms = {first / second:.1f}×", first / second >= 3))

    def goals_has(self, word):
        return any(word in g[0] for g in self.goals)


def main():
    data = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "docs/bench/data")
    doc = sys.argv[2] if len(sys.argv) > 2 else os.path.join(ROOT, "docs/BENCHMARKS.md")
    folders = sorted(os.path.join(data, d) for d in os.listdir(data) if os.path.exists(os.path.join(data, d, "meta.txt")))
    if not folders:
        sys.exit(f"render.py: {data}: no machine folders (each needs a meta.txt from tools/report/collect.sh)")
    machines = [Machine(f) for f in folders]
    rep = Report(machines, os.path.join(os.path.dirname(doc), "bench/plots"))
    rep.routines()
    rep.tracer()
    rep.gpu_passes()
    rep.frames()
    rep.frame_compare()
    rep.env_compare()
    rep.bake()
    rep.startup()
    rep.load()
    rep.textures()
    scale.section(rep)

    head = ["# Benchmark report: speed beside error", "",
            "Generated by `tools/report.sh` (`tools/report/collect.sh` runs every command on a machine and keeps "
            "its raw output in `docs/bench/data/<machine>/`; `tools/report/render.py` writes this page and the "
            "plots from those files). Do not edit by hand: every number below is in a raw file, with the exact "
            "command on its first line. GPU times are timestamp queries (median over the stated frames or "
            "submissions after warm-up).", "", "## Machines", ""]
    for m in machines:
        head.append(f"- **{m.label}**: {m.caption()}" + (" (quick run: fewer frames)" if m.meta.get("quick") == "1" else ""))
    head += ["", "## Goals (set in `tools/report/render.py`)", "", "| goal | measured | met? |", "|---|---|---|"]
    for g, v, ok in rep.goals:
        head.append(f"| {g} | {v} | {'yes' if ok else '**no**'} |")
    head.append("")
    notes = os.path.join(data, "NOTES.md")  # hand-written context that the numbers need, kept with the data
    if os.path.exists(notes):
        head += [open(notes).read().rstrip(), ""]
    with open(doc, "w") as f:
        f.write("\n".join(head + rep.out).rstrip() + "\n")
    print(f"render.py: wrote {doc} and {rep.plots}/*.png from {len(machines)} machine(s)")


if __name__ == "__main__":
    main()
