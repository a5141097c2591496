"""The workcell file, its contacts and the default workcell (regrasp.workcell)."""

import itertools
import tomllib

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import regrasp
from regrasp import ArgumentError, SceneError
from regrasp.execution.assignment import assign, pusher_contact
from regrasp.execution import default_workcell
from regrasp.workcell import Feature, Workcell, bundled
from regrasp.fields import MAX_WORKCELL_FEATURES
from regrasp.workcell.description import BOUNDS

from .conftest import rotation_matrix as rot

EXAMPLE = regrasp.examples.ROOT / "workcells" / "workcell-ur5e.toml"


def example_dict():
    return tomllib.loads(EXAMPLE.read_text())


def test_example_loads_and_round_trips(tmp_path):
    w = Workcell.load(EXAMPLE)
    assert w.robot.name == "ur5e" and w.object.on == "table" and len(w.features) == 4
    assert Workcell.from_toml(w.to_toml()).to_dict() == w.to_dict()
    assert Workcell.from_toml(w.to_toml()) == w and w != default_workcell(regrasp.load_scene(regrasp.examples.path("t-shape")))
    assert bundled() == EXAMPLE and bundled("workcell-ur5e.toml") == EXAMPLE
    with pytest.raises(ArgumentError, match="workcell-ur5e"):
        bundled("nope")
    w.save(tmp_path / "w.toml")
    assert Workcell.load(tmp_path / "w.toml").to_dict() == w.to_dict()
    # the file's numbers are read as written (independent of the writer)
    d = example_dict()
    assert w.table.height == d["table"]["height"]
    assert np.allclose(w.feature("fixture").pose, d["features"][0]["pose"])


def test_contacts_of_a_block_are_its_faces_edges_and_corners():
    w = Workcell.load(EXAMPLE)
    f = w.feature("fixture")
    c, h = f.pose[:3], f.size / 2
    cs = {c_.name: c_ for c_ in w.contacts() if c_.name.startswith("fixture.")}
    # the bottom face, its 4 edges and 4 corners rest on the table: not offered
    assert len(cs) == 26 - 9
    verts = np.array(list(itertools.product(*[(-s, s) for s in h]))) + c
    for name, k in cs.items():
        R, o = rot(k.frame[3:]), k.frame[:3]
        assert np.allclose(R.T @ R, np.eye(3)) and np.isclose(np.linalg.det(R), 1)
        rel = (o - c) / h                       # in units of the half sizes
        on = np.isclose(np.abs(rel), 1)
        if k.kind == "corner":
            assert on.all() and np.allclose(R[:, 2], np.sign(rel) / np.sqrt(3))
            assert np.min(np.linalg.norm(verts - o, axis=1)) < 1e-12
        elif k.kind == "edge":
            assert on.sum() == 2 and np.isclose(k.length, 2 * h[~on][0])
            assert np.allclose(np.abs(R[:, 0]), (~on).astype(float))          # along the free axis
            assert np.allclose(R[:, 2], np.where(on, np.sign(rel), 0) / np.sqrt(2))
        else:
            assert on.sum() == 1 and np.allclose(R[:, 2], np.where(on, np.sign(rel), 0))
            assert np.isclose(np.prod(2 * k.extent), np.prod(2 * h[~on]))
        assert o[2] > w.table.height                                          # above the table top
    table = w.contacts()[0]
    assert table.name == "table" and np.allclose(table.frame, [0.5, 0, 0.75, 1, 0, 0, 0])


def leaves(d, path=""):
    """(dotted path, container, key) of every value of the file's dict, numbers of arrays too."""
    items = d.items() if isinstance(d, dict) else enumerate(d)
    for k, v in items:
        p = (f"{path}.{k}" if path else k) if isinstance(d, dict) else f"{path}[{k}]"
        yield p, d, k
        if isinstance(v, (dict, list)):
            yield from leaves(v, p)


PATHS = [p for p, _, _ in leaves(example_dict())]
BAD = [float("nan"), float("inf"), -float("inf"), 1e300, -1e300, -1.0, 0.0, "x", "", True, [], [1.0], {"a": 1}, None]


def mutate(path, value):
    d = example_dict()
    for p, parent, k in leaves(d):
        if p == path:
            if value is None:
                del parent[k]
            else:
                parent[k] = value
            return d
    raise AssertionError(path)


@settings(max_examples=300, deadline=None)
@given(st.sampled_from(PATHS), st.sampled_from(BAD))
def test_mutations_are_refused_naming_the_field(path, value):
    d = mutate(path, value)
    try:
        w = Workcell.from_dict(d)
    except SceneError as e:
        assert e.field and f"`{e.field}`" in str(e)
        # the error names the mutated field, or a field inside it, or the table that lost a key; a
        # table moved or shrunk (a valid value) may leave the object, which starts on it, off it
        parent = path.rsplit(".", 1)[0] if "." in path else ""
        off_table = path.startswith("table.") and e.field.startswith("object.pose") and "over the table" in str(e)
        assert e.field.startswith(path) or e.field.startswith(parent.split("[")[0]) or path.startswith(e.field) \
            or off_table, (path, e.field)
        return
    # accepted: then the value was valid there, and the workcell round-trips
    assert Workcell.from_toml(w.to_toml()).to_dict() == w.to_dict()


