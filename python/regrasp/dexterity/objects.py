"""An object for the grasp graph: a 3-D scene file (docs/scene-file.md) of which the
``[object]``, ``[grasp]`` and ``[gravity]`` tables are read; its ``[[pushers]]`` and ``[task]``
are optional (a task is required by :meth:`regrasp.Scene3D.load`: without one, the object is
loaded with a still one at the origin, which nothing here uses). An optional ``[taxonomy]``
table sets the taxonomy's options (``lateral``: the fractions of the grasps held off the
object's centre across the fingers, :func:`regrasp.dexterity.taxonomy.taxonomy`; read here
only: :meth:`regrasp.Scene3D.load` accepts the table and ignores it). The bundled
objects (:data:`OBJECTS`): the thesis' triangular prism, a cylinder and a box, and a bar held
near its ends for the gravity pivots."""

from __future__ import annotations

from importlib.resources import files
from pathlib import Path

from ..errors import ArgumentError, SceneError
from ..files import parse_toml, read_text

OBJECTS = ("prism", "cylinder", "box", "bar")  # examples/objects/NAME.toml
STILL_TASK = "\n[task]\nstart = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]\ngoal = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]\n" \
             "tolerance = [0.001, 0.001, 0.001, 0.0175]\n"


PLACEHOLDER = "_unused"  # the name of the pusher added to an object file without one (the loader needs one)


def _placeholder(data: dict, base: Path) -> str:
    """A ``[[pushers]]`` table at a point of the object's surface (a box's face centre, a
    sphere's pole, a mesh's first vertex): :meth:`regrasp.Scene3D.load` needs one pusher; the
    grasp graph uses none."""
    obj = data.get("object", {})
    try:
        if obj.get("shape") == "box":
            point = [float(obj["size"][0]) / 2, 0.0, 0.0]
        elif obj.get("shape") == "sphere":
            point = [float(obj["radius"]), 0.0, 0.0]
        else:
            rows = [x.split()[1:4] for x in read_text(base / obj["mesh"], "object.mesh").splitlines()
                    if x.startswith("v ")]
            vertices = [[float(c) for c in r] for r in rows]
            point = vertices[0]
            centre = [sum(v[k] for v in vertices) / len(vertices) for k in range(3)]
            normal = [c - p for c, p in zip(centre, point)]  # into the object (towards its vertices' centroid)
            return _pusher(point, normal)
    except (KeyError, TypeError, ValueError, IndexError, OSError, StopIteration, ZeroDivisionError, ArgumentError,
            AttributeError):
        return ""  # the loader names what is wrong with the object table
    return _pusher(point, [-c for c in point])  # into the object (a box or sphere about its origin)


def _pusher(point, normal) -> str:
    return f"\n[[pushers]]\nname = \"{PLACEHOLDER}\"\nfriction = 0.0\npoints = [{list(point)}]\nnormal = {list(normal)}\n"


def object_path(name: str) -> Path:
    """The path of bundled object ``name`` (:data:`OBJECTS`)."""
    return Path(str(files("regrasp") / "examples" / "objects" / f"{name}.toml"))


def load_object(path):
    """The :class:`regrasp.Scene3D` of the object file ``path`` (or a bundled object's name),
    its task optional; a SceneError naming the field for a bad file (``dimension`` when it is
    not a 3-D scene)."""
    from ..scene.spatial import Scene3D

    if isinstance(path, str) and path in OBJECTS:
        path = object_path(path)
    path = Path(path)
    try:
        text = read_text(path, "object")
    except ArgumentError as e:
        raise ArgumentError(f"{e}; the bundled objects: {', '.join(OBJECTS)}", "object") from None
    data = parse_toml(text, "(toml)", lambda why: SceneError(f"scene field `(toml)`: {why}", "(toml)"))
    if data.get("dimension") != 3:
        raise SceneError("scene field `dimension`: the grasp graph needs a 3-D scene (`dimension = 3`)", "dimension")
    if not data.get("pushers"):
        text += _placeholder(data, path.parent)
    if "task" not in data:
        text += STILL_TASK
    scene = Scene3D.from_toml(text, path.parent)
    scene.path = path
    scene.taxonomy_lateral = _lateral(data.get("taxonomy", {}).get("lateral", ()))
    return scene


def _lateral(value) -> tuple:
    """``[taxonomy] lateral`` checked: fractions in (−½, ½), not 0 (a SceneError naming it)."""
    from .taxonomy import _check_lateral

    try:
        return _check_lateral(value)
    except ArgumentError as e:
        raise SceneError(f"scene field `taxonomy.lateral`: {str(e).split(': ', 1)[-1]}", "taxonomy.lateral") from None
