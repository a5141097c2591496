"""The browser view of a workcell and of a world motion (regrasp.viz.viewer.workcell_html,
motion_html): self-contained pages whose data carry every feature's numbers and the motion's
samples unchanged, checked against the workcell file and the motion with the suite's own
rotation matrices and scipy's slerp; the page's script run in node (the pose shown between
samples, the feature highlighted while it pushes) and in headless Chromium (no console errors);
Jupyter's ``_repr_html_``; the atomic write."""

import html
import json
import re
import shutil
import subprocess

import numpy as np
import pytest
from scipy.spatial.transform import Rotation, Slerp

import regrasp
from regrasp import ArgumentError
from regrasp.execution import world_motion
from regrasp.viz import world_data
from regrasp.viz.viewer import motion_html, workcell_html, write_motion_html
from regrasp.workcell import Workcell

from .conftest import ROOT, pose_matrix, rotation_matrix
from .test_viewer import CHROMIUM, NODE, chromium

WORKCELL = regrasp.examples.ROOT / "workcells" / "workcell-ur5e.toml"
MOTIONS: dict = {}


def motion_of(name):
    if name not in MOTIONS:
        scene = regrasp.load_scene(regrasp.examples.path(name))
        MOTIONS[name] = (scene, world_motion(scene, regrasp.plan(scene, seed=0)))
    return MOTIONS[name]


def data_of(page: str) -> dict:
    """The JSON the page embeds."""
    m = re.search(r'<script id="data" type="application/json">(.*?)</script>', page, re.S)
    return json.loads(m.group(1).replace("<\\/", "</"))


def self_contained(page: str):
    assert not re.search(r"https?://", page) and "<link" not in page and "src=" not in page


def local(pose, pts):
    """Points (k, 3) [m] in the frame of ``pose``, by 4 x 4 matrices."""
    m = np.linalg.inv(pose_matrix(pose))
    return np.asarray(pts, float) @ m[:3, :3].T + m[:3, 3]


def outward(v, t):
    v, t = np.asarray(v, float), np.asarray(t, int)
    n = np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]])
    return bool(np.all(np.einsum("ij,ij->i", n, v[t].mean(axis=1) - v.mean(axis=0)) > 0))


def test_workcell_page_carries_every_feature_and_its_geometry():
    wc = Workcell.load(WORKCELL)
    page = workcell_html(wc)
    self_contained(page)
    d = data_of(page)
    assert [f["name"] for f in d["features"]] == [f.name for f in wc.features] == ["fixture", "ledge", "post", "wall"]
    for f, g in zip(wc.features, d["features"]):
        assert f.name in page.split("<script>")[0] or f'"name": "{f.name}"' in page
        assert g["kind"] == f.kind and np.allclose(g["pose"], f.pose)
        v = local(f.pose, g["vertices"])  # the body in the feature's own frame
        assert outward(g["vertices"], g["triangles"]), f.name
        if f.kind == "block":
            assert np.allclose(g["size"], f.size) and np.allclose(np.abs(v), np.asarray(f.size) / 2) and len(v) == 8
        elif f.kind == "face":  # a plate behind the rectangle, its front face the feature's rectangle
            assert np.allclose(g["size"], f.size)
            front = v[np.isclose(v[:, 2], 0)]
            assert np.allclose(np.sort(np.abs(front), axis=0), np.tile(np.r_[np.asarray(f.size) / 2, 0], (4, 1)))
            assert np.isclose(v[:, 2].min(), -world_data.PLATE_THICKNESS) and v[:, 2].max() < 1e-12
        elif f.kind == "edge":  # a wedge behind the segment, its front edge the segment
            assert g["length"] == f.length
            front = v[np.isclose(v[:, 2], 0)]
            assert np.allclose(sorted(front[:, 0]), [-f.length / 2, f.length / 2]) and np.allclose(front[:, 1], 0)
            assert np.isclose(v[:, 2].min(), -world_data.FEATURE_BODY)
        else:  # a pyramid whose tip is the corner
            assert np.isclose(v[:, 2], 0).sum() == 1 and np.allclose(v[np.isclose(v[:, 2], 0)], 0)
            assert np.isclose(v[:, 2].min(), -world_data.FEATURE_BODY)
    # the table: its top at the height, over the rectangle; legs to the floor
    t = d["table"]
    assert t["height"] == wc.table.height and t["size"] == list(wc.table.size) and t["center"] == list(wc.table.center)
    slab = np.asarray(t["parts"][0]["vertices"])
    assert np.isclose(slab[:, 2].max(), 0.75) and np.allclose(slab[:, :2].min(axis=0), [-0.1, -0.4])
    assert np.allclose(slab[:, :2].max(axis=0), [1.1, 0.4]) and len(t["parts"]) == 5
    assert min(np.asarray(p["vertices"])[:, 2].min() for p in t["parts"]) == pytest.approx(0)
    # the robot's base: a cylinder standing on its pose, its name shown
    r = d["robot"]
    assert r["name"] == "ur5e" and np.allclose(r["base"], wc.robot.base)
    c = local(wc.robot.base, r["vertices"])
    rim = c[np.hypot(c[:, 0], c[:, 1]) > 1e-9]
    assert np.allclose(np.hypot(rim[:, 0], rim[:, 1]), world_data.BASE_RADIUS) and c[:, 2].min() == pytest.approx(0)
    assert outward(r["vertices"], r["triangles"]) and d["axes"]["origin"] == [0, 0, 0]
    # with a scene: its object on the table where the workcell starts it
    s = regrasp.load_scene(regrasp.examples.path("t-shape"))
    d = data_of(workcell_html(wc, s))
    assert d["gripper"] is None and np.allclose(d["samples"]["object"][0], wc.object.pose)
    assert d["object"]["triangles"] and d["scene"] == "t-shape"