@settings(max_examples=100, deadline=None)
@given(st.sampled_from(["", "table", "robot", "object", "features[0]", "features[2]"]), st.text(min_size=1, max_size=8))
def test_unknown_keys_are_refused(where, key):
    d = example_dict()
    target = d
    for part in [p for p in where.replace("[", ".").replace("]", "").split(".") if p]:
        target = target[int(part)] if part.isdigit() else target[part]
    if key in target:
        return
    target[key] = 1.0
    with pytest.raises(SceneError) as e:
        Workcell.from_dict(d)
    assert e.value.field == (f"{where}.{key}" if where else key)
    assert "unknown field" in str(e.value)


def test_specific_errors():
    d = example_dict()
    d["features"][1]["pose"][3:] = [0, 0, 0, 0]
    with pytest.raises(SceneError, match="quaternion") as e:
        Workcell.from_dict(d)
    assert e.value.field == "features[1].pose"
    d = example_dict()
    d["features"][2]["name"] = "fixture"
    with pytest.raises(SceneError, match="repeats") as e:
        Workcell.from_dict(d)
    assert e.value.field == "features[2].name"
    d = example_dict()
    d["features"][0]["length"] = 0.1
    with pytest.raises(SceneError) as e:
        Workcell.from_dict(d)
    assert e.value.field == "features[0].length"
    d = example_dict()
    d["object"] = {"on": "hand", "pose": [0, 0, 0, 1, 0, 0, 0]}
    with pytest.raises(SceneError) as e:
        Workcell.from_dict(d)
    assert e.value.field == "object.pose"
    with pytest.raises(SceneError) as e:
        Workcell.from_toml("name = [")
    assert e.value.field == "(toml)"
    with pytest.raises(ArgumentError):
        Workcell.load("/nonexistent/w.toml")
    lo, hi, _ = BOUNDS["size"]
    d = example_dict()
    d["table"]["size"] = [hi * 2, 1.0]
    with pytest.raises(SceneError, match=r"\[0.0001, 10\] m") as e:
        Workcell.from_dict(d)
    assert e.value.field == "table.size[0]"


@pytest.mark.parametrize("name", regrasp.examples.names())
def test_default_workcell_serves_every_pusher(name):
    scene = regrasp.load_scene(regrasp.examples.path(name))
    w = default_workcell(scene)
    assert Workcell.from_toml(w.to_toml()).to_dict() == w.to_dict()
    start = scene.task.start if scene.dimension == 2 and scene.task else (
        scene.task[0] if scene.dimension == 3 else np.zeros(3))
    contacts = {c.name: c for c in w.contacts()}
    for p in scene.pusher_names:
        (a,) = assign(scene, [start, start], [None, p], w, max_tilt=np.pi)  # kinds and sizes; tilt: test_world_motion
        c, pc = contacts[a.feature], pusher_contact(scene, p, start)
        # independent check of the kinds and sizes from the scene's own pusher points
        pts = (np.asarray(scene.pusher(p).points) if scene.dimension == 2
               else np.asarray(scene._core.pusher_spec(p, list(start))[0]))
        plane = scene.dimension == 3 and scene._core.is_plane(p)
        if plane or len(pts) >= 3:
            assert c.kind == "face"
        elif len(pts) == 1:
            assert c.kind == "corner"
        else:
            assert c.kind in ("edge", "face")
            if c.kind == "edge":
                assert c.length >= np.linalg.norm(pts[1] - pts[0]) - 1e-12
            else:
                assert c.name == "table"        # a line pusher from below rests on the table
        # features at the pushers' own friction (the plan's); where the scene's pushers differ,
        # a shared feature has the largest
        mus = {scene.pusher(q).friction if scene.dimension == 2 else scene._core.pusher_spec(q, list(start))[2]
               for q in scene.pusher_names}
        assert c.friction == pc.friction if len(mus) == 1 else c.friction >= pc.friction
        assert np.isclose(np.linalg.norm(a.frame[3:]), 1) and np.allclose(a.frame[:3], c.frame[:3])


