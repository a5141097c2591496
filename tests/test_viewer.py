"""The browser view (regrasp.viz.viewer): what the page describes (ground, jaws, axes, gravity,
pushers) against the scene's numbers, planar and 3-D; the page run in node and in headless
Chromium at two window sizes (no console errors, the canvas follows the window, the ground and
the jaws are on the screenshot); Jupyter's ``_repr_html_``."""

import html
import json
import re
import shutil
import subprocess

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import regrasp
from regrasp import Plan, Scene, Scene3D
from regrasp.polygon import triangulate
from regrasp.pose import planar_to_spatial
from regrasp.viz.view_data import FEATURE_DEPTH, _world, extrude
from regrasp.viz.viewer import description, page, write_html

from .conftest import EXAMPLES, ROOT

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
NODE = shutil.which("node")


@pytest.fixture(scope="module")
def pivot():
    s = Scene3D.load(EXAMPLES / "pivot-3d.toml")
    return s, s.plan(seed=0)


@pytest.fixture(scope="module")
def tshape():
    s = Scene.load(EXAMPLES / "t-shape.toml")
    return s, regrasp.plan(s, seed=0)


def check_features(d, pushers, depth):
    """Each pusher's body has its contact face at the pusher's points and lies behind it."""
    assert [f["name"] for f in d["features"]] == [n for n, _, _ in pushers]
    for f, (name, pts, normal) in zip(d["features"], pushers):
        n = np.asarray(normal, float) / np.linalg.norm(normal)
        v, p = np.asarray(f["vertices"], float), np.asarray(pts, float)
        assert np.allclose(f["points"], p) and np.allclose(f["normal"], n)
        level = p @ n
        assert np.allclose(level, level[0])  # the points of one contact are on one face
        assert np.isclose((v @ n).max(), level[0]) and np.isclose((v @ n).min(), level[0] - depth)
        face = v[np.isclose(v @ n, level[0])]
        lo, hi = face.min(axis=0) - 1e-12, face.max(axis=0) + 1e-12
        assert np.all((p >= lo) & (p <= hi)), name  # the contact face covers the points
        t = np.asarray(f["triangles"])
        normals = np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]])
        assert np.all(np.einsum("ij,ij->i", normals, v[t].mean(axis=1) - v.mean(axis=0)) > 0), name  # outward


def check_ground(d, gravity):
    """The ground is perpendicular to gravity, under the object at every pose, touching it once."""
    up = -np.asarray(gravity, float) / np.linalg.norm(gravity)
    G = d["ground"]
    assert np.allclose(G["normal"], up)
    heights = _world(d["poses"], np.asarray(d["vertices"], float)) @ up - np.dot(G["point"], up)
    assert heights.min() == pytest.approx(0, abs=1e-12) and np.all(heights > -1e-12)


def test_3d_page_describes_ground_jaws_axes_gravity_and_pushers(pivot):
    s, p = pivot
    d = description(s, p)
    assert np.allclose(d["poses"], p.poses) and d["pushers_of_steps"] == p.pushers
    # the jaws close on the box's 12 mm thickness (its extent along the gripper's y)
    assert d["jaws"]["width"] == pytest.approx(0.012) and d["jaws"]["pad"] == pytest.approx(0.007)
    assert d["gravity"]["direction"] == pytest.approx([0, 0, -1]) and d["gravity"]["g"] == pytest.approx(9.81)
    check_ground(d, [0, 0, -1])
    assert d["axes"]["origin"] == [0, 0, 0] and d["axes"]["length"] > 0
    core = s._core
    pushers = [(n, core.pusher_points(n), core.pusher_normal(n)) for n in s.pusher_names]
    check_features(d, pushers, FEATURE_DEPTH * d["size"])
    assert [f["kind"] for f in d["features"]] == ["face", "face"]
    # the palm is above the object (and its pushers) at every pose
    top = _world(d["poses"], np.concatenate([d["vertices"]] + [f["vertices"] for f in d["features"]]))[..., 2].max()
    assert d["jaws"]["palm_z"] > top
    assert np.allclose(d["goal"], s.task[1])
    # a ball on the floor: the floor plane is the ground (the support), under the ball
    b = Scene3D.load(EXAMPLES / "ball-roll-3d.toml")
    d = description(b, b.plan(seed=0))
    assert d["ground"]["support"] == "floor" and d["planes"] == {"floor": [0, 0, 1]}
    check_ground(d, [0, 0, -1])
    assert d["jaws"]["width"] == pytest.approx(0.07)


