"""The workcell: a table, fixed features in the world frame, the robot and where the object
starts (docs/workcell-file.md). World frame: z up, gravity along −z, lengths in metres, poses
``[x, y, z, qw, qx, qy, qz]`` (m, unit quaternion).

A feature's *contacts* are what it offers a pusher (:meth:`Workcell.contacts`): a **corner** (a
point), an **edge** (a segment) or a **face** (a rectangle), each with a contact frame in the
world whose origin is the contact point (an edge's midpoint, a face's centre), whose +z is the
direction the feature pushes an object touching it, and whose +x runs along an edge. A block
offers its 6 faces, 12 edges (pushing along the bisector of their two faces' normals) and 8
corners (along the diagonal); the table offers its top face at its centre. A contact that lies
on or below the table top is not offered (an object cannot reach it)."""

from __future__ import annotations

import itertools
import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import pose as P
from ..errors import ArgumentError, SceneError
from ..fields import MAX_WORKCELL_FEATURES, FieldCheck
from ..files import parse_toml

#: The bounds of a workcell file's numbers (inclusive), stated once: (low, high, unit).
BOUNDS = {
    "coordinate": (-100.0, 100.0, "m"),   # positions, table.height, table.center
    "size": (1e-4, 10.0, "m"),            # table.size, features[].size, features[].length
    "friction": (0.0, 100.0, ""),         # features[].friction (pusher friction)
    "support_friction": (1e-6, 100.0, ""),  # table.friction
    "quaternion_norm": (1e-6, 1e6, ""),   # a pose's quaternion (it is normalized)
}
#: The kinds of feature a workcell file may list.
FEATURE_KINDS = ("edge", "corner", "block", "face")
#: Where the object may start: on the table (at ``object.pose``, world frame) or in the hand.
OBJECT_STARTS = ("table", "hand")
#: Height [m] above the table top at or below which a contact is not offered.
ON_TABLE = 1e-6
#: The clearance [m] the gripper and object keep above every feature's top on transfers and
#: before a push (the world motion's default ``Timing.clearance``; :attr:`Workcell.clearance`).
CLEARANCE = 0.02
#: How far [rad] an object's face touching a block edge stays from lying flat on either of the
#: block's faces (where the line contact would become a face contact).
EDGE_MARGIN = np.radians(5.0)


_CHECK = FieldCheck("workcell")
_fail = _CHECK.fail


def check_number(x, field_: str, kind: str) -> float:
    """``x`` as a float when it is a finite number within ``BOUNDS[kind]``; else a SceneError
    naming ``field_`` (its unit is that of the bound, e.g. [m])."""
    return _CHECK.number(x, field_, *BOUNDS[kind])


def check_numbers(x, n: int, field_: str, kind: str) -> np.ndarray:
    """``x`` as an array of ``n`` floats each within ``BOUNDS[kind]`` (units as that bound), else a
    SceneError naming ``field_`` (a component as ``field_[i]``)."""
    return _CHECK.vector(x, n, field_, *BOUNDS[kind])


def check_pose(x, field_: str) -> np.ndarray:
    """A pose ``[x, y, z, qw, qx, qy, qz]`` (m, quaternion; normalized unless within 1e-12 of
    unit norm), else a SceneError naming ``field_``."""
    v = _CHECK.vector(x, 7, field_, *BOUNDS["coordinate"], what="[x, y, z, qw, qx, qy, qz]")
    p, q = v[:3], v[3:]
    lo, hi, _ = BOUNDS["quaternion_norm"]
    nq = float(np.linalg.norm(q))
    if not lo <= nq <= hi:
        raise _fail(field_, f"the quaternion's norm must be in [{lo:g}, {hi:g}]", nq)
    return np.concatenate([p, q if abs(nq - 1) <= 1e-12 else q / nq])  # a unit one is kept as written


def check_name(x, field_: str) -> str:
    """A non-blank string, else a SceneError naming ``field_``."""
    return _CHECK.name(x, field_)


