"""Hypothesis strategies of hostile input: mutated example scenes, bad argument values.

A scene mutation starts from a bundled example (``examples/*.toml``, planar and 3-D), parsed
with tomllib, and changes one or a few things: a numeric leaf replaced by a hostile value, a
key dropped or added, an array component appended or removed, a type changed, a pusher
duplicated, a string emptied, a mesh path that does not exist. :func:`to_toml` writes it back.
"""

from __future__ import annotations

import copy
import json
import math
import tomllib
from pathlib import Path

import numpy as np
from hypothesis import strategies as st

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
SCENE_FILES = sorted(EXAMPLES.glob("*.toml"))


def load_example(path: Path) -> dict:
    return tomllib.loads(path.read_text())


EXAMPLE_DICTS = {p.name: load_example(p) for p in SCENE_FILES}
PLANAR = sorted(n for n, d in EXAMPLE_DICTS.items() if "dimension" not in d)
SPATIAL = sorted(n for n, d in EXAMPLE_DICTS.items() if "dimension" in d)

#: hostile numbers: non-finite, huge, tiny, zero, negative, huge integers
HOSTILE_NUMBERS = [math.nan, math.inf, -math.inf, 1e300, -1e300, 1e200, 1e-300, -1e-300, 1e-30, 0.0, -0.0, -1.0,
                   0, -1, 2**63, -(2**63) - 1, 10**30, 1e9, -1e9, 5e-324, 1e-12]


# --- TOML -------------------------------------------------------------------------------------

def _key(k: str) -> str:
    if k and all(c.isalnum() or c in "_-" for c in k):
        return k
    return json.dumps(k)