def test_workcell_in_hand_holds_the_object_at_its_start_above_the_table():
    s = regrasp.load_scene(regrasp.examples.path("pivot-3d"))
    wc = regrasp.execution.default_workcell(s)
    d = data_of(workcell_html(wc, s))
    G, O = d["samples"]["gripper"][0], d["samples"]["object"][0]
    start = np.asarray(s.task[0], float)
    assert np.allclose(pose_matrix(O), pose_matrix(G) @ pose_matrix(start))  # held at the scene's start
    w = np.asarray(d["object"]["vertices"]) @ rotation_matrix(O[3:]).T + O[:3]
    assert w[:, 2].min() > wc.top()  # above every feature
    assert [f["name"] for f in d["features"]] == [f.name for f in wc.features] == ["fixture", "ledge", "rod", "plate"]


@pytest.mark.parametrize("name", ["t-shape", "pivot-3d"])
def test_motion_page_data_round_trips(name):
    s, m = motion_of(name)
    page = motion_html(s, m)
    self_contained(page)
    d = data_of(page)
    S = d["samples"]
    assert np.array_equal(S["times"], m.times) and np.array_equal(S["gripper"], m.gripper)
    assert np.array_equal(S["object"], m.object) and S["labels"] == list(m.labels) and np.array_equal(S["push"], m.push)
    assert [(p["index"], p["pusher"], p["feature"], p["first"], p["last"]) for p in d["pushes"]] == \
        [(a.index, a.pusher, a.feature, a.first, a.last) for a in m.assignments]
    for p, a in zip(d["pushes"], m.assignments):
        assert np.array_equal(p["frame"], a.frame)
        if p["body"] == "table":
            assert p["feature"] == "table"
        else:  # the contact lies on its feature's body: a block's surface, else the feature's own origin
            f = m.workcell.feature(p["body"])
            o = local(f.pose, [p["frame"][:3]])[0]
            if f.kind == "block":
                assert np.max(np.abs(o) / (np.asarray(f.size) / 2)) == pytest.approx(1)
            else:
                assert np.allclose(o, 0, atol=1e-9)
    # the jaws close on the object: its extremes along the gripper's y over the motion's in-hand poses
    J = d["gripper"]
    v = np.asarray(d["object"]["vertices"])
    ys = np.array([v @ rotation_matrix(q[3:])[1] + q[1] for q in m.in_hand])
    assert J["top"] == pytest.approx(ys.max()) and J["bot"] == pytest.approx(ys.min()) and J["top"] > J["bot"]
    assert set(S["labels"]) >= {"transfer", "approach", "push", "retreat"}
    # the camera's framing holds the gripper's whole path and the workcell
    pts = np.vstack([m.gripper[:, :3]] + [f["vertices"] for f in d["features"]])
    assert np.all(np.abs(pts - d["center"]) <= d["extent"] + 1e-12)


