"""Reading the Markdown tables that the benchmark tools print (tools/report/render.py)."""
import re

# A tool's stderr lands between its table rows in the raw file (a loader's "note: ..." while the next
# case loads): such a line is not the table's end.
INTERLEAVED = re.compile(r"^(note|warning): ")


def md_tables(text):
    """Every markdown table in text: a list of (header, rows), cells stripped."""
    out, lines, i = [], text.splitlines(), 0
    while i < len(lines):
        if lines[i].startswith("|") and i + 1 < len(lines) and re.match(r"^\|[-:| ]+\|\s*$", lines[i + 1]):
            header = [c.strip() for c in lines[i].strip().strip("|").split("|")]
            rows, i = [], i + 2
            while i < len(lines) and (lines[i].startswith("|") or INTERLEAVED.match(lines[i])):
                if lines[i].startswith("|"):
                    rows.append([c.strip() for c in lines[i].strip().strip("|").split("|")])
                i += 1
            out.append((header, rows))
        else:
            i += 1
    return out


def num(cell):
    """The first number in a cell ('0.37×' -> 0.37, '192 (0.189 %)' -> 192), or None."""
    m = re.search(r"-?\d+(?:\.\d+)?(?:e-?\d+)?", cell or "")
    return float(m.group(0)) if m else None


def col(header, *names):
    """Index of the first column whose name contains one of names (case-insensitive), or None."""
    for n in names:
        for i, h in enumerate(header):
            if n.lower() in h.lower():
                return i
    return None
