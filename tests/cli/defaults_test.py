#!/usr/bin/python3
"""docs/files-and-cli.md's defaults table says what the tools do: each default in backticks is the one
the tool prints in --help, which CLI11 takes from the option's variable in the code.

    defaults_test.py BIN_DIR"""
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def doc_rows():
    text = open(os.path.join(ROOT, "docs/files-and-cli.md")).read()
    section = text.split("\n## Defaults\n", 1)[1]
    rows = []
    for line in section.splitlines():
        m = re.match(r"^\| `([\w-]+)` \| `(--[\w-]+)` \| `([^`]+)`", line)
        if m:
            rows.append(m.groups())
    return rows


def help_defaults(exe):
    out = subprocess.run([exe, "--help"], capture_output=True, text=True, timeout=60).stdout
    found = {}
    for line in out.splitlines():
        if not line.startswith("  -"):
            continue
        head = re.split(r"\s{2,}", line.strip())[0]  # names and type, before the description
        for name in re.findall(r"--[\w-]+", head.split(" ")[0]):
            found[name] = head.rsplit("=", 1)[1] if "=" in head else None
    return found


def main():
    bin_dir = sys.argv[1]
    rows = doc_rows()
    if len(rows) < 10:
        sys.exit(f"defaults_test: only {len(rows)} rows found in docs/files-and-cli.md's Defaults table")
    failures, printed = [], {}
    for tool, option, default in rows:
        if tool not in printed:
            printed[tool] = help_defaults(os.path.join(bin_dir, tool))
        if option not in printed[tool]:
            failures.append(f"{tool} {option}: no such option in --help")
        elif printed[tool][option] != default:
            failures.append(f"{tool} {option}: docs say {default}, the tool's default is {printed[tool][option]}")
    for f in failures:
        print(f)
    print(f"defaults_test: {len(rows)} documented defaults, {len(failures)} wrong")
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