def test_the_documented_keys_are_the_loaders_and_the_example_loads():
    import re

    from regrasp.workcell.file import KEYS

    doc = (regrasp.examples.ROOT.parents[2] / "docs" / "workcell-file.md").read_text()
    documented = set(re.findall(r"^\| `([a-z_.\[\]]+)` \|", doc, re.M))
    accepted = set()
    for table, (req, opt) in KEYS.items():
        accepted |= {f"{table}.{k}" if table else k for k in req | opt}
    accepted |= {"table", "robot", "object", "features"}
    assert documented == accepted
    block = re.search(r"```toml\n(.*?)```", doc, re.S).group(1)
    w = Workcell.from_toml(block)
    assert {k: v for k, v in w.to_dict().items() if k != "description"} == \
        {k: v for k, v in Workcell.load(EXAMPLE).to_dict().items() if k != "description"}


unit_quats = st.lists(st.floats(-1, 1), min_size=4, max_size=4).filter(lambda q: np.linalg.norm(q) > 0.1)


@settings(max_examples=60, deadline=None)
@given(unit_quats, st.lists(st.floats(0.01, 0.5), min_size=3, max_size=3),
       st.lists(st.floats(-1, 1), min_size=3, max_size=3))
def test_block_contacts_lie_on_the_block_for_any_pose(q, size, at):
    from regrasp.workcell.description import block_contacts

    q = np.asarray(q) / np.linalg.norm(q)
    f = Feature("b", "block", [*at, *q], 0.5, size)
    R, c, h = rot(q), np.asarray(at), np.asarray(size) / 2
    cs = block_contacts(f)
    assert [k.kind for k in cs].count("face") == 6 and [k.kind for k in cs].count("edge") == 12
    for k in cs:
        Rk = rot(k.frame[3:])
        assert np.allclose(Rk.T @ Rk, np.eye(3), atol=1e-9) and np.isclose(np.linalg.det(Rk), 1)
        local = R.T @ (k.frame[:3] - c)                              # in the block's frame
        assert np.max(np.abs(local) / h) == pytest.approx(1.0)      # on the surface
        n = R.T @ Rk[:, 2]                                           # push direction, block frame
        on = np.isclose(np.abs(local), h, rtol=1e-9, atol=1e-12)
        assert np.allclose(n, np.where(on, np.sign(local), 0) / np.sqrt(on.sum()), atol=1e-9)
        if k.kind == "edge":
            assert np.isclose(k.length, 2 * h[~on][0])
            ends = [k.frame[:3] + s * k.length / 2 * Rk[:, 0] for s in (-1, 1)]
            assert all(np.max(np.abs(R.T @ (e - c)) / h) == pytest.approx(1.0) for e in ends)


@settings(max_examples=60, deadline=None)
@given(st.sampled_from(["name", "table", "features", "robot", "object", "description"]),
       st.sampled_from([None, 3, "", "x", [], [1.0], {"a": 1}, float("nan")]))
def test_constructing_a_workcell_with_bad_parts_names_the_part(part, value):
    w = Workcell.load(EXAMPLE)
    kw = {"name": w.name, "table": w.table, "features": w.features, "robot": w.robot, "object": w.object,
          "description": None} | {part: value}
    try:
        Workcell(**kw)
    except SceneError as e:
        assert e.field == part
        return
    assert (part, value) in (("description", None), ("description", ""), ("description", "x"), ("features", []),
                             ("name", "x"))


def test_default_workcell_needs_a_scene():
    with pytest.raises(ArgumentError) as e:
        default_workcell("t-shape")
    assert e.value.field == "scene"


def test_a_rolled_gripper_gets_inclines_that_serve_its_line_pushers_level():
    """block-tilted-gripper's gravity is 30° off the gripper's −z: its line pushers' segments are
    neither level nor plumb, so no block edge, ledge or rod serves them within MAX_TILT; the
    default workcell adds a bar per pusher, laid along the segment as the scene's gravity holds
    it. Independent check: scipy's rotation taking the scene's gravity to the world's −z turns
    the pusher's segment and normal onto the bar (up to a turn about the vertical), and every
    other bundled example gets none."""
    from scipy.spatial.transform import Rotation

    from regrasp.execution.assignment import MAX_TILT

    scene = regrasp.load_scene(regrasp.examples.path("block-tilted-gripper"))
    w = default_workcell(scene)
    inclines = [f for f in w.features if f.name.startswith("incline-")]
    assert sorted(f.name for f in inclines) == ["incline-bottom", "incline-left", "incline-right"]
    (gx, gz), _ = scene.gravity
    R, _ = Rotation.align_vectors([[0.0, 0.0, -1.0]], [[gx, 0.0, gz]])
    start = scene.task.start
    for f in inclines:
        name = f.name.removeprefix("incline-")
        pts, n = np.asarray(scene.pusher(name).points), np.asarray(scene.pusher(name).normal)
        seg = np.r_[pts[1, 0] - pts[0, 0], 0.0, pts[1, 1] - pts[0, 1]]
        seg, push = R.apply(seg / np.linalg.norm(seg)), R.apply([n[0], 0.0, n[1]])
        B = rot(f.pose[3:])
        # the same vertical components (a turn about the vertical keeps them) and angle between
        assert abs(B[2, 0]) == pytest.approx(abs(seg[2]), abs=1e-9) and B[2, 2] == pytest.approx(push[2], abs=1e-9)
        assert f.length >= np.linalg.norm(pts[1] - pts[0]) - 1e-12
        if np.hypot(push[0], push[1]) > 1e-6:
            assert B[0, 2] < 0 and B[1, 2] == pytest.approx(0.0, abs=1e-9)  # pushes towards the robot
        (a,) = assign(scene, [start, start], [None, name], w)
        assert a.feature == f.name and a.tilt <= 1e-6
    plan = regrasp.plan(scene, seed=0)
    motion = regrasp.execution.world_motion(scene, plan)  # within the default MAX_TILT now
    assert all(a.tilt <= MAX_TILT and a.feature.startswith("incline-") for a in motion.assignments)
    for name in regrasp.examples.names():
        if name != "block-tilted-gripper":
            cell = default_workcell(regrasp.load_scene(regrasp.examples.path(name)))
            assert not any(f.name.startswith("incline-") for f in cell.features), name