@pytest.mark.skipif(NODE is None, reason="needs node to run the page's script")
@pytest.mark.parametrize("name", ["t-shape", "pivot-3d"])
def test_page_script_shows_the_motion_and_highlights_the_pushing_feature(name, tmp_path):
    s, m = motion_of(name)
    f = write_motion_html(tmp_path / "out" / "m.html", s, m)
    idx = np.unique(np.r_[0, np.linspace(1, len(m.times) - 1, 40).astype(int)])
    times = [float(m.times[i]) for i in idx] + [float((m.times[i - 1] + m.times[i]) / 2) for i in idx[1:]]
    out = json.loads(subprocess.run([NODE, str(ROOT / "tests" / "js" / "run_world_viewer.js"), str(f), json.dumps(times)],
                                    capture_output=True, text=True, check=True).stdout)["frames"]
    owner = world_data.contact_owners(m.workcell)
    seen = set()
    for fr, t in zip(out, times):
        assert fr["finite"] and fr["drawn"] > 20
        k = int(np.searchsorted(m.times, t))  # the sample reached next
        assert fr["label"] == m.labels[k] and fr["push"] == m.push[k]
        j = max(k - 1, 0)
        u = 1.0 if m.times[k] == m.times[j] else (t - m.times[j]) / (m.times[k] - m.times[j])
        for key, arr in (("gripper", m.gripper), ("object", m.object)):
            a, b = arr[j], arr[k]
            q = Slerp([0, 1], Rotation.from_quat([a[[4, 5, 6, 3]], b[[4, 5, 6, 3]]]))(u).as_quat()[[3, 0, 1, 2]]
            got = np.asarray(fr[key])
            assert np.allclose(got[:3], a[:3] + u * (b[:3] - a[:3]), atol=1e-12)
            assert min(np.abs(got[3:] - q).max(), np.abs(got[3:] + q).max()) < 1e-9
        if m.push[k] >= 0:
            body = owner[m.assignments[m.push[k]].feature]
            assert fr["highlighted"] == body and fr["pushing"] == (m.labels[k] == "push")
            assert f"push {m.push[k]}" in fr["info"] and m.assignments[m.push[k]].feature in fr["info"]
            seen.add((body, fr["pushing"]))
        else:
            assert fr["highlighted"] is None and not fr["pushing"]
    assert {b for b, on in seen if on} == {owner[a.feature] for a in m.assignments}  # every push's feature lit


@pytest.mark.skipif(CHROMIUM is None, reason="needs Chromium (Debian package chromium)")
def test_pages_load_in_headless_chromium_without_errors(tmp_path):
    s, m = motion_of("t-shape")
    wc = Workcell.load(WORKCELL)
    pages = {"motion": motion_html(s, m), "bare": motion_html(None, m), "workcell": workcell_html(wc),
             "workcell-scene": workcell_html(wc, s)}
    for name, text in pages.items():
        f = tmp_path / f"{name}.html"
        f.write_text(text)
        out, console = chromium(tmp_path, f"file://{f}#selftest", (900, 650), "--dump-dom")
        assert not console, (name, console)
        got = json.loads(html.unescape(re.search(r'<pre id="selftest">(.*?)</pre>', out, re.S).group(1)))
        W, H = got["css"]
        assert W == 900 and H > 400
        for fr in got["frames"]:  # the table at least; following the gripper, the gripper
            assert fr["ink"] > (0.002 if fr.get("follow") else 0.05) * W * H, name
        if name in ("motion", "bare"):
            assert np.allclose(got["frames"][4]["gripper"], m.gripper[-1]) and got["frames"][4]["t"] == pytest.approx(m.times[-1], rel=1e-14)
            assert np.allclose(got["frames"][0]["gripper"], m.gripper[0])


