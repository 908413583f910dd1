#!/usr/bin/env python3
"""A small fault review (issue 33): generated and corrupted OBJ, .rtrscene and .comp5892mesh files through
rtr-bake and rtr-trace, each run under a timeout, and a table of what happened:

  crash    the tool died of a signal            hang     it ran past the timeout
  unnamed  it failed without naming the input   damaged  a failed `rtr-bake --force` changed the older output
  usage    exit 2 on a file (a usage error is for options, not for input)

Every one of these must be 0. `fault_review.py BIN_DIR SOURCE_DIR [COUNT] [SEED]`; ctest runs a small COUNT.
"""
import math
import os
import random
import shutil
import subprocess
import sys
import tempfile

BIN, SRC = sys.argv[1], sys.argv[2]
COUNT = int(sys.argv[3]) if len(sys.argv) > 3 else 300
rng = random.Random(int(sys.argv[4]) if len(sys.argv) > 4 else 33)
TIMEOUT = 20

VALUES = ["0", "1", "-1", "0.5", "1e38", "-1e38", "3.4e38", "1e20", "-1e20", "1e12", "1e13", "1e-38", "1e-45",
          "nan", "inf", "-inf", "1e400", "0x10", "", "abc", "1e", "--1", "7" * 60]


BAD = 0.0  # the chance of a hostile number, chosen per file


def number():
    return rng.choice(VALUES) if rng.random() < BAD else f"{rng.uniform(-10, 10):.4f}"


def one_huge_value():
    """The review's shape: a small valid mesh with one enormous coordinate (it aborted all tools)."""
    n = rng.randint(3, 8)
    vs = [[f"{rng.uniform(-10, 10):.4f}" for _ in range(3)] for _ in range(n)]
    vs[rng.randrange(n)][rng.randrange(3)] = rng.choice(["-1e38", "1e38", "3.4e38", "1e20", "-1e19", "1e13", "1e12"])
    faces = [f"f 1 {k} {k + 1}" for k in range(2, n)]
    return "\n".join(["v " + " ".join(v) for v in vs] + faces).encode()


def random_obj():
    global BAD
    if rng.random() < 0.2:
        return one_huge_value()
    BAD = rng.choice([0, 0, 0.003, 0.02, 0.2])
    lines, nv = [], rng.randint(0, 40)
    for _ in range(nv):
        lines.append("v " + " ".join(number() for _ in range(rng.choice([2, 4]) if rng.random() < BAD else 3)))
    if rng.random() < 0.3:
        lines += ["vt 0.5 0.5", "vn 0 0 1", "vn nan 0 0"]
    for _ in range(rng.randint(0, 40)):
        k = rng.choice([2, 12]) if rng.random() < BAD else rng.choice([3, 3, 4, 5])
        idx = [str(rng.choice([rng.randint(1, max(1, nv)), rng.randint(-nv - 2, 0), nv + 1, 2 ** 31, 2 ** 33]))
               if rng.random() < BAD else str(rng.randint(1, max(1, nv))) for _ in range(k)]
        lines.append("f " + " ".join(i + (rng.choice(["/1", "//1", "/1/1", "/x"]) if rng.random() < BAD else "")
                                     for i in idx))
    extras = ["mtllib /dev/zero", "mtllib missing.mtl", "mtllib ../../../etc/passwd", "usemtl " + "m" * 40000,
              "o", "g a b", "s 1", "l 1 2", "p 1", "\x00\x01", "\xff\xfe", "#" * 100000, "f", "v"]
    for _ in range(rng.choice([0, 0, 1, 3])):
        lines.insert(rng.randint(0, len(lines)), rng.choice(extras))
    text = "\n".join(lines)
    if rng.random() < 0.05:
        text = text[: rng.randint(0, len(text))]
    return text.encode("utf-8", "surrogateescape") if isinstance(text, str) else text


def corrupt(data):
    b = bytearray(data)
    for _ in range(rng.randint(1, 8)):
        op = rng.random()
        if op < 0.5 and b:
            i = rng.randrange(len(b))
            b[i] = rng.randrange(256)
        elif op < 0.7 and b:
            i = rng.randrange(len(b))
            b[i:i + 4] = rng.choice([b"\xff\xff\xff\x7f", b"\x00\x00\x80\x7f", b"\x00\x00\xc0\x7f", b"\x99\x76\x96\x7e"])
        elif op < 0.85:
            del b[rng.randrange(len(b) + 1):]
        else:
            b += bytes(rng.randrange(256) for _ in range(rng.randint(1, 64)))
    return bytes(b)


