"""The world side's files for the fuzz suite: a valid base of each kind (workcell, plan, grasp
graph, trajectory, robot, a mesh-object scene) and the strategies that mutate them — a leaf replaced
by a hostile value or a value of another type, a key dropped or added, a list emptied or
repeated past its limit, the text truncated, nested deeper than the limit or made binary.

Each mutation says whether the result is certainly invalid, and then which top-level field an
error must name: a number replaced by NaN or inf, any value replaced by one of another JSON type
(outside the free-form parts of a file), an unknown key in a file that refuses unknown keys."""

from __future__ import annotations

import copy
import json
import math
from functools import lru_cache

from hypothesis import strategies as st

import regrasp
from regrasp.fields import LIMITS, MAX_NESTING
from regrasp.planning.plan import KEYS as PLAN_KEYS
from regrasp.workcell import Workcell, bundled

from .strategies import EXAMPLES, HOSTILE_NUMBERS, _parent, dotted, leaves, to_toml

#: values of another type than a leaf's, or hostile numbers
REPLACEMENTS = HOSTILE_NUMBERS + ["", " ", "x", "NaN", True, False, None, [], {}, [1e300], {"a": 1}, [[[]]]]


def _types(v) -> str:
    if isinstance(v, bool):
        return "bool"
    if isinstance(v, (int, float)):
        return "number"
    return {str: "str", list: "list", dict: "dict", type(None): "null"}[type(v)]


# --- the bases ---------------------------------------------------------------------------------

@lru_cache(maxsize=None)
def workcell_base() -> str:
    return json.dumps(Workcell.load(bundled()).to_dict())


@lru_cache(maxsize=None)
def plan_base() -> str:
    scene = regrasp.load_scene(EXAMPLES / "block-low-friction.toml")
    return json.dumps(regrasp.plan(scene, seed=0, time_limit=1.0).to_json())


@lru_cache(maxsize=None)
def graph_base() -> str:
    from regrasp.dexterity.actions import ACTIONS
    from regrasp.dexterity.graph import Edge, GraspGraph, Settings
    from regrasp.dexterity.objects import load_object
    from regrasp.dexterity.taxonomy import taxonomy_of

    grasps = taxonomy_of(load_object("box")).grasps
    nodes = [dict(g.to_dict(), clearance=0.03, fits=True) for g in grasps[:4]]
    a, b, c = (n["name"] for n in nodes[:3])
    pose = list(nodes[1]["pose"])
    e0 = Edge(a, "gravity-slide", b, 3, {b: 2, "dropped": 1}, {"lowered": 0.5}, 1.5,
              [(b, pose, [1.0, 1.1, 0.9]), ("dropped", None, [0.9, 1.0, 1.0]), (b, pose, [1.1, 0.9, 1.0])])
    e1 = Edge(b, "push-down", c, 2, {c: 1, b: 1}, {}, 0.7)
    g = GraspGraph({"name": "box", "file": "box"}, nodes, [e0, e1],
                   [ACTIONS[k].to_dict() for k in ("gravity-slide", "push-down")], Settings(trials=3).to_dict(), 2.2)
    return json.dumps(g.to_dict())


def trajectory_base() -> str:
    from regrasp.execution.trajectory import FORMAT, VERSION

    joints = [f"joint{i}" for i in range(6)]
    samples = [{"t": 0.1 * i, "q": [0.01 * i] * 6, "gripper_pose": [0.4, 0.0, 0.9 + 0.001 * i, 1.0, 0.0, 0.0, 0.0],
                "grip_force": 20.0, "label": "push" if 3 <= i < 8 else "transfer", "push": 0 if 3 <= i < 8 else None}
               for i in range(12)]
    return json.dumps({"format": FORMAT, "version": VERSION, "scene": "s", "workcell": "w", "robot": "ur5e-2f85",
                       "joint_names": joints, "samples": samples,
                       "assignments": [{"pusher": "left", "feature": "ledge", "first": 3, "last": 8,
                                        "frame": [0.4, 0.0, 0.8, 1.0, 0.0, 0.0, 0.0], "tilt": 0.1,
                                        "penetration": 0.001}]})


