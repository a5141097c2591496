"""The workcell file (TOML, docs/workcell-file.md): read it into a :class:`Workcell`, checking
every key (unknown keys, missing keys, types, bounds; the error names the dotted field), and
write it back."""

from __future__ import annotations

import json
import math
import tomllib
from pathlib import Path

import numpy as np

from ..errors import ArgumentError, SceneError
from .description import Feature, ObjectStart, Robot, Table, Workcell

#: The folder of the bundled workcell files (``workcell-ur5e.toml``).
BUNDLED = Path(__file__).resolve().parents[1] / "examples" / "workcells"

#: The keys of each table of the file: (required, optional).
KEYS = {
    "": ({"name", "table", "robot"}, {"description", "features", "object"}),
    "table": ({"height", "size", "friction"}, {"center"}),
    "robot": ({"name", "base"}, set()),
    "object": ({"on"}, {"pose"}),
    "features[]": ({"name", "kind", "pose", "friction"}, {"size", "length", "description"}),
}


def _table(d, where: str, kind: str) -> dict:
    if not isinstance(d, dict):
        raise SceneError(f"workcell field `{where or '(toml)'}`: must be a table (got {d!r:.60})", where or "(toml)")
    required, optional = KEYS[kind]
    for k in d:
        if k not in required | optional:
            f = f"{where}.{k}" if where else k
            raise SceneError(f"workcell field `{f}`: unknown field; allowed here: {', '.join(sorted(required | optional))}", f)
    for k in sorted(required):
        if k not in d:
            f = f"{where}.{k}" if where else k
            raise SceneError(f"workcell field `{f}`: is required", f)
    return d


def from_dict(d) -> Workcell:
    """The workcell of a dict laid out as the file; SceneError naming the field at fault."""
    _table(d, "", "")
    t = _table(d["table"], "table", "table")
    table = Table(t["height"], t["size"], t["friction"], t.get("center", [0.0, 0.0]))
    r = _table(d["robot"], "robot", "robot")
    robot = Robot(r["name"], r["base"])
    start = ObjectStart("hand")
    if "object" in d:
        o = _table(d["object"], "object", "object")
        start = ObjectStart(o["on"], o.get("pose"))
    fs = d.get("features", [])
    if not isinstance(fs, list):
        raise SceneError(f"workcell field `features`: must be an array of tables (got {fs!r:.60})", "features")
    features = []
    for i, f in enumerate(fs):
        _table(f, f"features[{i}]", "features[]")
        features.append(Feature(f["name"], f["kind"], f["pose"], f["friction"], f.get("size"), f.get("length"), i))
    desc = d.get("description")
    if desc is not None and not isinstance(desc, str):
        raise SceneError(f"workcell field `description`: must be a string (got {desc!r:.60})", "description")
    return Workcell(d["name"], table, tuple(features), robot, start, desc)


def from_toml(text: str) -> Workcell:
    """The workcell of a TOML text; SceneError naming the field (``(toml)`` for a syntax error)."""
    if not isinstance(text, str):
        raise ArgumentError(f"invalid `text`: the workcell file's text, a str (got {type(text).__name__})", "text")
    try:
        d = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise SceneError(f"workcell field `(toml)`: {e}", "(toml)") from None
    return from_dict(d)


def load(path) -> Workcell:
    """The workcell of the TOML file at ``path``; ArgumentError when it cannot be read."""
    try:
        text = Path(path).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError, TypeError, ValueError) as e:
        raise ArgumentError(f"invalid `workcell`: cannot read {str(path)!r}: {e}", "workcell") from None
    return from_toml(text)


def bundled(name: str = "workcell-ur5e") -> Path:
    """The path of bundled workcell file ``name`` (``.toml`` optional); ArgumentError listing them
    when there is none."""
    names = sorted(p.stem for p in BUNDLED.glob("*.toml"))
    stem = str(name).removesuffix(".toml")
    if stem not in names:
        raise ArgumentError(f"invalid `name`: no bundled workcell {name!r}; the workcells: {', '.join(names)}", "name")
    return BUNDLED / f"{stem}.toml"


def _floats(a) -> list:
    return [float(x) for x in np.asarray(a, float)]


def to_dict(w: Workcell) -> dict:
    """The workcell as a dict laid out as the file."""
    d: dict = {"name": w.name}
    if w.description is not None:
        d["description"] = w.description
    d["table"] = {"height": float(w.table.height), "size": _floats(w.table.size), "friction": float(w.table.friction),
                  "center": _floats(w.table.center)}
    d["robot"] = {"name": w.robot.name, "base": _floats(w.robot.base)}
    d["object"] = {"on": w.object.on} | ({"pose": _floats(w.object.pose)} if w.object.pose is not None else {})
    d["features"] = []
    for f in w.features:
        e = {"name": f.name, "kind": f.kind, "pose": _floats(f.pose), "friction": float(f.friction)}
        if f.size is not None:
            e["size"] = _floats(f.size)
        if f.length is not None:
            e["length"] = float(f.length)
        d["features"].append(e)
    return d


def toml_value(v) -> str:
    """The TOML text of a value: a string, a bool, an int, a finite float, a list (or numpy
    array) or a table (an inline one) of them (floats written exactly: ``repr``). A ValueError
    for anything else (a datetime, a NaN)."""
    if hasattr(v, "tolist"):  # a numpy array or scalar
        v = v.tolist()
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False)  # a JSON string is a TOML basic string
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{json.dumps(str(k))} = {toml_value(x)}" for k, x in v.items()) + "}"
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float) and math.isfinite(v):
        return repr(v)
    raise ValueError(f"no TOML value for {v!r}")


def to_toml(w: Workcell) -> str:
    """The workcell's TOML text (floats written exactly: ``from_toml`` reads back the same numbers)."""
    d = to_dict(w)
    lines = [f"{k} = {toml_value(d[k])}" for k in ("name", "description") if k in d]
    for table in ("table", "robot", "object"):
        lines += ["", f"[{table}]"] + [f"{k} = {toml_value(v)}" for k, v in d[table].items()]
    for f in d["features"]:
        lines += ["", "[[features]]"] + [f"{k} = {toml_value(v)}" for k, v in f.items()]
    return "\n".join(lines) + "\n"


def save(w: Workcell, path) -> None:
    """Write the workcell's TOML file to ``path`` (through a temporary file, then renamed)."""
    p = Path(path)
    tmp = p.with_name(p.name + ".tmp")
    tmp.write_text(to_toml(w), encoding="utf-8")
    tmp.replace(p)
