#!/usr/bin/env python3
"""Runs every .obj (or, with --gltf, every .gltf and .glb) of Debian's assimp-testmodels through rtr-bake,
rtr-view and rtr-trace.

Each tool must render the model or refuse it with a message naming the file; none may crash (signal)
or hang (timeout). Rendered images must not be all black, and models whose MTL has a map_Kd (glTF: whose
materials have a base colour texture) must show texture-like colour variety. Exit 0: all good, 1: a
failure, 77: the corpus is not installed (CTest skip).
Usage: run_corpus.py BIN_DIR [--gltf] [--table] [--timeout S] [--keep DIR]
"""
import json, os, re, struct, subprocess, sys, tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from pngread import read_png  # noqa: E402

CORPUS = ["/usr/share/assimp/models/OBJ", "/usr/share/assimp/models/invalid"]
GLTF_CORPUS = "/usr/share/assimp/models/glTF2"
SIZE = "320x240"


def image_stats(path):
    """(brightest channel value, number of distinct coloured (not grey) 4-bit-per-channel colours)."""
    _, _, rgb = read_png(path)
    brightest, colours = 0, set()
    for i in range(0, len(rgb), 3):
        r, g, b = rgb[i], rgb[i + 1], rgb[i + 2]
        brightest = max(brightest, r, g, b)
        if max(r, g, b) - min(r, g, b) > 8:
            colours.add((r >> 4, g >> 4, b >> 4))
    return brightest, len(colours)


def gltf_textured(path):
    """Whether a glTF file parses and some material of it has a base colour texture whose image exists."""
    try:
        data = open(path, "rb").read()
        if data[:4] == b"glTF":
            n = struct.unpack("<I", data[12:16])[0]
            data = data[20:20 + n]
        doc = json.loads(data)
        images = doc.get("images", [])
        for m in doc.get("materials", []):
            t = m.get("pbrMetallicRoughness", {}).get("baseColorTexture")
            if t is None: continue
            src = doc["textures"][t["index"]].get("source")
            uri = images[src].get("uri", "data:") if src is not None else None
            if uri and (uri.startswith("data:") or os.path.isfile(os.path.join(os.path.dirname(path), uri))):
                return True
            if src is not None and "bufferView" in images[src]:
                return True
    except (ValueError, KeyError, IndexError, TypeError, AttributeError, struct.error):
        pass
    return False


def textured(obj):
    """Whether an MTL of the model (named by mtllib, or NAME.mtl beside it) has a map_Kd."""
    folder, libs = os.path.dirname(obj), []
    with open(obj, "rb") as f:
        for line in f:
            m = re.match(rb"\s*mtllib\s+(.+?)\s*$", line)
            if m: libs.append(m.group(1).decode("latin-1"))
    if not libs: libs = [os.path.splitext(os.path.basename(obj))[0] + ".mtl"]
    for lib in libs:
        p = os.path.join(folder, lib)
        if os.path.isfile(p) and re.search(rb"^\s*map_Kd\s", open(p, "rb").read(), re.M):
            return True
    return False