def test_repr_html_write_and_refusals(tmp_path):
    s, m = motion_of("t-shape")
    wc = Workcell.load(WORKCELL)
    for x, inner in ((wc, workcell_html(wc)), (m, motion_html(None, m))):
        h = x._repr_html_()
        assert h.startswith("<iframe srcdoc=") and html.unescape(re.search(r'srcdoc="(.*?)"', h, re.S).group(1)) == inner
    assert m.html(s) == motion_html(s, m) and wc.html(s) == workcell_html(wc, s)
    d = data_of(motion_html(None, m))
    assert d["object"] is None and d["gripper"] is None and np.array_equal(d["samples"]["gripper"], m.gripper)
    f = write_motion_html(tmp_path / "a" / "b.html", s, m)
    assert f.read_text() == motion_html(s, m) and sorted(p.name for p in f.parent.iterdir()) == ["b.html"]
    assert 50_000 < f.stat().st_size < 5_000_000
    with pytest.raises(ArgumentError) as e:
        motion_html(regrasp.load_scene(regrasp.examples.path("block-low-friction")), m)
    assert e.value.field == "scene"
    with pytest.raises(ArgumentError) as e:
        motion_html(s, "motion")
    assert e.value.field == "motion"
    with pytest.raises(ArgumentError) as e:
        workcell_html("bench")
    assert e.value.field == "workcell"


ARMS: dict = {}


def arm_of(name, robot="ur5e-parallel"):
    """The world motion the arm follows, its joint trajectory and the arm's drawing data."""
    pytest.importorskip("mink")
    from regrasp.execution.arm import arm_motion
    from regrasp.robot.shapes import arm_view

    if (name, robot) not in ARMS:
        scene = regrasp.load_scene(regrasp.examples.path(name))
        am = arm_motion(scene, regrasp.plan(scene, seed=0), robot=robot)
        ARMS[name, robot] = scene, am, arm_view(am.robot, am.trajectory.q)
    return ARMS[name, robot]


def test_the_drawn_arm_follows_the_joint_trajectory():
    """The drawn bodies' hulls are made of the bodies' own collision-geom points, and the page's
    body poses are MuJoCo's kinematics: the palm carries the TCP rigidly (a fixed offset at every
    kept sample) and ends where the world motion's gripper is."""
    from regrasp import pose as P
    from regrasp.robot.shapes import _geom_points, body_shapes

    scene, am, view = arm_of("t-shape")
    robot, mujoco = am.robot, pytest.importorskip("mujoco")
    shapes = body_shapes(robot)
    assert {"arm/shoulder_link", "arm/wrist_3_link", "gripper/base"} <= {s["name"] for s in shapes}
    for s in shapes:  # every hull vertex is a point of the body's geoms
        pts = np.vstack([_geom_points(robot.model, g, mujoco) for g in robot.robot_geoms
                         if robot.model.geom_bodyid[g] == s["body"]])
        v = np.asarray(s["vertices"])
        assert np.min(np.linalg.norm(v[:, None] - pts[None], axis=2), axis=1).max() < 1e-4, s["name"]
        assert outward(v, s["triangles"]), s["name"]
    k = [b["name"] for b in view["bodies"]].index("gripper/base")
    offsets = []
    for f, i in enumerate(view["samples"][::25]):
        palm = np.asarray(view["poses"][f * 25][k])
        offsets.append(P.compose(P.inverse(palm), am.robot.tcp_pose(am.trajectory.q[i])))
    assert np.ptp(np.asarray(offsets)[:, :3], axis=0).max() < 1e-4
    assert view["samples"][-1] == len(am.motion.times) - 1 and len(view["samples"]) <= 601
    page = data_of(motion_html(scene, am.motion, view))
    assert page["arm"]["poses"] == view["poses"] and page["arm"]["robot"] == "ur5e-parallel"
    with pytest.raises(ArgumentError) as e:
        motion_html(scene, am.motion, {**view, "samples": view["samples"][:-1]})
    assert e.value.field == "arm"