def test_planar_page_extrudes_the_outline_and_keeps_the_scenes_numbers(tshape):
    s, p = tshape
    d = description(s, p)
    v = np.asarray(d["vertices"], float)
    width = v[:, 1].max() - v[:, 1].min()
    assert d["dimension"] == 2 and d["jaws"]["width"] == pytest.approx(width) and width > 2 * 0.006
    assert np.allclose(v[:, [0, 2]], np.tile(s.outline, (2, 1)))
    # the planar pose [x, z, theta] moves the outline as in the plane
    q = np.array([0.01, -0.02, 0.7])
    R = np.array([[np.cos(q[2]), -np.sin(q[2])], [np.sin(q[2]), np.cos(q[2])]])
    w = _world([planar_to_spatial(q)], v)[0]
    assert np.allclose(w[:, [0, 2]], v[:, [0, 2]] @ R.T + q[:2]) and np.allclose(w[:, 1], v[:, 1])
    assert np.allclose(d["poses"], [planar_to_spatial(x) for x in p.poses])
    g, _ = s.gravity
    assert d["gravity"]["direction"] == pytest.approx([g[0], 0, g[1]])
    check_ground(d, [g[0], 0, g[1]])
    h = width / 2
    pushers = [(x.name, [[a, y, c] for a, c in x.points for y in (-h, h)], [x.normal[0], 0, x.normal[1]]) for x in s.pushers]
    check_features(d, pushers, FEATURE_DEPTH * d["size"])
    # a tilted gripper: gravity as the scene states it; the ground perpendicular to it
    t = Scene.load(EXAMPLES / "block-tilted-gripper.toml")
    d = description(t)
    g, _ = t.gravity
    assert abs(g[0]) > 0.1 and d["gravity"]["direction"] == pytest.approx([g[0], 0, g[1]])
    check_ground(d, [g[0], 0, g[1]])
    # the scene alone: its start, its goal; an object on a surface: no jaws, the support as ground
    d = description(s)
    assert np.allclose(d["poses"], [planar_to_spatial(s.task.start)])
    assert np.allclose(d["goal"], planar_to_spatial(s.task.goal))
    d = description(Scene.load(EXAMPLES / "block-on-incline.toml"))
    assert d["jaws"] is None and d["ground"]["support"] == "surface" and d["goal"] is None
    kinds = {f["name"]: f["kind"] for f in d["features"]}
    assert kinds == {"finger": "edge", "paddle": "face"}


def test_extrusion_of_a_non_convex_outline_is_closed_and_outward():
    outline = np.array(Scene.load(EXAMPLES / "t-shape.toml").outline)
    v, t = extrude(outline, 0.01)
    t = np.asarray(t)
    edges = {}
    for a, b, c in t:
        for e in ((a, b), (b, c), (c, a)):
            edges[e] = edges.get(e, 0) + 1
    assert all(edges.get((b, a)) == 1 for (a, b) in edges)  # closed, consistently oriented
    n = np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]])
    volume = np.einsum("ij,ij->i", v[t[:, 0]], n).sum() / 6
    area = 0.5 * abs(np.sum(outline[:, 0] * np.roll(outline[:, 1], -1) - np.roll(outline[:, 0], -1) * outline[:, 1]))
    assert volume == pytest.approx(area * 0.01)  # positive: the normals point out


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(0.2, 1.0), min_size=3, max_size=12), st.floats(0, 6.28))
def test_ear_clipping_tiles_star_shaped_polygons(radii, turn):
    a = turn + 2 * np.pi * np.arange(len(radii)) / len(radii)
    p = np.stack([np.cos(a), np.sin(a)], axis=1) * np.asarray(radii)[:, None]
    t = np.asarray(triangulate(p))
    assert len(t) == len(p) - 2
    e1, e2 = p[t[:, 1]] - p[t[:, 0]], p[t[:, 2]] - p[t[:, 0]]
    areas = (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]) / 2
    polygon = 0.5 * np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1])
    assert np.all(areas >= -1e-12) and areas.sum() == pytest.approx(polygon)  # counter-clockwise, no overlap