@dataclass(frozen=True, eq=False)
class Table:
    """The table: its top surface at height ``height`` [m] (world z), a rectangle of ``size``
    ``[x, y]`` [m] centred at ``center`` ``[x, y]`` [m], object-table friction ``friction``."""
    height: float
    size: np.ndarray
    friction: float
    center: np.ndarray = field(default_factory=lambda: np.zeros(2))

    def __post_init__(self):
        object.__setattr__(self, "height", check_number(self.height, "table.height", "coordinate"))
        object.__setattr__(self, "size", check_numbers(self.size, 2, "table.size", "size"))
        object.__setattr__(self, "friction", check_number(self.friction, "table.friction", "support_friction"))
        object.__setattr__(self, "center", check_numbers(self.center, 2, "table.center", "coordinate"))


    def off(self, pose) -> tuple[int, str] | None:
        """Why an object's origin at world ``pose`` (m) is not on the table — (the pose's index at
        fault, what it must be) — or None: it lies over the table's rectangle and above its top by
        at most the largest object size (10 m)."""
        p, most = np.asarray(pose, float), BOUNDS["size"][1]
        if not self.height < p[2] <= self.height + most:
            return 2, f"must be above the table top ({self.height:g} m) by at most {most:g} m"
        off = np.abs(p[:2] - self.center) - self.size / 2
        if np.any(off > 1e-9):
            return int(np.argmax(off)), (f"must lie over the table (its centre {self.center.tolist()}, size "
                                         f"{self.size.tolist()} m)")
        return None


@dataclass(frozen=True, eq=False)
class Feature:
    """A fixed feature in the world frame: ``kind`` ``"edge"`` (a segment of ``length`` [m] along
    the pose's x axis, centred at its origin, pushing along its z axis), ``"corner"`` (the pose's
    origin, pushing along its z axis), ``"block"`` (a box of ``size`` ``[x, y, z]`` [m] centred on
    the pose) or ``"face"`` (a rectangle of ``size`` ``[x, y]`` [m] in the pose's x-y plane,
    pushing along its z axis); ``pose`` (m, unit quaternion) in the world; ``friction`` with the
    object. ``index`` is its place in the file (for error messages)."""
    name: str
    kind: str
    pose: np.ndarray
    friction: float
    size: np.ndarray | None = None
    length: float | None = None
    index: int = 0

    def __post_init__(self):
        f = f"features[{self.index}]"
        check_name(self.name, f"{f}.name")
        if self.name == "table":
            raise _fail(f"{f}.name", "`table` is the table's name", self.name)
        if self.kind not in FEATURE_KINDS:
            raise _fail(f"{f}.kind", f"must be one of {', '.join(FEATURE_KINDS)}", self.kind)
        object.__setattr__(self, "pose", check_pose(self.pose, f"{f}.pose"))
        object.__setattr__(self, "friction", check_number(self.friction, f"{f}.friction", "friction"))
        sizes = {"block": 3, "face": 2}
        if self.kind in sizes:
            if self.size is None:
                raise _fail(f"{f}.size", f"is required for a {self.kind}", None)
            object.__setattr__(self, "size", check_numbers(self.size, sizes[self.kind], f"{f}.size", "size"))
        elif self.size is not None:
            raise _fail(f"{f}.size", f"does not apply to an {self.kind}" if self.kind == "edge" else
                        f"does not apply to a {self.kind}", self.size)
        if self.kind == "edge":
            if self.length is None:
                raise _fail(f"{f}.length", "is required for an edge", None)
            object.__setattr__(self, "length", check_number(self.length, f"{f}.length", "size"))
        elif self.length is not None:
            raise _fail(f"{f}.length", "applies only to an edge", self.length)


@dataclass(frozen=True, eq=False)
class Robot:
    """The robot: its model ``name`` (e.g. ``"ur5e"``) and its base ``base`` pose (m, unit
    quaternion) in the world."""
    name: str
    base: np.ndarray

    def __post_init__(self):
        check_name(self.name, "robot.name")
        object.__setattr__(self, "base", check_pose(self.base, "robot.base"))


@dataclass(frozen=True, eq=False)
class ObjectStart:
    """Where the object starts: ``on`` ``"table"`` at ``pose`` (m, unit quaternion; world frame),
    or ``"hand"`` (held at the scene's ``task.start``; no pose)."""
    on: str
    pose: np.ndarray | None = None

    def __post_init__(self):
        if self.on not in OBJECT_STARTS:
            raise _fail("object.on", f"must be one of {', '.join(OBJECT_STARTS)}", self.on)
        if self.on == "table":
            if self.pose is None:
                raise _fail("object.pose", "is required when the object starts on the table", None)
            object.__setattr__(self, "pose", check_pose(self.pose, "object.pose"))
        elif self.pose is not None:
            raise _fail("object.pose", "does not apply when the object starts in the hand", self.pose)


