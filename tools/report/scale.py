"""The report's scale section (tools/report/render.py): collect.sh's `scale` group, issues 29 and 30 at
100 M triangles and a billion instanced ones: the bake by phase, and frames by view and level of detail."""
import os
import re

from tables import md_tables

import matplotlib.pyplot as plt


def _f(pattern, text, cast=float):
    m = re.search(pattern, text or "")
    return cast(m.group(1)) if m else None


def _n(row, key):
    return "–" if not row or row[key] is None else f"{row[key]:,}".replace(",", " ")


def bake_row(t):
    """rtr-bake's phase line, its cpu line and /usr/bin/time -v's peak memory, from one raw file."""
    phases = dict((k, float(v)) for k, v in re.findall(r"(\w+) ([\d.]+) s", t.split("time:", 1)[-1].split("\n")[0]))
    cpu = sum(float(v) for v in re.findall(r"\w+ ([\d.]+) s", t.split("cpu (all threads):", 1)[-1].split("\n")[0]))
    return {"phases": phases, "cpu": cpu, "mbs": _f(r"parse [\d.]+ s \(([\d.]+) MB/s", t),
            "triangles": _f(r"triangles (\d+)", t, int), "rss": _f(r"Maximum resident set size \(kbytes\): (\d+)", t),
            "bytes": _f(r"(?m)^-\S+ +\d+ +\S+ +\S+ +(\d+) ", t, int)}


def frame_row(t):
    """min and median total ms of a --bench run, the passes' medians, and the cull counts."""
    passes = {}
    for header, rows in md_tables(t or ""):
        if header and header[0] == "pass":
            passes = {r[0]: (float(r[1]), float(r[2])) for r in rows if len(r) >= 3}
    return {"passes": passes, "listed": _f(r"(\d+) triangles listed", t, int),
            "tests": _f(r"cull: (\d+) cluster tests", t, int), "nodes": _f(r"and (\d+) tree node tests", t, int),
            "triangles": _f(r" (\d+) triangles, ", t, int)}


def section(rep):
    rep.w("## Scale: the temple at 100 M triangles and 100 instances of the 10 M temple")
    rep.w()
    rep.w("`collect.sh`'s `scale` group (issues 29 and 30): `scenegen --scale 10000` (101.7 M triangles; a quick run: "
          "`--scale 1000`) baked by `rtr-bake` without (`--no-lod`) and with the cluster hierarchy under "
          "`/usr/bin/time -v`; then that file's 4K frames (quick: 1080p) in the stored, inside and outside views at "
          "full detail (`--lod-error 0`) and at 1 px, compute raster with culling on; and `scenegen --scale 1000 "
          "--instances 100` (quick: `--scale 100`): the base temple alone and the grid of 100 instances in three "
          "views. Frame ms are min / median over the run's frames. CPU cores busy: the phases' CPU time over the "
          "bake's wall time.")
    rep.w()
    for m in rep.m:
        rows = sorted(r[:-4] for r in os.listdir(m.folder) if r.startswith("scale-"))
        if not rows:
            rep.missing("the scale rows", m, "scale-bake-10000-lod")
            continue
        rep.w(f"**{m.label}**")
        rep.w()
        bakes = {r.rsplit("-", 1)[1]: bake_row(m.raw(r)) for r in rows if r.startswith("scale-bake-") and not m.failed(r)}
        keys = ["parse", "weld", "clusters", "hierarchy", "write", "total"]
        rep.w("| bake | triangles | " + " | ".join(f"{k} s" for k in keys) + " | parse MB/s | CPU cores busy | peak memory GB | "
              "output GB | memory ÷ output |")
        rep.w("|---|" + "---:|" * (len(keys) + 6))
        for kind, b in sorted(bakes.items(), key=lambda kv: kv[0] != "nolod"):
            total, out = b["phases"].get("total"), b["bytes"]
            rss = b["rss"] * 1024 / 1e9 if b["rss"] else None
            cells = [f"{b['phases'][k]:.2f}" if k in b["phases"] else "–" for k in keys]
            cells += [f"{b['mbs']:.0f}" if b["mbs"] else "–", f"{b['cpu'] / total:.1f}" if total else "–",
                      f"{rss:.2f}" if rss else "–", f"{out / 1e9:.2f}" if out else "–",
                      f"{rss / (out / 1e9):.2f}×" if rss and out else "–"]
            rep.w(f"| {'without the hierarchy' if kind == 'nolod' else 'with the hierarchy'} | {b['triangles'] or '–'} | " +
                  " | ".join(cells) + " |")
        rep.w()
        frames = {r: frame_row(m.raw(r)) for r in rows if r.startswith("scale-frame-")}
        grid_n = _f(r"(\d+) instances", m.raw("scale-grid-gen") or "", int) or 0
        order = {"stored": 0, "inside": 1, "outside": 2}
        scenes = sorted({r.rsplit("-", 1)[0] for r in frames},
                        key=lambda s: ("grid" in s, len(s.rsplit("-", 1)[0]), s.rsplit("-", 1)[0], order.get(s.rsplit("-", 1)[1], 9)))
        rep.w("| scene | view | source triangles | full detail ms | 1 px ms | 1 px: triangles listed | 1 px: cluster / node "
              "tests | 1 px: cull / raster / shade median ms (both phases) | 1 px, `--cull frustum` ms |")
        rep.w("|---|---|---:|---:|---:|---:|---:|---|---:|")
        at1, at1f = {}, {}
        for s in scenes:
            body = s[len("scale-frame-"):]
            name, view = body.rsplit("-", 1)
            f0, f1, f1f = frames.get(s + "-0"), frames.get(s + "-1"), frames.get(s + "-1f")
            tri = (f1 or f0)["triangles"] or 0
            src = tri * grid_n if name.startswith("grid") else tri
            label = f"{src / 1e6:.1f} M" + (f" ({grid_n} × {tri / 1e6:.1f} M)" if name.startswith("grid") else "")
            cell = lambda f: f"{f['passes']['total'][0]:.3f} / {f['passes']['total'][1]:.3f}" if f and "total" in f["passes"] else "–"  # noqa: E731
            # Both phases' rows where culling ran in two ("cull early" + "cull", "raster early" + "raster").
            part = lambda p: sum(f1["passes"][q][1] for q in (p, p + " early") if q in f1["passes"])  # noqa: E731
            parts = " / ".join(f"{part(p):.3f}" if f1 and p in f1["passes"] else "–" for p in ("cull", "raster", "shade"))
            scene = f"grid, 100 × scale {name[4:]}" if name.startswith("grid") else f"temple, scale {name}"
            rep.w(f"| {scene} | {view} | {label} | "
                  f"{cell(f0)} | {cell(f1)} | {_n(f1, 'listed')} | {_n(f1, 'tests')} / {_n(f1, 'nodes')} | {parts} | "
                  f"{cell(f1f)} |")
            if f1 and "total" in f1["passes"]:
                at1[(name, view)] = (src, f1["passes"]["total"][1])
            if f1f and "total" in f1f["passes"]:
                at1f[(name, view)] = (src, f1f["passes"]["total"][1])
        rep.w()
        rep.source(m, [r for r in rows if r.startswith("scale-bake-")][-1] if bakes else rows[-1])
        rep.source(m, sorted(frames)[-1] if frames else rows[-1])
        plot(rep, m, at1)
        if m.gpu:
            goals(rep, m, bakes, at1)
            frame_goals(rep, m, at1f, ", `--cull frustum`")


