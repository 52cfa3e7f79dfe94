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

for f in findings:
    print(f"check_layers: {f}")
if findings:
    sys.exit(1)
print(f"check_layers: {len(layers)} layers, each using only what docs/ARCHITECTURE.md lists; "
      f"{len(public)} public headers, {len(detail)} detail headers used by the library alone")
