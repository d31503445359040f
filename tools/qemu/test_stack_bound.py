#!/usr/bin/env python3
"""Tests of stack_bound.py on hand-written disassembly (standard library only).

    python3 tools/qemu/test_stack_bound.py
"""

import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import stack_bound  # noqa: E402

# `arm-none-eabi-objdump -d -C --no-show-raw-insn` as it prints a Thumb-2
# image: `plan` (20 + 8 + 64 + 300 = 392 B) calls `a` (8 + 1000) and `b`
# (which tail-calls `c`, 16 + 2000, after freeing its own 48 B); two
# functions demangle to the same name `same` (monomorphizations), one deep.
LINES = """
00001000 <plan>:
    1000:\tpush\t{r4, r5, r6, r7, lr}
    1002:\tstmdb\tsp!, {r8, r9}
    1006:\tvpush\t{d8-d15}
    100a:\tsub.w\tsp, sp, #300\t@ 0x12c
    100e:\tbl\t2000 <a>
    1012:\tbl\t3000 <b>
    1016:\tbl\t5000 <same>
    101a:\tb.n\t1000 <plan>
    101c:\tbeq.n\t1012 <plan+0x12>
    101e:\tpop\t{r4, r5, r6, r7, pc}

00002000 <a>:
    2000:\tpush\t{r7, lr}
    2002:\tsub.w\tsp, sp, #1000\t@ 0x3e8
    2006:\tpop\t{r7, pc}

00003000 <b>:
    3000:\tpush\t{r4, lr}
    3002:\tsub\tsp, #40\t@ 0x28
    3004:\tadd\tsp, #40\t@ 0x28
    3006:\tpop.w\t{r4, lr}
    300a:\tb.w\t4000 <c>

00004000 <c>:
    4000:\tpush\t{r4, r5, r6, lr}
    4002:\tsubw\tsp, sp, #2000\t@ 0x7d0
    4006:\tpop\t{r4, r5, r6, pc}

00005000 <same>:
    5000:\tpush\t{r7, lr}
    5002:\tbx\tlr

00006000 <same>:
    6000:\tpush\t{r7, lr}
    6002:\tsub.w\tsp, sp, #4000\t@ 0xfa0
    6006:\tbx\tlr
""".splitlines()


def bound_of(lines, root_addr):
    funcs = stack_bound.parse(lines)
    return stack_bound.bound(funcs, root_addr)


class StackBound(unittest.TestCase):
    def test_frames_calls_and_a_tail_call(self):
        (total, chain), problems = bound_of(LINES, 0x1000)
        self.assertEqual(problems, [])
        # plan 392 + max(a 1008, b's tail call to c 2016, same 8).
        self.assertEqual(total, 392 + 2016)
        self.assertEqual([f for f, _ in chain], ["plan", "b (tail call)", "c"])

    def test_functions_with_one_name_are_kept_apart(self):
        # The deep `same` at 0x6000 is never called: it must not count.
        funcs = stack_bound.parse(LINES)
        self.assertEqual(funcs[0x5000]["frame"], 8)
        self.assertEqual(funcs[0x6000]["frame"], 4008)

    def test_recursion_is_not_a_bound(self):
        lines = LINES + ["", "00007000 <r>:", "    7000:\tpush\t{r7, lr}", "    7002:\tbl\t7000 <r>"]
        _, problems = bound_of(lines, 0x7000)
        self.assertTrue(any(p.startswith("recursion") for p in problems), problems)

    def test_an_indirect_call_is_not_a_bound(self):
        lines = LINES + ["", "00008000 <f>:", "    8000:\tpush\t{r7, lr}", "    8002:\tblx\tr3"]
        _, problems = bound_of(lines, 0x8000)
        self.assertTrue(any("indirect" in p for p in problems), problems)

    def test_a_dynamic_frame_is_not_a_bound(self):
        lines = LINES + ["", "00009000 <g>:", "    9000:\tpush\t{r7, lr}", "    9002:\tsub.w\tsp, sp, r0"]
        _, problems = bound_of(lines, 0x9000)
        self.assertTrue(any("dynamic" in p for p in problems), problems)


if __name__ == "__main__":
    unittest.main()