def plot(rep, m, at1):
    stored = sorted(v for (n, view), v in at1.items() if view == "stored")
    if len(stored) < 2:
        return
    fig, ax = plt.subplots(figsize=(6, 3.5))
    ax.plot([s for s, _ in stored], [t for _, t in stored], "o-")
    ax.set_xscale("log")
    ax.set_ylim(bottom=0)
    ax.set_xlabel("source triangles")
    ax.set_ylabel("frame ms (median), 1 px")
    ax.set_title(f"{m.label}: stored view at 1 px against the scene's size", fontsize=10)
    ax.grid(alpha=0.3)
    rep.plot(fig, f"scale-{m.label}.png", f"{m.label}: frame time at 1 px against source triangles")


def goals(rep, m, bakes, at1):
    g = rep.goals
    nolod, lod = bakes.get("nolod"), bakes.get("lod")
    if nolod and "total" in nolod["phases"] and (nolod["triangles"] or 0) > 50e6:
        t = nolod["phases"]["total"]
        g.append((f"100 M-triangle bake ≤ 15 s, without the hierarchy ({m.label})", f"{t:.1f} s", t <= 15))
        if nolod["mbs"]:
            g.append((f"100 M-triangle bake: OBJ parse ≥ 1 GB/s ({m.label})", f"{nolod['mbs']:.0f} MB/s", nolod["mbs"] >= 1000))
        if nolod["rss"] and nolod["bytes"]:
            r = nolod["rss"] * 1024 / nolod["bytes"]
            g.append((f"100 M-triangle bake: peak memory ≤ 2× the output ({m.label})", f"{r:.2f}×", r <= 2.0))
        if lod and "total" in lod["phases"]:
            r = lod["phases"]["total"] / t
            g.append((f"100 M-triangle bake with the hierarchy ≤ 3× the bake without it ({m.label})",
                      f"{lod['phases']['total']:.1f} s = {r:.2f}×", r <= 3))
            if lod["bytes"] and nolod["bytes"]:
                r = lod["bytes"] / nolod["bytes"]
                g.append((f"file with the hierarchy ≤ 2.5× the base mesh's ({m.label})", f"{r:.2f}×", r <= 2.5))
    frame_goals(rep, m, at1, "")


def frame_goals(rep, m, at1, how):
    """Issue 30's frame goals from the 1 px rows of one culling mode (`how`: how the label names it)."""
    g = rep.goals
    for (name, view), (src, ms) in sorted(at1.items()):
        if name.startswith("grid") and src > 0.9e9:
            g.append((f"a billion instanced triangles ≤ 1.0 ms at 4K, 1 px, {view} view ({m.label}{how})", f"{ms:.3f} ms", ms <= 1.0))
        elif not name.startswith("grid") and src > 90e6:
            g.append((f"100 M-triangle temple ≤ 0.6 ms at 4K, 1 px, {view} view ({m.label}{how})", f"{ms:.3f} ms", ms <= 0.6))
    stored = [ms for (n, view), (src, ms) in at1.items() if view == "stored"]
    if len(stored) >= 3:
        r = max(stored) / min(stored)
        g.append((f"frame time flat from 10 M to 1 B source triangles, stored view at 1 px: largest ≤ 1.2× smallest ({m.label}{how})",
                  f"{min(stored):.3f}–{max(stored):.3f} ms = {r:.2f}×", r <= 1.2))