def snapshot(d):
    out = {}
    for root, _, files in os.walk(d):
        for f in files:
            with open(os.path.join(root, f), "rb") as fh:
                out[os.path.relpath(os.path.join(root, f), d)] = fh.read()
    return out


def run(tool, args):
    try:
        p = subprocess.run([os.path.join(BIN, tool)] + args, capture_output=True, text=True, errors="replace",
                           timeout=TIMEOUT)
        return p.returncode, p.stderr
    except subprocess.TimeoutExpired:
        return "hang", ""


def main():
    tmp = tempfile.mkdtemp(prefix="rtr_review_")
    table = {}  # (tool, kind) -> counts
    examples = []

    def record(tool, kind, name, rc, err, damaged=False):
        row = table.setdefault((tool, kind), {"runs": 0, "ok": 0, "error": 0, "crash": 0, "hang": 0, "unnamed": 0,
                                               "usage": 0, "damaged": 0})
        row["runs"] += 1
        verdict = None
        if rc == "hang":
            verdict = "hang"
        elif rc < 0:
            verdict = "crash"
        elif rc == 2:
            verdict = "usage"
        elif rc == 1 and name not in err and "/dev/zero" not in err:
            verdict = "unnamed"
        if damaged:
            row["damaged"] += 1
            examples.append(f"damaged: {tool} {name}")
        if verdict:
            row[verdict] += 1
            examples.append(f"{verdict}: {tool} {name}: exit {rc}: {err.strip()[-200:]}")
        elif rc == 0:
            row["ok"] += 1
        else:
            row["error"] += 1

    try:
        # Seeds: a baked scene of each format.
        good = os.path.join(tmp, "good")
        os.makedirs(good)
        cornell = os.path.join(SRC, "assets-src/rt/cornell_box.obj")
        for ext in ("rtrscene", "comp5892mesh"):
            rc, err = run("rtr-bake", [cornell, os.path.join(good, "c." + ext)])
            if rc != 0:
                sys.exit(f"cannot bake the seed .{ext}: {err}")
        seeds = {ext: open(os.path.join(good, "c." + ext), "rb").read() for ext in ("rtrscene", "comp5892mesh")}
        # The older output a failing `rtr-bake --force` must not damage.
        keep = os.path.join(tmp, "keep")
        os.makedirs(keep)
        shutil.copytree(good, keep, dirs_exist_ok=True)
        before = snapshot(keep)

        work = os.path.join(tmp, "in")
        os.makedirs(work)
        shutil.copy(os.path.join(SRC, "assets-src/rt/cornell_box.mtl"), os.path.join(work, "c.mtl"))
        out = os.path.join(tmp, "o.png")
        for i in range(COUNT):
            kind = rng.choice(["obj", "obj", "rtrscene", "comp5892mesh"])
            name = f"f{i}.{kind}"
            path = os.path.join(work, name)
            data = random_obj() if kind == "obj" else corrupt(seeds[kind])
            with open(path, "wb") as f:
                f.write(data)
            rc, err = run("rtr-trace", [path, "-o", out, "--size", "8x8", "-q", "--force", "--threads", "1"])
            record("rtr-trace", kind, name, rc, err)
            if kind == "obj":
                target = os.path.join(keep, "c.rtrscene")
                rc, err = run("rtr-bake", [path, target, "--force", "--threads", "1"])
                damaged = False
                if rc != 0:
                    damaged = snapshot(keep) != before
                else:  # a good bake replaced it: the new one is the older output from now on
                    before = snapshot(keep)
                record("rtr-bake", kind, name, rc, err, damaged)
            os.remove(path)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)

    cols = ["runs", "ok", "error", "crash", "hang", "unnamed", "usage", "damaged"]
    print("| tool | input | " + " | ".join(cols) + " |")
    print("|---|---|" + "---|" * len(cols))
    total = {c: 0 for c in cols}
    for (tool, kind), row in sorted(table.items()):
        print(f"| {tool} | {kind} | " + " | ".join(str(row[c]) for c in cols) + " |")
        for c in cols:
            total[c] += row[c]
    print("| all | | " + " | ".join(str(total[c]) for c in cols) + " |")
    for e in examples[:20]:
        print(e)
    bad = sum(total[c] for c in ("crash", "hang", "unnamed", "usage", "damaged"))
    sys.exit(1 if bad else 0)


main()
