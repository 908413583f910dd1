#!/usr/bin/env python3
"""Help and docs agree (issue 28): every option of every tool's --help is named in README.md or docs/, every
rtr option the docs name exists, a help text mentions only options its tool has, and the window's keys are
the same in `rtr-view --help` (the panel's Keys section prints the same list) and in docs/viewer.md.

Usage: docs_test.py BIN_DIR SOURCE_DIR     Exit 0 pass, 1 fail.
"""
import glob
import os
import re
import subprocess
import sys

TOOLS = ["rtr-view", "rtr-trace", "rtr-bake", "rtr-reflect"]
OPTION = re.compile(r"(?<![\w-])(--[a-z][a-z0-9-]*)")
# Options the docs name that belong to other programs: CMake and CTest, the benchmark and report tools
# (tools/*: their own --help), the corpus and window test scripts, glslang.
OTHERS = {"--preset", "--build", "--target", "--build-only", "--quick", "--keep", "--table", "--target-env",
          "--runs", "--warmup", "--scale", "--scene", "--case", "--only", "--skip", "--out", "--runner",
          "--benchmark", "--explain", "--no-check", "--avx2", "--sse", "--packets-only", "--leaf-rays",
          "--mip-sizes", "--mips-per-texture", "--textures", "--plain", "--gltf", "--alone-rays", "--alone-sweep", "--in-flight-sweep", "--profile",
          "--mirror-tiles", "--build-grain",  # bench-trace (docs/bench/trace.md, round 15)
          "--reps", "--cpu-time", "--singles-only",  # bench-trace (docs/bench/trace.md, rounds 16 and 17)
          "--sphere-grid", "--env-cases", "--spp-curve", "--flip", "--flip-map", "--ppd",  # scenegen, rtr-frame-compare
           "--mesh", "--rebuild", "--fates", "--instances",  # rtr-lod-cut (docs/virtual-geometry.md), scenegen
          "--mib", "--chunks",  # rtr-bench-upload (docs/startup.md, "What the bus allows")
          "--test-ui", "--test-drop"}  # rtr-view's test-only options, hidden from --help (docs/viewer.md)
failures = []


def check(cond, msg):
    print(("ok: " if cond else "FAIL: ") + msg, flush=True)
    if not cond:
        failures.append(msg)


def main():
    if len(sys.argv) < 3:
        print(__doc__)
        return 2
    bins, src = sys.argv[1], sys.argv[2]
    helps = {t: subprocess.run([os.path.join(bins, t), "--help"], capture_output=True, text=True, timeout=60).stdout
             for t in TOOLS}
    docs = {p: open(p, encoding="utf-8").read()
            for p in [os.path.join(src, "README.md")] + glob.glob(os.path.join(src, "docs", "*.md"))}
    alldocs = "\n".join(docs.values())
    known = set()
    for tool, text in helps.items():
        defined = {m.group(2) for m in re.finditer(r"^\s+(-\w,)?(--[a-z][a-z0-9-]*)", text, re.M)}
        # CLI11 lists aliases on one line: "-o,--output,--screenshot TEXT".
        defined |= {o for m in re.finditer(r"^\s+(-[\w,-]+)", text, re.M) for o in OPTION.findall(m.group(1))}
        known |= defined
        check(defined, f"{tool} --help lists options ({len(defined)})")
        undocumented = sorted(o for o in defined if not re.search(re.escape(o) + r"(?![\w-])", alldocs))
        check(not undocumented, f"every option of {tool} --help is named in README.md or docs/ (missing: {undocumented})")
        check(not re.search(r"\{(false|true)\}", text), f"{tool} --help shows no CLI11 default markers like {{false}}")
        stray = sorted(set(OPTION.findall(text)) - defined)
        check(not stray, f"{tool} --help mentions only options {tool} has (others: {stray})")
    named = set(OPTION.findall(alldocs))
    unknown = sorted(named - known - OTHERS)
    check(not unknown, f"every option the docs name exists in a tool's --help (unknown: {unknown})")

    # Keys: the help's list against the key table of docs/viewer.md.
    text = helps["rtr-view"]
    start = text.find("Keys in the window")
    end = text.find("View 13", start)
    help_keys = set(re.findall(r"^  (\S[^:]*?): ", text[start:end], re.M)) if 0 <= start < end else set()
    viewer = docs[os.path.join(src, "docs", "viewer.md")]
    table = viewer[viewer.index("## Keys"):]
    table = table[:table.index("\n\n", table.index("| key |"))]
    doc_keys = {row.split("|")[1].strip().replace("`", "") for row in table.splitlines()[4:] if row.startswith("|")}
    check(len(help_keys) >= 15, f"rtr-view --help lists the window's keys ({len(help_keys)})")
    check(help_keys == doc_keys, f"the keys of rtr-view --help and docs/viewer.md's table are the same "
          f"(only in help: {sorted(help_keys - doc_keys)}; only in docs: {sorted(doc_keys - help_keys)})")
    mode = text[text.find("  --mode "):][:500]
    for m in range(1, 16):
        check(re.search(rf"\b{m} [A-Za-z]", mode) is not None, f"rtr-view --help names view mode {m}")
    print(f"{len(failures)} failure(s)" if failures else "all passed", flush=True)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