def test_pages_are_small_and_refuse_a_wrong_scene(pivot, tshape, tmp_path):
    for s, p in (pivot, tshape):
        assert 10_000 < len(page(s, p).encode()) < 1_000_000 and "http" not in page(s, p).split("<script>")[1]
    b = Scene3D.load(EXAMPLES / "ball-roll-3d.toml")
    assert len(page(b, None).encode()) < 1_000_000
    with pytest.raises(regrasp.ArgumentError):
        page(tshape[0], pivot[1])  # a 3-D plan for a planar scene
    with pytest.raises(regrasp.ArgumentError):
        page("t-shape", None)


@pytest.mark.skipif(NODE is None, reason="needs node to run the page's script")
def test_planar_page_draws_every_frame_in_node(tshape, tmp_path):
    s, p = tshape
    f = write_html(s, p, tmp_path / "t.html")
    out = json.loads(subprocess.run([NODE, str(ROOT / "tests" / "js" / "run_viewer.js"), str(f)],
                                    capture_output=True, text=True, check=True).stdout)
    width = description(s, p)["jaws"]["width"]
    for fr in out["frames"]:
        assert fr["finite"] and fr["drawn"] >= 4 + 2 and fr["pusher_dots"] == 2  # line pushers: 2 contacts
        assert fr["drawn_all"] > fr["drawn"] + 10  # ground, jaws, pushers, goal
        assert fr["jaw_gap"] == pytest.approx(width)
    assert "pusher top" in out["frames"][0]["info"]
    assert np.allclose(out["frames"][-1]["pose"], planar_to_spatial(p.poses[-1]), atol=1e-9)


FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--enable-logging=stderr", "--v=0"]


def chromium(tmp_path, url, size, *extra):
    """Runs headless Chromium on ``url`` at window ``size``: (stdout, console messages)."""
    prof = tmp_path / f"profile-{len(list(tmp_path.glob('profile-*')))}"
    r = subprocess.run([CHROMIUM, *FLAGS, f"--user-data-dir={prof}", f"--window-size={size[0]},{size[1]}", *extra, url],
                       capture_output=True, text=True, timeout=120)
    return r.stdout, [x for x in r.stderr.splitlines() if ":CONSOLE" in x]


def selftest(tmp_path, f, size):
    out, console = chromium(tmp_path, f"file://{f}#selftest", size, "--dump-dom")
    m = re.search(r'<pre id="selftest">(.*?)</pre>', out, re.S)
    assert m and not console, console
    return json.loads(html.unescape(m.group(1)))


def is_ground(px):  # the ground's beige (r > g > b), not the white background
    r, g, b = px[:3]
    return r > g > b and r - b > 15


def is_jaw(px):  # the jaws' grey over white
    r, g, b = px[:3]
    return max(r, g, b) < 205 and max(r, g, b) - min(r, g, b) < 25