def _value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, list):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{_key(k)} = {_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(type(v))


def _is_table_array(v) -> bool:
    return isinstance(v, list) and len(v) > 0 and all(isinstance(x, dict) for x in v)


def to_toml(d: dict, prefix: str = "") -> str:
    """A small TOML emitter: scalars and arrays inline, tables and arrays of tables as sections."""
    lines, later = [], []
    for k, v in d.items():
        name = f"{prefix}{_key(k)}"
        if isinstance(v, dict):
            later.append(f"\n[{name}]\n" + to_toml(v, name + "."))
        elif _is_table_array(v):
            for x in v:
                later.append(f"\n[[{name}]]\n" + to_toml(x, name + "."))
        else:
            lines.append(f"{_key(k)} = {_value(v)}")
    return "\n".join(lines) + "\n" + "".join(later)


# --- mutations --------------------------------------------------------------------------------

def leaves(x, path=()):
    """(path, value) of every leaf and every container in a parsed scene (paths as key tuples)."""
    out = [(path, x)]
    if isinstance(x, dict):
        for k, v in x.items():
            out += leaves(v, path + (k,))
    elif isinstance(x, list):
        for i, v in enumerate(x):
            out += leaves(v, path + (i,))
    return out


def _parent(d, path):
    for k in path[:-1]:
        d = d[k]
    return d


def dotted(path) -> str:
    s = ""
    for k in path:
        s += f"[{k}]" if isinstance(k, int) else (f".{k}" if s else str(k))
    return s


@st.composite
def mutation(draw, d: dict):
    """Mutates ``d`` in place once; returns (description of the change, the dotted field a loader
    must reject it with, or None when the change may leave a valid scene)."""
    all_nodes = [(p, v) for p, v in leaves(d) if p]
    numeric = [(p, v) for p, v in all_nodes if isinstance(v, (int, float)) and not isinstance(v, bool)]
    arrays = [(p, v) for p, v in all_nodes if isinstance(v, list) and not _is_table_array(v)]
    tables = [(p, v) for p, v in leaves(d) if isinstance(v, dict)]
    strings = [(p, v) for p, v in all_nodes if isinstance(v, str)]
    kinds = ["number"] * 4 + ["drop", "add", "append", "remove", "type", "duplicate_pusher", "string", "mesh",
                              "scale"]
    kind = draw(st.sampled_from(kinds))
    if kind in ("number", "scale") and numeric:
        p, v = draw(st.sampled_from(numeric))
        new = draw(st.one_of(st.sampled_from(HOSTILE_NUMBERS), st.floats())) if kind == "number" else v * draw(
            st.sampled_from([-1, 1e3, 1e-3, 1e6, 1e-6, 1e12]))
        _parent(d, p)[p[-1]] = new
        bad = isinstance(new, float) and not math.isfinite(new)
        return f"{dotted(p)} = {new!r}", dotted(p) if bad else None
    if kind == "drop" and all_nodes:
        p, _ = draw(st.sampled_from(all_nodes))
        del _parent(d, p)[p[-1]]
        return f"drop {dotted(p)}", None
    if kind == "add" and tables:
        p, t = draw(st.sampled_from(tables))
        k = draw(st.sampled_from(["unknown", "frobnicate", "Mass", "mass ", "", "x.y"]))
        t[k] = draw(st.sampled_from([1.0, "x", [1.0, 2.0], {"a": 1}]))
        return f"add {dotted(p + (k,))}", dotted(p + (k,))
    if kind == "append" and arrays:
        p, a = draw(st.sampled_from(arrays))
        a.append(copy.deepcopy(a[-1]) if a and draw(st.booleans()) else draw(st.sampled_from([99.0, 0.0, math.nan])))
        vector = all(isinstance(x, (int, float)) for x in a[:-1]) and len(a) > 1
        return f"append to {dotted(p)}", dotted(p) if vector else None
    if kind == "remove" and arrays:
        p, a = draw(st.sampled_from(arrays))
        if a:
            a.pop(draw(st.integers(0, len(a) - 1)))
        return f"remove from {dotted(p)}", None
    if kind == "type" and all_nodes:
        p, _ = draw(st.sampled_from(all_nodes))
        new = draw(st.sampled_from(["0.1", True, [], [[]], {}, 1.0, [1.0], {"a": [1.0]}]))
        _parent(d, p)[p[-1]] = new
        return f"{dotted(p)} = {new!r}", None
    if kind == "duplicate_pusher" and isinstance(d.get("pushers"), list) and d["pushers"]:
        i = draw(st.integers(0, len(d["pushers"]) - 1))
        dup = copy.deepcopy(d["pushers"][i])
        if isinstance(dup, dict) and draw(st.booleans()):
            pts = dup.get("points")
            if isinstance(pts, list) and pts:
                dup["points"] = [copy.deepcopy(pts[0])] * max(2, len(pts))  # identical points
                dup["name"] = f"{dup.get('name', 'p')}-same"
        d["pushers"].append(dup)
        return f"duplicate pushers[{i}] as pushers[{len(d['pushers']) - 1}]", "pushers"
    if kind == "string":
        targets = strings or [(("name",), d.get("name"))]
        p, _ = draw(st.sampled_from(targets))
        new = draw(st.sampled_from(["", " ", "\t", "\n", "x" * 5000, "ü", "\x00"]))
        _parent(d, p)[p[-1]] = new
        pusher_name = len(p) == 3 and p[0] == "pushers" and p[2] == "name"
        return f"{dotted(p)} = {new!r}", dotted(p) if pusher_name and not new.strip() else None
    if kind == "mesh" and "dimension" in d and isinstance(d.get("object"), dict):
        new = draw(st.sampled_from(["meshes/missing.obj", "/nonexistent/x.obj", "", "meshes", "../README.md"]))
        d["object"]["mesh"] = new
        d["object"]["shape"] = "mesh"
        d["object"].pop("size", None)
        return f"object.mesh = {new!r}", "object.mesh"
    return "unchanged", None


@st.composite
def mutated_scene(draw, names):
    """(example name, mutated dict, description of the mutations, the fields one of which a loader
    must name when rejecting it — empty when the mutations may leave a valid scene)."""
    name = draw(st.sampled_from(names))
    d = copy.deepcopy(EXAMPLE_DICTS[name])
    done = [draw(mutation(d)) for _ in range(draw(st.sampled_from([1, 1, 1, 1, 2, 3])))]
    done = [m for m in done if m[0] != "unchanged"] or [("unchanged", None)]
    # one change only: a second could undo what the first made invalid (drop the NaN's parent)
    must = [f for _, f in done if f is not None] if len(done) == 1 else []
    return name, d, "; ".join(w for w, _ in done), must


# --- bad argument values ----------------------------------------------------------------------

class Weird:
    """An object of no type the API knows."""

    def __repr__(self):
        return "Weird()"


BAD_SCALARS = [None, "", " ", "x", "1.0", True, False, math.nan, math.inf, -math.inf, 1e300, -1e300, 1e-300,
               0, -1, -1.0, 2**64, 2**70, -(2**70), 10**400, Weird(), [], {}, {"a": 1}, b"x", np.float64("nan"),
               np.int64(-1), complex(1, 1)]


def bad_vectors(n: int) -> list:
    """Bad values for an ``n``-vector argument: wrong shapes, non-finite or huge components."""
    ok = [0.0] * n
    out = [[], [[]], ok[:-1], ok + [0.0], [ok], np.zeros((2, n)), np.zeros((n, n)), "abc", ["a"] * n, [None] * n,
           {"x": 1}, np.array(ok, dtype=object)]
    for v in (math.nan, math.inf, -math.inf, 1e300, -1e300, 1e200):
        for i in range(n):
            a = list(ok)
            a[i] = v
            out.append(a)
    out.append([1e300] * n)
    return out


def bad_values(kind: str) -> st.SearchStrategy:
    """Bad values of one argument kind: "vec2", "vec3", "vec6", "vec7", "rows3", "scalar", "count",
    "name", "bool", "any"."""
    base = list(BAD_SCALARS)
    if kind.startswith("vec"):
        base += bad_vectors(int(kind[3:]))
    elif kind == "rows3":
        base += [np.zeros((0, 3)), np.zeros((2, 2)), np.zeros((2, 3, 1)), np.full((2, 3), np.nan),
                 np.full((2, 3), 1e300), np.full((3, 3), np.inf), [[0.0, 0.0]], [[0.0] * 3, [0.0] * 2]]
    elif kind == "count":
        base += [-5, 0, 2**31, 2**63, 10**12, 1.5, "10"]
    elif kind == "name":
        base += ["nope", "LEFT", "left ", "\x00", "ü" * 3, "x" * 10000]
    n = int(kind[3:]) if kind.startswith("vec") else 3
    # drawn counts and numbers stay out of the valid-but-slow middle (a million pushes is valid)
    drawn = {"name": st.text(max_size=12), "count": st.integers(max_value=3) | st.integers(min_value=2**31),
             "scalar": st.floats(max_value=1e-9) | st.floats(min_value=1e12)}.get(
        kind, st.lists(st.floats(), min_size=n - 1, max_size=n + 1))
    return st.one_of(st.sampled_from(base), drawn)
