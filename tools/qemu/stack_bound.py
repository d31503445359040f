#!/usr/bin/env python3
"""A static upper bound of the stack one planner call can use, on any line.

The QEMU benchmark measures the stack's high-water mark of the calls it
runs (Monterey 1, 2 and 3). Which escapes a call takes depends on the
line, so a line never measured can go deeper. This bound covers every
path: it reads the firmware's disassembly (`arm-none-eabi-objdump -d`),
takes each function's frame from its prologue (`push`/`stmdb sp!`,
`vpush`, `sub sp`: every stack decrement in the function, summed, so an
over-estimate where a function has two prologues) and its direct calls
(`bl`, and a `b` to another function's start, a tail call that frees the
caller's frame first), and returns the deepest chain from ROOT.

It fails (exit 2) where the bound would not be sound: an indirect call
(`blx rN`, `bx rN` other than a return) or a dynamic stack adjustment
reachable from ROOT, or recursion.

    tools/qemu/stack_bound.py ELF [ROOT] [--limit BYTES]

ROOT is a substring of the demangled symbol (default: `Planner<_,_>::plan`,
the entry point every call goes through). With `--limit`, exit 1 when the
bound is over it. Prints `stack-bound|BYTES` and the chain.
"""

import argparse
import re
import subprocess
import sys

FUNC = re.compile(r"^([0-9a-f]+) <(.*)>:$")
PUSH = re.compile(r"\t(?:push(?:\.w)?|stmdb(?:\.w)?\s+sp!,)\s+\{([^}]*)\}")
VPUSH = re.compile(r"\tvpush\s+\{([^}]*)\}")
SUB_SP = re.compile(r"\tsub(?:\.w|w)?\s+sp, (?:sp, )?#(\d+)")
STR_PRE = re.compile(r"\tstr(?:\.w)?\s+\w+, \[sp, #-(\d+)\]!")
DYN_SP = re.compile(r"\t(?:sub|add)(?:\.w)?\s+sp, (?:sp, )?r\d+")
CALL = re.compile(r"\tbl\s+([0-9a-f]+) <(.*)>$")
BRANCH = re.compile(r"\tb(?:\.w|\.n)?\s+([0-9a-f]+) <(.*)>$")
INDIRECT = re.compile(r"\t(?:blx\s+r\d+|bx\s+r\d+|mov\s+pc,|ldr(?:\.w)?\s+pc,)")


def registers(text):
    """Bytes a register list of push/stmdb/vpush takes."""
    size = 0
    for part in text.split(","):
        part = part.strip()
        m = re.fullmatch(r"([rds])(\d+)-[rds](\d+)", part)
        unit = {"d": 8}.get(part[:1], 4)
        size += unit * (int(m.group(3)) - int(m.group(2)) + 1) if m else unit
    return size


def parse(lines):
    """Per function (keyed by its address: two monomorphizations can
    demangle to the same name): its name, frame bytes, calls, tail calls
    and unsound sites."""
    funcs = {}
    cur = None
    for line in lines:
        m = FUNC.match(line.strip())
        if m:
            start = int(m.group(1), 16)
            cur = {"name": m.group(2), "frame": 0, "calls": set(), "tails": set(), "unsound": []}
            funcs[start] = cur
            continue
        if cur is None:
            continue
        for pat in (PUSH, VPUSH):
            m = pat.search(line)
            if m:
                cur["frame"] += registers(m.group(1))
        for pat in (SUB_SP, STR_PRE):
            m = pat.search(line)
            if m:
                cur["frame"] += int(m.group(1))
        if DYN_SP.search(line):
            cur["unsound"].append("dynamic stack adjustment: " + line.strip())
        m = CALL.search(line)
        if m:
            cur["calls"].add(int(m.group(1), 16))
            continue
        m = BRANCH.search(line)
        # (A branch to another function's start; one to its own is a loop.)
        if m and not re.search(r"\+0x[0-9a-f]+$", m.group(2)) and int(m.group(1), 16) != start:
            cur["tails"].add(int(m.group(1), 16))
        if INDIRECT.search(line) and "bx\tlr" not in line:
            cur["unsound"].append("indirect branch: " + line.strip())
    return funcs


def bound(funcs, root):
    """The deepest chain from `root`: (bytes, [(function, frame)])."""
    memo = {}
    problems = []

    def depth(f, path):
        if f in memo:
            return memo[f]
        info = funcs.get(f)
        if info is None:
            return 0, []
        if f in path:
            cycle = path[path.index(f):] + (f,)
            problems.append("recursion: " + " -> ".join(funcs[g]["name"] for g in cycle))
            return 0, []
        problems.extend(f"{info['name']}: {u}" for u in info["unsound"])
        best = (0, [])
        for c in sorted(info["calls"]):
            d = depth(c, path + (f,))
            if d[0] > best[0]:
                best = d
        out = (info["frame"] + best[0], [(info["name"], info["frame"])] + best[1])
        for c in sorted(info["tails"]):
            d = depth(c, path + (f,))
            if d[0] > out[0]:
                out = (d[0], [(info["name"] + " (tail call)", 0)] + d[1])
        memo[f] = out
        return out

    return depth(root, ()), problems


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("elf")
    ap.add_argument("root", nargs="?", default="Planner<_,_>::plan")
    ap.add_argument("--limit", type=int)
    ap.add_argument("--objdump", default="arm-none-eabi-objdump")
    args = ap.parse_args()
    dis = subprocess.run(
        [args.objdump, "-d", "-C", "--no-show-raw-insn", args.elf],
        check=True, capture_output=True, text=True,
    ).stdout.splitlines()
    funcs = parse(dis)
    roots = [f for f, info in funcs.items() if info["name"].endswith(args.root)]
    if len(roots) != 1:
        sys.exit(f"stack_bound.py: {len(roots)} functions end with {args.root!r}")
    (total, chain), problems = bound(funcs, roots[0])
    print(f"stack-bound|{total}")
    for f, frame in chain:
        print(f"  {frame:6d} B  {f}")
    if problems:
        print("not a bound:", *sorted(set(problems)), sep="\n  ", file=sys.stderr)
        sys.exit(2)
    if args.limit is not None and total > args.limit:
        print(f"stack_bound.py: {total} B over the limit of {args.limit} B", file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()