@pytest.mark.skipif(CHROMIUM is None or NODE is None, reason="needs Chromium (Debian package chromium) and node")
@pytest.mark.parametrize("which", ["planar", "3d"])
def test_pages_render_in_headless_chromium_at_two_sizes(which, pivot, tshape, tmp_path):
    from PIL import Image

    s, p = tshape if which == "planar" else pivot
    f = write_html(s, p, tmp_path / "view.html")
    seen = []
    for size in ((940, 700), (640, 820)):
        out = selftest(tmp_path, f, size)
        W, H = out["css"]
        # the canvas fills the page's width and its height under the bar, at the pixel density
        assert W == out["viewport"][0] == size[0] and out["offset"][1] + H == out["viewport"][1] and H > 0.6 * size[1] - 150
        assert out["pixels"] == [round(W * out["dpr"]), round(H * out["dpr"])]
        for fr in out["frames"]:
            assert fr["drawn"] >= 6 and 0.01 * W * H < fr["ink"] < fr["ink_all"]
        assert np.allclose(out["frames"][-1]["pose"], description(s, p)["poses"][-1], atol=1e-9)
        # the page's own reading of its canvas where the ground and the jaws project
        assert any(is_ground(px) for px in out["probe_pixels"]["ground"]), out["probe_pixels"]
        assert all(is_jaw(px) for px in out["probe_pixels"]["jaws"]), out["probe_pixels"]
        # the screenshot (its page is the window's size: the canvas grows to the window's height
        # under the bar): the ground and the jaws where the page's script, run in node on a
        # canvas of that size, draws them
        shot = tmp_path / f"view-{size[0]}.png"
        chromium(tmp_path, f"file://{f}", size, f"--screenshot={shot}")
        img = np.asarray(Image.open(shot).convert("RGB"))
        assert img.shape[:2] == (size[1], size[0])
        top = out["offset"][1]
        probes = json.loads(subprocess.run([NODE, str(ROOT / "tests" / "js" / "run_viewer.js"), str(f), str(size[0]),
                                            str(size[1] - top)], capture_output=True, text=True, check=True).stdout)["probes"]

        def at(x, y):
            return img[int(round(top + y)), int(round(x))]

        assert any(is_ground(at(x, y)) for x, y, _ in probes["ground"]), [at(x, y) for x, y, _ in probes["ground"]]
        assert all(is_jaw(at(x, y)) for x, y, _ in probes["jaws"]), [at(x, y) for x, y, _ in probes["jaws"]]
        assert not is_ground(at(*probes["jaws"][0][:2])) and not is_jaw(at(*probes["ground"][0][:2]))
        seen.append((W, H))
    assert seen[0] != seen[1]  # the canvas followed the window


@pytest.mark.skipif(CHROMIUM is None, reason="needs Chromium (Debian package chromium; .ci/run installs it)")
def test_scene_alone_renders_without_errors(tmp_path):
    for s in (Scene.load(EXAMPLES / "block-on-incline.toml"), Scene3D.load(EXAMPLES / "ball-roll-3d.toml")):
        f = write_html(s, None, tmp_path / f"{s.name}.html")
        out = selftest(tmp_path, f, (800, 600))
        assert out["frames"][0]["ink"] > 0.01 * out["css"][0] * out["css"][1] and "the start" in out["frames"][0]["info"]


def test_repr_html_of_scenes_and_plans(pivot, tshape, tmp_path):
    for s, p in (tshape, pivot):
        for x in (s, p):
            h = x._repr_html_()
            assert h.startswith("<iframe srcdoc=") and "height:480px" in h
            inner = html.unescape(re.search(r'srcdoc="(.*?)"', h, re.S).group(1))
            assert inner == page(s, p if x is p else None)
        # the scene is remembered outside the plan's state: its file is unchanged, a copy read
        # back from its file shows its summary
        saved = p.save(tmp_path / f"{s.name}.json") if hasattr(p, "save") else None
        q = Plan.from_json(json.loads(saved.read_text()) if saved else p.to_json())
        assert q.to_json() == p.to_json()
        h = q._repr_html_()
        assert h.startswith("<table>") and "found" in h and f"<td>{len(p.poses) - 1}</td>" in h
        assert "switch-overs" in h and "stop reason" in h