def robot_base() -> str:
    """The bundled UR5e with the 2F-85 as a robot file (its model from the package that ships it)."""
    import tomllib

    from ..test_robot_file import UR5E

    return json.dumps(tomllib.loads(UR5E))


#: kind -> (base JSON text, format of the file, paths (dotted, prefix) whose content is free-form,
#: paths that may be null, whether unknown keys are refused, the prefix of every field named)
KINDS = {
    "workcell": (workcell_base, "toml", ("description",), (), True, ""),
    "plan": (plan_base, "json", ("scene", "stop_reason", "propagation", "path[0].pusher"),
             ("path[0].pusher",) + tuple(k for k in PLAN_KEYS[2] if k != "path"),  # null: not known
             False, "plan."),
    "graph": (graph_base, "json", ("object.", "edges[0].detail", "edges[1].detail", "actions[0].summary",
                                   "actions[0].resource", "actions[1].summary", "actions[1].resource",
                                   "settings.actions", "chained"),
              ("edges[0].to", "edges[1].to", "edges[0].success_rate", "edges[1].success_rate", "edges[0].runs[1].pose", "edges[0].runs[0].pose", "edges[0].runs[2].pose",
               "settings.actions"), False, ""),
    "trajectory": (trajectory_base, "json", (), ("robot",) + tuple(f"samples[{i}].push" for i in range(12)), True, ""),
    "robot": (robot_base, "toml", (), (), True, ""),
}


#: the field that a file's syntax error (or too deep nesting) names
PARSE_FIELD = {"workcell": "(toml)", "plan": "plan", "graph": "graph", "trajectory": "(json)", "robot": "(toml)"}
#: kind -> (the list with a count limit, that limit)
LIMITED = {"workcell": ("features", LIMITS["workcell_features"]), "plan": ("path", LIMITS["plan_steps"] + 1),
           "graph": ("nodes", LIMITS["graph_nodes"])}


def _free(field: str, free: tuple) -> bool:
    return any(field == f or field.startswith(f + ".") or field.startswith(f + "[") or
               (f.endswith(".") and field.startswith(f)) for f in free)


def text_of(d, fmt: str) -> str:
    return to_toml(d) if fmt == "toml" else json.dumps(d)