@dataclass(frozen=True, eq=False)
class Contact:
    """What a feature offers a pusher: ``kind`` ``"corner"``, ``"edge"`` or ``"face"``; ``frame``
    (m, unit quaternion): its contact frame in the world (origin: the contact point, +z: the
    direction it pushes, +x: along an edge); ``length`` [m] of an edge (0 otherwise); ``extent``
    ``[x, y]`` [m]: a face's half-sizes along the frame's x and y (zeros otherwise);
    ``friction``; ``name``: the feature's name, a block's part as ``NAME.faces[i]``,
    ``NAME.edges[i]``, ``NAME.corners[i]``; ``cone`` [rad]: how far the push direction may turn
    about an edge (about the frame's x) either way and stay a line contact on it (a block edge:
    45° less :data:`EDGE_MARGIN`, the object's face between the block's two faces; else 0)."""
    name: str
    kind: str
    frame: np.ndarray
    friction: float
    length: float = 0.0
    extent: np.ndarray = field(default_factory=lambda: np.zeros(2))
    cone: float = 0.0


def _frame(z, x, origin) -> np.ndarray:
    z = np.asarray(z, float) / np.linalg.norm(z)
    x = np.asarray(x, float) - (np.asarray(x, float) @ z) * z
    x /= np.linalg.norm(x)
    return P.from_frame(np.column_stack([x, np.cross(z, x), z]), origin)


def block_contacts(f: Feature) -> list[Contact]:
    """The 6 faces, 12 edges and 8 corners of block feature ``f`` as contacts in the world."""
    h, E, out = np.asarray(f.size) / 2, np.eye(3), []
    local = []
    for a, s in itertools.product(range(3), (1, -1)):
        b, c = (a + 1) % 3, (a + 2) % 3
        local.append(("faces", "face", _frame(s * E[a], E[b], s * h[a] * E[a]), 0.0, np.array([h[b], h[c]])))
    for a in range(3):
        b, c = (a + 1) % 3, (a + 2) % 3
        for s1, s2 in itertools.product((1, -1), (1, -1)):
            mid = s1 * h[b] * E[b] + s2 * h[c] * E[c]
            local.append(("edges", "edge", _frame(s1 * E[b] + s2 * E[c], E[a], mid), 2 * h[a], np.zeros(2)))
    for s in itertools.product((1, -1), repeat=3):
        z = np.array(s, float)
        local.append(("corners", "corner", _frame(z, P.tangents(z)[0], z * h), 0.0, np.zeros(2)))
    counts: dict = {}
    for group, kind, fr, length, extent in local:
        i = counts[group] = counts.get(group, -1) + 1
        cone = np.pi / 4 - EDGE_MARGIN if kind == "edge" else 0.0
        out.append(Contact(f"{f.name}.{group}[{i}]", kind, P.compose(f.pose, fr), f.friction, float(length), extent,
                           cone))
    return out