def run(cmd, obj, timeout):
    """'ok', 'refused', or a failure ('CRASH ...', 'HANG', 'UNNAMED ...') with the message's first line."""
    try:
        p = subprocess.run(cmd, capture_output=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return "HANG", ""
    err = p.stderr.decode("utf-8", "replace")
    if p.returncode < 0 or p.returncode >= 128:
        return "CRASH (signal %d)" % (-p.returncode if p.returncode < 0 else p.returncode - 128), err
    if p.returncode != 0:
        lines = [l for l in err.splitlines() if "error" in l]
        msg = lines[-1] if lines else err.strip().splitlines()[-1] if err.strip() else ""
        return ("refused" if obj in msg else "UNNAMED refusal"), msg
    return "ok", err


def main():
    args = sys.argv[1:]
    if not args:
        print(__doc__)
        return 2
    bindir, table, gltf = args[0], "--table" in args, "--gltf" in args
    timeout = float(args[args.index("--timeout") + 1]) if "--timeout" in args else 120.0
    if gltf:
        objs = sorted(os.path.join(d, f) for d, _, files in os.walk(GLTF_CORPUS) for f in files
                      if f.endswith((".gltf", ".glb")))
    else:
        objs = sorted(os.path.join(d, f) for d in CORPUS if os.path.isdir(d) for f in os.listdir(d) if f.endswith(".obj"))
    is_textured = gltf_textured if gltf else textured
    if not objs:
        print("corpus not installed (Debian package assimp-testmodels): skipped")
        return 77
    keep = args[args.index("--keep") + 1] if "--keep" in args else None
    tmp = keep or tempfile.mkdtemp(prefix="rtr_corpus_")
    os.makedirs(tmp, exist_ok=True)
    bake, view, trace = (os.path.join(bindir, t) for t in ("rtr-bake", "rtr-view", "rtr-trace"))
    failures, rows = [], []
    for obj in objs:
        name = os.path.splitext(os.path.relpath(obj, GLTF_CORPUS) if gltf else os.path.basename(obj))[0]
        out = os.path.join(tmp, name.replace(os.sep, "_"))
        os.makedirs(out, exist_ok=True)
        cells, notes = [], []
        name = os.path.basename(name)
        r1 = run([bake, obj, os.path.join(out, name + ".rtrscene"), "--force"], obj, timeout)
        r2 = r1 if gltf else run([bake, obj, os.path.join(out, name + ".comp5892mesh"), "--force"], obj, timeout)
        cells.append(r1[0] if r1[0] == r2[0] else r1[0] + "/" + r2[0])
        for tool, cmd, png in (
                ("view", [view, "--headless", "--mosaic", "off", "--size", SIZE, "--screenshot", os.path.join(out, "view.png"), obj], "view.png"),
                # Textured models in the tracer's pbr mode, the viewer's model: its default Blinn-Phong (the
                # course's) samples map_Kd too, but Ka + Kd of these MTLs saturate it to near white.
                # A black backdrop: "BLACK image" is judged against black (the default is mid-grey).
                ("trace", [trace, "-q", "--size", SIZE, obj, "-o", os.path.join(out, "trace.png"), "--background", "0"] +
                 (["--shading", "pbr"] if is_textured(obj) else []), "trace.png")):
            outcome, msg = run(cmd, obj, timeout)
            if outcome == "ok":
                brightest, colours = image_stats(os.path.join(out, png))
                if brightest < 16:
                    outcome = "BLACK image"
                elif is_textured(obj) and colours < (20 if gltf else 24):
                    outcome = "NO TEXTURE (%d colours)" % colours
                else:
                    outcome = "ok (max %d, %d colours)" % (brightest, colours)
            cells.append(outcome)
            if outcome.startswith("refused"): notes.append(msg.split(": error: ")[-1])
        if r1[0] == "refused": notes.insert(len(notes) if gltf else 0, r1[1].split(": error: ")[-1])
        for c in cells:
            if c.split(" ")[0].isupper() or c.startswith(("CRASH", "HANG", "UNNAMED", "BLACK", "NO ")):
                failures.append("%s: %s" % (obj, c))
        note = notes[0].replace(obj, "FILE") if notes else ""
        rows.append((os.path.relpath(obj, "/usr/share/assimp/models"), cells, note))
    if table:
        print("| file | bake | view | trace | note |\n|---|---|---|---|---|")
        for f, c, n in rows:
            print("| %s | %s | %s | %s | %s |" % (f, c[0], c[1], c[2], n.replace("|", "\\|")))
    else:
        for f, c, n in rows:
            print("%-40s bake %-10s view %-28s trace %-28s %s" % (f, c[0], c[1], c[2], n))
    for f in failures:
        print("FAIL", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
