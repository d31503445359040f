"""Compact, deterministic JSON: nested structure indented, scalar lists on
one line, floats in full repr precision (shortest round-trip form)."""

import json
import math


def _scalar(v):
    if isinstance(v, float):
        if not math.isfinite(v):
            raise ValueError("non-finite float in fixture")
        return repr(v)
    return json.dumps(v, ensure_ascii=False)


def _is_scalar(v):
    return v is None or isinstance(v, (bool, int, float, str))


def _dump(v, ind, lvl):
    pad = " " * (ind * (lvl + 1))
    end = " " * (ind * lvl)
    if _is_scalar(v):
        return _scalar(v)
    if isinstance(v, dict):
        if not v:
            return "{}"
        items = [f"{pad}{json.dumps(str(k))}: {_dump(x, ind, lvl + 1)}" for k, x in v.items()]
        return "{\n" + ",\n".join(items) + "\n" + end + "}"
    if isinstance(v, (list, tuple)):
        if all(_is_scalar(x) for x in v):
            return "[" + ",".join(_scalar(x) for x in v) + "]"
        if all(isinstance(x, (list, tuple)) and all(_is_scalar(y) for y in x) for x in v):
            # matrix: one row per line
            rows = [pad + _dump(x, ind, lvl + 1) for x in v]
            return "[\n" + ",\n".join(rows) + "\n" + end + "]"
        items = [pad + _dump(x, ind, lvl + 1) for x in v]
        return "[\n" + ",\n".join(items) + "\n" + end + "]"
    raise TypeError(f"cannot serialize {type(v)}")


def dumps(obj, indent=1):
    s = _dump(obj, indent, 0) + "\n"
    assert json.loads(s) is not None or obj is None
    return s