@dataclass(frozen=True, eq=False)
class Workcell:
    """A workcell (docs/workcell-file.md): ``name``, the ``table``, the fixed ``features`` (a
    tuple of :class:`Feature`), the ``robot`` and the object's start (``object``). Read and
    written by :meth:`load` / :meth:`save` (TOML) and :meth:`from_dict` / :meth:`to_dict`."""
    name: str
    table: Table
    features: tuple
    robot: Robot
    object: ObjectStart = field(default_factory=lambda: ObjectStart("hand"))
    description: str | None = None

    def __post_init__(self):
        check_name(self.name, "name")
        for f_, t_ in (("table", Table), ("robot", Robot), ("object", ObjectStart)):
            if not isinstance(getattr(self, f_), t_):
                raise _fail(f_, f"must be a {t_.__name__}", type(getattr(self, f_)).__name__)
        if not isinstance(self.features, (list, tuple)) or not all(isinstance(f, Feature) for f in self.features):
            raise _fail("features", "must be a sequence of Feature", self.features)
        if self.description is not None and not isinstance(self.description, str):
            raise _fail("description", "must be a string", self.description)
        object.__setattr__(self, "features", tuple(self.features))
        _CHECK.count(self.features, "features", MAX_WORKCELL_FEATURES, "features")
        self._check_start()
        seen: dict = {}
        for i, f in enumerate(self.features):
            if f.name in seen:
                raise _fail(f"features[{i}].name", f"repeats features[{seen[f.name]}].name", f.name)
            seen[f.name] = i

    def _check_start(self) -> None:
        """An object starting on the table starts on it (:meth:`Table.off`)."""
        if self.object.on != "table":
            return
        off = self.table.off(self.object.pose)
        if off is not None:
            k, why = off
            raise _fail(f"object.pose[{k}]", f"{why}: the object starts on the table", float(self.object.pose[k]))

    def __eq__(self, other) -> bool:
        """Workcells are equal when their files are (:meth:`to_dict`)."""
        return isinstance(other, Workcell) and self.to_dict() == other.to_dict()

    __hash__ = None  # type: ignore[assignment]

    def feature(self, name: str) -> Feature:
        """The feature called ``name``."""
        for f in self.features:
            if f.name == name:
                return f
        raise SceneError(f"workcell has no feature `{name}`", "features")

    def contacts(self) -> list[Contact]:
        """Everything the workcell offers a pusher (see the module's doc): the table's top face
        first, then each feature's contacts in file order, those on or below the table top left
        out."""
        t = self.table
        out = [Contact("table", "face", np.array([*t.center, t.height, 1.0, 0, 0, 0]), t.friction, 0.0, t.size / 2)]
        for f in self.features:
            if f.kind == "block":
                cs = block_contacts(f)
            elif f.kind == "face":
                cs = [Contact(f.name, "face", f.pose, f.friction, 0.0, np.asarray(f.size) / 2)]
            else:
                cs = [Contact(f.name, f.kind, f.pose, f.friction, float(f.length or 0.0))]
            out += [c for c in cs if c.frame[2] > t.height + ON_TABLE]
        return out

    #: the clearance [m] above every feature's top that transfers keep (:data:`CLEARANCE`)
    clearance = CLEARANCE

    def contact_owners(self) -> dict:
        """The feature (``"table"`` for the table) that owns each contact name: a block's
        ``NAME.faces[i]``, ``NAME.edges[i]`` and ``NAME.corners[i]`` belong to ``NAME``."""
        out = {"table": "table"}
        for f in self.features:
            out.update({c.name: f.name for c in block_contacts(f)} if f.kind == "block" else {f.name: f.name})
        return out

    def top(self) -> float:
        """The highest point [m] (world z) of the table and every feature's body
        (:func:`regrasp.workcell.shapes.shapes`: an edge's bar and a corner's ball included)."""
        from .shapes import shapes

        return max([self.table.height] + [s.top for s in shapes(self)])

    # -- the file (regrasp.workcell.file) ------------------------------------------------------

    @classmethod
    def load(cls, path) -> "Workcell":
        """The workcell of a TOML file; SceneError naming the field at fault (``(toml)`` for a
        syntax error), ArgumentError when ``path`` cannot be read."""
        return load(path)

    @classmethod
    def from_toml(cls, text: str) -> "Workcell":
        """The workcell of a TOML text (see :meth:`load`)."""
        return from_toml(text)

    @classmethod
    def from_dict(cls, d: dict) -> "Workcell":
        """The workcell of a dict laid out as the file (see :meth:`load`)."""
        return from_dict(d)

    def to_dict(self) -> dict:
        """The workcell as a dict laid out as the file (lists of floats)."""
        return to_dict(self)

    def to_toml(self) -> str:
        """The workcell's TOML text (:meth:`from_toml` reads it back equal)."""
        return to_toml(self)

    def save(self, path) -> None:
        """Write the workcell's TOML file to ``path``."""
        save(self, path)

    def html(self, scene=None) -> str:
        """The workcell's browser view, a self-contained HTML page (see
        :func:`regrasp.viz.viewer.workcell_html`); with ``scene``, its object where it starts."""
        from ..viz.viewer import workcell_html

        return workcell_html(self, scene)

    def _repr_html_(self) -> str:
        """Jupyter's display: the workcell's browser view in a frame."""
        from ..viz.viewer import iframe

        return iframe(self.html())


# --- the file (TOML, docs/workcell-file.md): read with every key checked (unknown keys, missing
# keys, types, bounds; the error names the dotted field), and written back ---------------------

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
    _CHECK.count(fs, "features", MAX_WORKCELL_FEATURES, "features")
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
    return from_dict(parse_toml(text, "(toml)", lambda why: SceneError(f"workcell field `(toml)`: {why}", "(toml)")))


def load(path) -> Workcell:
    """The workcell of the TOML file at ``path``; ArgumentError when it cannot be read."""
    from ..files import read_text

    return from_toml(read_text(path, "workcell"))


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
