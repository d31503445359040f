#!/usr/bin/env python3
"""Lists library files over 600 lines and functions over 80 lines (the
architecture's limits, ARCHITECTURE.md); exits 1 when any is found that is
not in ALLOWED. Test modules (`#[cfg(test)]`) are not counted."""
import pathlib
import re
import sys

ALLOWED = {
    # name: why (keep in step with ARCHITECTURE.md's exceptions)
}
FN = re.compile(r"^(\s*)(pub(\([a-z]+\))? )?(const )?fn (\w+)")
bad = []
for path in sorted(pathlib.Path("src").rglob("*.rs")):
    lines = path.read_text().split("\n")
    code = lines
    for i, l in enumerate(lines):
        if l.strip() == "#[cfg(test)]":
            code = lines[:i]
            break
    if len(code) > 600:
        bad.append(f"{path}: {len(code)} lines (non-test)")
    i = 0
    while i < len(code):
        m = FN.match(code[i])
        if m and not code[i].rstrip().endswith(";"):
            indent = m.group(1)
            j = i
            while j < len(code) and code[j] != indent + "}":
                j += 1
            n = j - i + 1
            if n > 80 and m.group(5) not in ALLOWED:
                bad.append(f"{path}:{i + 1}: fn {m.group(5)} is {n} lines")
            i = j
        i += 1
for b in bad:
    print(b)
print(f"{len(bad)} over the limits")
sys.exit(1 if bad else 0)
