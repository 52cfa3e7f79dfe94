#!/usr/bin/env python3
"""Checks docs/ARCHITECTURE.md's layer table against the code's includes.

For every layer (a folder under src/ with its public headers under include/trivox/<layer>/),
the layers its files include must be exactly those the table's "uses" column lists: a layer
that includes one the table does not list breaks a wall, and one the table lists but never
includes makes the table wrong. No file under src/ may include another layer's private
header (src/<other>/...). The program (apps/trivox) and the top-level headers
(include/trivox/*.h) are outside the table.

A layer's detail headers (include/trivox/<layer>/detail/) are what the library's own layers
share and a user does not see (docs/ARCHITECTURE.md, "Public surface"): another layer may
include them, within the table's walls, but no public header (include/trivox/ outside
detail/) may, and neither may the program, the Python module or the fuzzers (apps/, python/,
fuzz/), which use the public headers only. Tests and benchmarks may use anything.

The top-level files (include/trivox/*.h and src/*.{h,cpp}: shared value types, checks, the
parallel seam, the SIMD choice) include no layer's header. Every source that runs work in
parallel (parallel_for_each, TBB) or is compiled per SIMD target (Highway, TRIVOX_CLONED, the
SIMD choice of trivox/simd.h) is named by its path in the document's section about it ("One
parallel seam", "SIMD targets"), and the document quotes the counts of the public surface as
this script prints them, so that neither can drift from the code.

Exit status 0 when all holds, 1 with one line per finding otherwise. Run by the test suite
(tests/CMakeLists.txt).
"""
import pathlib
import re
import sys

root = pathlib.Path(__file__).resolve().parent.parent
findings = []

# The table: rows "| `layer` | what | uses |" between the "## Folders are layers" heading
# and the next heading.
text = (root / "docs" / "ARCHITECTURE.md").read_text()
section = text.split("## Folders are layers", 1)[1].split("\n## ", 1)[0]
table = {}
for line in section.splitlines():
    m = re.match(r"\|\s*`([a-z_]+)`\s*\|.*\|\s*([^|]*)\|\s*$", line)
    if not m:
        continue
    uses = m.group(2).strip()
    table[m.group(1)] = set() if uses in ("nothing", "") else {u.strip() for u in uses.split(",")}

layers = sorted(p.name for p in (root / "src").iterdir() if p.is_dir())
for layer in layers:
    if layer not in table:
        findings.append(f"src/{layer}/ is not in docs/ARCHITECTURE.md's layer table")
for layer in table:
    if layer not in layers:
        findings.append(f"docs/ARCHITECTURE.md lists layer '{layer}' but there is no src/{layer}/")

include_re = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)
for layer in layers:
    files = sorted((root / "src" / layer).rglob("*.[ch]*")) + sorted((root / "include" / "trivox" / layer).rglob("*.h"))
    used = set()
    for f in files:
        rel = f.relative_to(root)
        for inc in include_re.findall(f.read_text()):
            parts = inc.split("/")
            if parts[0] == "trivox" and (len(parts) == 3 or (len(parts) == 4 and parts[2] == "detail")):
                other = parts[1]
            elif len(parts) == 2 and parts[0] in layers:
                other = parts[0]
                if other != layer:
                    findings.append(f"{rel}: includes {inc}, a private header of layer '{other}'")
            else:
                continue
            if other == layer:
                continue
            used.add(other)
            if layer in table and other not in table[layer]:
                findings.append(f"{rel}: includes {inc}, but docs/ARCHITECTURE.md does not let '{layer}' use '{other}'")
    if layer in table:
        for other in sorted(table[layer] - used):
            findings.append(f"docs/ARCHITECTURE.md says '{layer}' uses '{other}', but no file of it includes '{other}'")

# The public surface: no public header, and nothing in the program, the Python module or the
# fuzzers, includes a detail header or a private one.
include_root = root / "include" / "trivox"
public = sorted(h for h in include_root.rglob("*.h") if "detail" not in h.relative_to(include_root).parts)
detail = sorted(h for h in include_root.rglob("*.h") if "detail" in h.relative_to(include_root).parts)
users = [f for area in ("apps", "python", "fuzz") for f in sorted((root / area).rglob("*")) if f.suffix in (".h", ".cpp")]
for f in public + users:
    rel = f.relative_to(root)
    for inc in include_re.findall(f.read_text()):
        parts = inc.split("/")
        if parts[0] == "trivox" and "detail" in parts:
            findings.append(f"{rel}: includes {inc}, a detail header, which only the library's own sources use")
        elif parts[0] in layers and (root / "src" / inc).is_file():
            findings.append(f"{rel}: includes {inc}, a private header of layer '{parts[0]}'")

# The top level: the shared value types of include/trivox/*.h and the sources beside them in
# src/ (checks, the parallel seam, the SIMD choice, the version) sit above every layer, so they
# include no layer's header.
top = sorted(include_root.glob("*.h")) + sorted(f for f in (root / "src").glob("*") if f.suffix in (".h", ".cpp"))
for f in top:
    rel = f.relative_to(root)
    for inc in include_re.findall(f.read_text()):
        parts = inc.split("/")
        if (parts[0] == "trivox" and len(parts) > 2) or (len(parts) > 1 and parts[0] in layers):
            findings.append(f"{rel}: includes {inc}, but the top-level files use no layer")

# Every place that runs work in parallel or compiles code per SIMD target is named (by its
# path) in docs/ARCHITECTURE.md's section about it, so that the section cannot miss one.
sources = [f for area in ("src", "apps", "python/src") for f in sorted((root / area).rglob("*"))
           if f.suffix in (".h", ".cpp")]
sites = {  # heading: (what a site is, how it is found)
    "One parallel seam": ("a parallel site", re.compile(r"parallel_for_each|tbb::|task_arena")),
    "SIMD targets": ("a SIMD site", re.compile(r"hwy/|HWY_|__AVX|immintrin|TRIVOX_CLONED|trivox/simd\.h")),
}
for heading, (what, pattern) in sites.items():
    part = text.split(f"## {heading}", 1)
    body = part[1].split("\n## ", 1)[0] if len(part) == 2 else ""
    for f in sources:
        rel = f.relative_to(root).as_posix()
        code = re.sub(r"//[^\n]*", "", f.read_text())
        if pattern.search(code) and f"`{rel}`" not in body:
            findings.append(f"{rel}: {what} that docs/ARCHITECTURE.md's \"{heading}\" does not name")

# The counts of the public surface, as docs/ARCHITECTURE.md quotes them.
def includes_of(area):
    found = set()
    for f in sorted((root / area).rglob("*")):
        if f.suffix in (".h", ".cpp"):
            found.update(inc for inc in include_re.findall(f.read_text()) if inc.startswith("trivox/"))
    return found
public_names = {h.relative_to(include_root.parent).as_posix() for h in public}
used = set().union(*(includes_of(a) for a in ("apps", "python", "fuzz", "bench"))) & public_names
by_python = includes_of("python") & public_names
counts = (f"{len(layers)} layers; {len(public)} public headers, {len(used)} of them included by apps/, python/, "
          f"fuzz/ or bench/ ({len(by_python)} by the Python module); {len(detail)} detail headers")
if f"check_layers: {counts}" not in text:
    findings.append(f"docs/ARCHITECTURE.md does not quote the counts as they are: 'check_layers: {counts}'")

for f in findings:
    print(f"check_layers: {f}")
if findings:
    sys.exit(1)
print(f"check_layers: {counts}")
