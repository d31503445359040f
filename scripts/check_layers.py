#!/usr/bin/env python3
"""The library's import graph points down (ARCHITECTURE.md):

    error  ->  plan  ->  sim, optim  ->  model  ->  num, log

Reads every `use crate::…` / `crate::…::` path in src/ (test modules
included: a test may only look down too), maps each file to its layer,
and fails on an import that points up or sideways between sim and optim,
and on any cycle between files of one folder. Prints the file graph's
edge count; exit 1 on a violation."""
import pathlib
import re
import sys

RANK = {"num": 0, "log": 0, "model": 1, "sim": 2, "optim": 2, "plan": 3, "error": 4, "lib": 5}
# Sideways edges that are allowed: none. sim and optim do not know each other.
PATH = re.compile(r"\bcrate::([a-z_]+)(?:::([a-z_]+))?")
SUPER = re.compile(r"\buse super::(?:\{)?([a-z_]+)")


def layer(path: pathlib.Path) -> str:
    parts = path.relative_to("src").parts
    return parts[0].removesuffix(".rs") if len(parts) > 1 else path.stem


def module(path: pathlib.Path) -> str:
    return path.stem if path.stem != "mod" else "mod"


bad = []
edges = {}
for path in sorted(pathlib.Path("src").rglob("*.rs")):
    me = layer(path)
    text = path.read_text()
    # Intra-doc links are not imports.
    code = "\n".join(l for l in text.split("\n") if not l.lstrip().startswith("//"))
    for m in PATH.finditer(code):
        to = m.group(1)
        if to not in RANK or to == me:
            continue
        if RANK[to] >= RANK[me]:
            bad.append(f"{path}: imports crate::{to} (layer {RANK[to]}) from layer {RANK[me]}")
    # Within a folder: file -> sibling file edges via `super::x`.
    if len(path.relative_to("src").parts) > 1:
        for m in SUPER.finditer(code):
            sib = m.group(1)
            # A sibling is a file or a folder's mod.rs.
            for target in (path.parent / f"{sib}.rs", path.parent / sib / "mod.rs"):
                if sib != module(path) and target.exists():
                    edges.setdefault(str(path), set()).add(str(target))

# Cycles between sibling files (items re-exported by mod.rs count as mod.rs's,
# so only direct `super::file` paths form edges).
def cycle_from(start):
    stack, seen = [(start, [start])], set()
    while stack:
        node, trail = stack.pop()
        for nxt in edges.get(node, ()):
            if nxt == start:
                return trail + [nxt]
            if nxt not in seen:
                seen.add(nxt)
                stack.append((nxt, trail + [nxt]))
    return None

for f in sorted(edges):
    c = cycle_from(f)
    if c:
        bad.append("cycle: " + " -> ".join(c))
        break
for b in bad:
    print(b)
print(f"{sum(len(v) for v in edges.values())} file edges within folders; {len(bad)} violations")
sys.exit(1 if bad else 0)