@st.composite
def mutated_file(draw, kind: str):
    """(file text, what was done, the fields one of which an error must name — empty when the
    file may still be valid)."""
    base, fmt, free, nullable, strict_keys, prefix = KINDS[kind]
    d = json.loads(base())
    op = draw(st.sampled_from(["replace"] * 5 + ["drop", "add", "empty", "repeat", "explode", "truncate", "deep",
                                                 "binary"]))
    if op == "explode" and kind in LIMITED:
        key, most = LIMITED[kind]
        top = d[key]
        d[key] = (top * (most // max(len(top), 1) + 2))[: most + 2]
        return text_of(d, fmt), f"{key} past its limit ({len(d[key])})", [prefix + key.split(".")[0]]
    nodes = [(p, v) for p, v in leaves(d) if p]
    p, v = draw(st.sampled_from(nodes))
    field = dotted(p)
    certain = False
    if op == "replace":
        new = draw(st.sampled_from(REPLACEMENTS))
        _parent(d, p)[p[-1]] = new
        hostile = isinstance(new, float) and not math.isfinite(new) and _types(v) == "number"
        retyped = _types(new) != _types(v) and field not in nullable  # a nullable field takes null or a value
        certain = (hostile or retyped) and not _free(field, free)
        if fmt == "toml" and new is None:  # TOML has no null: the key is dropped
            del _parent(d, p)[p[-1]]
            certain = False
        what = f"{field} = {new!r:.60}"
    elif op == "drop":
        del _parent(d, p)[p[-1]]
        what = f"drop {field}"
    elif op == "add":
        tables = [(q, t) for q, t in leaves(d) if isinstance(t, dict)]
        q, t = draw(st.sampled_from(tables))
        t["frobnicate"] = 1.0
        field = dotted(q + ("frobnicate",))
        certain = strict_keys and not _free(field, free)
        what = f"add {field}"
    elif op in ("empty", "repeat") and isinstance(v, list):
        _parent(d, p)[p[-1]] = [] if op == "empty" else (v * draw(st.sampled_from([2, 50])))[:200_000]
        what = f"{op} {field}"
    else:
        text = text_of(d, fmt)
        if op == "truncate":
            n = draw(st.integers(0, max(len(text) - 1, 0)))
            return text[:n], f"truncated at {n}", []
        if op == "deep":
            depth = draw(st.sampled_from([MAX_NESTING + 1, 1000, 100_000]))
            deep = "[" * depth + "]" * depth
            return (text + f"\nzz = {deep}\n" if fmt == "toml" else text[:-1] + f', "zz": {deep}}}'), \
                f"nested {depth} deep", [PARSE_FIELD[kind]]
        if op == "binary":
            return text[: len(text) // 2] + "\udcff\udcfe\x00", "binary", []
        what = "unchanged"
    must = [prefix + field.split(".")[0].split("[")[0]] if certain else []
    if certain and kind == "trajectory" and op == "replace" and isinstance(new, float) and not math.isfinite(new):
        must.append(PARSE_FIELD[kind])  # NaN and Infinity are not JSON: the trajectory reader refuses the text
    return text_of(d, fmt), what, must


# --- a mesh object -----------------------------------------------------------------------------

MESH_SCENE = EXAMPLES / "prism-3d.toml"
MESH = EXAMPLES / "meshes" / "prism.obj"


@st.composite
def mutated_mesh(draw):
    """(OBJ text, what was done, the fields an error must name — empty when it may be valid)."""
    lines = MESH.read_text().splitlines()
    vs = [i for i, x in enumerate(lines) if x.startswith("v ")]
    op = draw(st.sampled_from(["vertex", "vertex", "face", "drop", "many", "empty", "binary", "flat"]))
    if op == "vertex":
        i = draw(st.sampled_from(vs))
        bad = draw(st.sampled_from(["nan", "inf", "-inf", "1e300", "a", "1e999"]))
        k = draw(st.integers(1, 3))
        parts = lines[i].split()
        parts[k] = bad
        lines[i] = " ".join(parts)
        return "\n".join(lines), f"line {i}: {lines[i]}", ["object.mesh"]
    if op == "face":
        lines.append(f"f 1 2 {draw(st.sampled_from([0, -1, 99999, 2**40]))}")
        return "\n".join(lines), f"face {lines[-1]}", []
    if op == "drop":
        i = draw(st.sampled_from(vs))
        del lines[i]
        return "\n".join(lines), f"drop line {i}", []
    if op == "many":
        n = draw(st.sampled_from([6000, 20000]))
        return Many(lines, n), f"{n} more vertices", ["object.mesh"]
    if op == "empty":
        return "", "empty", ["object.mesh"]
    if op == "binary":
        return "\udcff\udcfe\x00v 1 2", "binary", ["object.mesh"]
    return "\n".join(f"v {x:.3f} 0 0" for x in (0.0, 0.01, 0.02, 0.03)), "all vertices on a line", ["object.mesh"]


class Many(str):
    """An OBJ text with ``n`` more vertices, made when written (its repr stays short)."""

    def __new__(cls, lines, n):
        extra = [f"v {0.01 * math.cos(k * 0.001):.9f} {0.01 * math.sin(k * 0.001):.9f} {k * 1e-6:.9f}" for k in range(n)]
        self = super().__new__(cls, "\n".join(lines + extra))
        self.n = n
        return self

    def __repr__(self):
        return f"<OBJ text with {self.n} more vertices>"


def copy_dict(text: str):
    return copy.deepcopy(json.loads(text))
