#!/usr/bin/env python3
"""The first picture of a file (issue 28), as a user meets it: rtr-view --headless and rtr-trace on models
nobody here wrote (Debian's assimp-testmodels) and on small files of our own (tests/first_minute/models),
with no options but the output.

Usage: first_minute_test.py BIN_DIR [--keep DIR]
Each model must render with exit 0, framed and lit (no empty-image warning, enough lit pixels), and the two
tools must show the same picture: same pose, same shading (PBR for models), both sides drawn in both.
Exit 0 pass, 1 fail, 77 when assimp-testmodels is not installed.
"""
import os
import re
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, ".."))
from pngread import read_png  # noqa: E402

ASSIMP = "/usr/share/assimp/models/OBJ"
OWN = os.path.join(HERE, "models")
SIZE = (160, 120)
# (file, extra options): models get PBR in both tools and must match.
MODELS = [(f"{ASSIMP}/box.obj", []), (f"{ASSIMP}/WusonOBJ.obj", []), (f"{ASSIMP}/cube_usemtl.obj", []),
          (f"{ASSIMP}/regr01.obj", ["--up", "+Z"]), (f"{ASSIMP}/spider.obj", []),
          (f"{OWN}/torus_no_vn.obj", []), (f"{OWN}/vertex_colors.obj", [])]
failures = []


def check(cond, msg):
    print(("ok: " if cond else "FAIL: ") + msg, flush=True)
    if not cond:
        failures.append(msg)


def run(cmd):
    return subprocess.run(cmd, capture_output=True, text=True, timeout=300)


def render(bins, out, model, extra, tool):
    png = os.path.join(out, f"{os.path.basename(model)}.{tool}.png")
    size = f"{SIZE[0]}x{SIZE[1]}"
    cmd = ([f"{bins}/rtr-view", model, "--headless", "-o", png, "--size", size, "--force"] if tool == "view" else
           # A black backdrop: the checks count lit pixels against black (rtr-trace's default is mid-grey).
           [f"{bins}/rtr-trace", model, "-o", png, "--size", size, "--force", "--background", "0"]) + extra
    r = run(cmd)
    return r, png


def lit_fraction(rgb):
    n = len(rgb) // 3
    return sum(1 for i in range(n) if max(rgb[3 * i:3 * i + 3]) >= 16) / n


def mean_diff(a, b):
    return sum(abs(x - y) for x, y in zip(a, b)) / len(a)


def main():
    if len(sys.argv) < 2:
        print(__doc__)
        return 2
    bins = sys.argv[1]
    if not os.path.isdir(ASSIMP):
        print("skip: assimp-testmodels is not installed (tools/setup.sh installs it)")
        return 77
    keep = sys.argv[sys.argv.index("--keep") + 1] if "--keep" in sys.argv else None
    tmp = tempfile.TemporaryDirectory(prefix="rtr-first-minute-")
    out = keep or tmp.name
    os.makedirs(out, exist_ok=True)

    for model, extra in MODELS:
        name = os.path.basename(model)
        images = {}
        for tool in ("view", "trace"):
            r, png = render(bins, out, model, extra, tool)
            check(r.returncode == 0, f"{name}: rtr-{tool} exit 0 ({r.returncode}) {r.stderr.strip()[-300:] if r.returncode else ''}")
            if r.returncode:
                continue
            check("warning: the" not in r.stderr, f"{name}: rtr-{tool} gives no empty-image warning")
            w, h, rgb = read_png(png)
            images[tool] = rgb
            check(lit_fraction(rgb) > 0.03, f"{name}: rtr-{tool}'s image is framed and lit "
                  f"({100 * lit_fraction(rgb):.1f} % of pixels lit)")
        if len(images) == 2:
            d = mean_diff(images["view"], images["trace"])
            check(d < 6.0, f"{name}: rtr-view and rtr-trace show the same picture (mean difference {d:.2f} of 255)")

    # The staged box (a Cornell box of our own, its light without Ke): seen from its open side in both, lit.
    box = f"{OWN}/open_box.obj"
    for tool in ("view", "trace"):
        r, png = render(bins, out, box, [], tool)
        check(r.returncode == 0 and "warning: the" not in r.stderr, f"open_box: rtr-{tool} exit 0, no warning")
        w, h, rgb = read_png(png)
        c = (h // 2 * w + w // 2) * 3
        check(max(rgb[c:c + 3]) >= 40, f"open_box: rtr-{tool} looks in through the open side at the lit back wall "
              f"(centre pixel {tuple(rgb[c:c + 3])})")
        if tool == "trace":
            m = re.search(r"pose \S+,\S+,(\S+),(\S+),(\S+) ->", r.stderr)
            check(m and float(m.group(2)) == 180 and float(m.group(3)) == 0 and float(m.group(1)) < 0,
                  f"open_box: framed level from -z, the open side ({m.group(0) if m else r.stderr[-200:]})")
            check("Blinn-Phong shading: one of the course's scenes" in r.stderr,
                  "open_box: rtr-trace picks the course's Blinn-Phong for a scene lit by its *light* material")

    # --crease: 0 (flat) and 180 (smooth) give different pictures of the torus in both tools.
    torus = f"{OWN}/torus_no_vn.obj"
    for tool in ("view", "trace"):
        _, flat = render(bins, out, torus, ["--crease", "0"], tool)
        flat_rgb = read_png(flat)[2]
        os.rename(flat, flat + ".flat.png")
        _, smooth = render(bins, out, torus, ["--crease", "180"], tool)
        d = mean_diff(flat_rgb, read_png(smooth)[2])
        check(d > 0.5, f"torus: rtr-{tool} --crease 0 and 180 differ (mean difference {d:.2f})")

    # A folder on the command line stands for its scene files: --headless takes one, and says how many it got.
    r = run([f"{bins}/rtr-view", OWN, "--headless", "-o", os.path.join(out, "x.png")])
    check(r.returncode == 2 and "3 given" in r.stderr, f"a folder gives its 3 scene files ({r.stderr.strip()[-120:]})")

    # rtr-bake takes --up and --crease as the renderers do: the baked Z-up house renders as the OBJ does.
    baked = os.path.join(out, "regr01", "regr01.rtrscene")
    r = run([f"{bins}/rtr-bake", f"{ASSIMP}/regr01.obj", baked, "--up", "+Z", "--crease", "0", "--force"])
    check(r.returncode == 0, f"rtr-bake --up +Z --crease 0 exit 0 ({r.stderr.strip()[-200:]})")
    if r.returncode == 0:
        _, from_obj = render(bins, out, f"{ASSIMP}/regr01.obj", ["--up", "+Z", "--crease", "0"], "view")
        _, from_bake = render(bins, out, baked, [], "view")
        d = mean_diff(read_png(from_obj)[2], read_png(from_bake)[2])
        check(d < 0.5, f"the baked scene renders as the OBJ with the same --up and --crease (mean difference {d:.2f})")

    print(f"{len(failures)} failure(s)" if failures else "all passed", flush=True)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