@pytest.mark.skipif(NODE is None, reason="needs node to run the page's script")
def test_page_script_puts_the_arm_where_its_samples_are(tmp_path):
    scene, am, view = arm_of("t-shape")
    f = write_motion_html(tmp_path / "m.html", scene, am.motion, view)
    kept = view["samples"][::40]
    times = [float(am.motion.times[i]) for i in kept]
    out = json.loads(subprocess.run([NODE, str(ROOT / "tests" / "js" / "run_world_viewer.js"), str(f), json.dumps(times)],
                                    capture_output=True, text=True, check=True).stdout)["frames"]
    for fr, i in zip(out, kept):
        k = int(np.searchsorted(am.motion.times, am.motion.times[i]))  # repeated times: the first
        want = np.asarray(view["poses"][view["samples"].index(i)]) if k == i else None
        got = np.asarray(fr["arm"])
        assert fr["finite"] and got.shape == (len(view["bodies"]), 7)
        if want is not None:
            assert np.allclose(got[:, :3], want[:, :3], atol=1e-9)


@pytest.mark.skipif(CHROMIUM is None, reason="needs Chromium (Debian package chromium)")
@pytest.mark.parametrize("name, robot", [("t-shape", "ur5e-parallel"), ("block-xztheta", "ur5e-2f85")])
def test_the_arm_gripper_and_object_are_inside_the_frame_in_chromium(name, robot, tmp_path):
    """The world view with the arm in headless Chromium: no console error, and at every frame the
    arm, the jaws and the object drawn inside the canvas; the screenshot holds the arm's colour."""
    scene, am, view = arm_of(name, robot)
    f = write_motion_html(tmp_path / "m.html", scene, am.motion, view)
    out, console = chromium(tmp_path, f"file://{f}#selftest", (1000, 700), "--dump-dom")
    assert not console, console
    got = json.loads(html.unescape(re.search(r'<pre id="selftest">(.*?)</pre>', out, re.S).group(1)))
    W, H = got["css"]
    for fr in got["frames"]:
        if fr.get("follow"):
            continue
        for kind in ("arm", "object", "jaw"):
            x0, y0, x1, y1 = fr["boxes"][kind]
            assert 0 <= x0 < x1 <= W and 0 <= y0 < y1 <= H, (kind, fr["t"], fr["boxes"][kind], (W, H))
    shot = tmp_path / "shot.png"
    chromium(tmp_path, f"file://{f}#t=0.5", (1000, 700), f"--screenshot={shot}")
    import matplotlib.image as mpimg

    px = (mpimg.imread(shot)[..., :3] * 255).astype(int)
    r, g, b = px[..., 0], px[..., 1], px[..., 2]
    arm = (b - r > 40) & (b - g > 25) & (b < 190)  # the arm's slate blue, shaded
    assert arm.mean() > 0.01, arm.mean()


@pytest.mark.skipif(CHROMIUM is None, reason="needs Chromium (Debian package chromium)")
def test_a_link_to_a_moment_means_the_same_in_both_views(tmp_path):
    """``#t=0.5`` is half-way in the world view as in the plan view; ``#t=50%`` too; the world
    view also takes seconds (``#t=12.5s``)."""
    from regrasp.viz.viewer import write_html

    s, m = motion_of("t-shape")
    f = write_motion_html(tmp_path / "m.html", s, m)
    T = float(m.times[-1])
    info = {}
    for h in ("0.5", "50%", f"{T / 2:.4f}s", "0"):
        out, console = chromium(tmp_path, f"file://{f}#t={h}", (900, 650), "--dump-dom")
        info[h] = re.search(r'<span id="info">(.*?)</span>', out, re.S).group(1)
    assert info["0.5"] == info["50%"] == info[f"{T / 2:.4f}s"] != info["0"]
    assert f"t = {T / 2:.2f} s" in info["0.5"]
    p = write_html(s, regrasp.plan(s, seed=0), tmp_path / "p.html")
    plan_info = {h: re.search(r'<span id="info">(.*?)</span>', chromium(tmp_path, f"file://{p}#t={h}", (900, 650),
                                                                        "--dump-dom")[0], re.S).group(1)
                 for h in ("0.5", "50%", "0")}
    assert plan_info["0.5"] == plan_info["50%"] != plan_info["0"]