def test_toml_values_read_back_and_a_value_toml_has_no_text_for_is_refused():
    import math
    import tomllib

    import numpy as np

    from regrasp.workcell.file import toml_value

    values = {"s": 'a "quoted" \\ name', "b": True, "i": 3, "f": 0.1 + 0.2, "a": np.array([1.5, -2.0]),
              "t": {"mesh": "m.obj", "scale": [1e-3, 1e-3, 1e-3]}}
    text = "\n".join(f"{k} = {toml_value(v)}" for k, v in values.items())
    back = tomllib.loads(text)
    assert back["s"] == values["s"] and back["b"] is True and back["i"] == 3 and back["f"] == 0.1 + 0.2
    assert back["a"] == [1.5, -2.0] and back["t"] == {"mesh": "m.obj", "scale": [1e-3, 1e-3, 1e-3]}
    for bad in (math.nan, None, object()):
        with pytest.raises(ValueError):
            toml_value(bad)


@pytest.mark.parametrize("change, field", [
    (lambda d: d["object"].update(pose=[0.45, -0.2, -10.0, 1, 0, 0, 0]), "object.pose[2]"),  # 10 m under the table
    (lambda d: d["object"].update(pose=[0.45, -0.2, 20.0, 1, 0, 0, 0]), "object.pose[2]"),  # 19 m above it
    (lambda d: d["object"].update(pose=[5.0, -0.2, 0.8, 1, 0, 0, 0]), "object.pose[0]"),  # beside it
    (lambda d: d.update(features=[dict(d["features"][0], name=f"f{i}") for i in range(MAX_WORKCELL_FEATURES + 1)]),
     "features"),
])
def test_a_workcell_that_makes_no_physical_sense_is_refused(change, field):
    d = Workcell.load(bundled()).to_dict()
    change(d)
    with pytest.raises(SceneError) as e:
        Workcell.from_dict(d)
    assert e.value.field == field, e.value


def test_a_deeply_nested_workcell_is_refused_naming_the_file():
    deep = 'name = "w"\nx = ' + "[" * 20000 + "]" * 20000 + "\n"
    with pytest.raises(SceneError) as e:
        Workcell.from_toml(deep)
    assert e.value.field == "(toml)" and "nested" in str(e.value)


def test_default_features_have_the_friction_of_the_pushers_they_serve():
    """Each generated feature has its pushers' friction (not a floor of 0.5): the thesis'
    low-friction pushers meet low-friction features; a feature at the pusher's own friction is
    preferred to one with more."""
    low = regrasp.load_scene(regrasp.examples.path("block-low-friction"))
    w = default_workcell(low)
    assert w.table.friction == 0.25 and {f.friction for f in w.features} == {0.25}
    # block-3d: a line pusher at 0.25 and a patch at 0.5. Lines meet the ledge and rod at 0.25, the
    # block (serving both) has the larger, and the line pusher is assigned a 0.25 contact
    b3 = regrasp.load_scene(regrasp.examples.path("block-3d"))
    w = default_workcell(b3)
    mu = {f.name: f.friction for f in w.features}
    assert mu["ledge"] == mu["rod"] == 0.25 and mu["fixture"] == 0.5 and w.table.friction == 0.5
    start = b3.task[0]
    (a,) = assign(b3, [start, start], [None, "left"], w, max_tilt=np.pi)
    assert {c.name: c for c in w.contacts()}[a.feature].friction == 0.25
    # a scene with only point pushers: the table serves none and keeps TABLE_FRICTION
    from regrasp.execution.layout import TABLE_FRICTION, feature_friction
    assert feature_friction(low, ("point",), TABLE_FRICTION) == TABLE_FRICTION
