import os
import signal
from pathlib import Path

import numpy as np
import pytest
from hypothesis import settings
from hypothesis import strategies as st

import regrasp
from regrasp.extras import default_gl

# MuJoCo picks its OpenGL backend once, at its first import: choose it before any test module
# imports mujoco itself (else the rendering tests find GLFW without a display and skip)
default_gl()

# Property tests draw the same examples on every run (reproducible CI); a failure a random
# exploration finds (HYPOTHESIS_PROFILE=explore) becomes a regression test.
settings.register_profile("ci", derandomize=True)
settings.register_profile("explore", derandomize=False, max_examples=500)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))

# Ctrl-C as in a terminal: a runner may start the tests with SIGINT ignored (a shell's background
# job), which the signal tests' processes would inherit; a handled signal is reset to its default
# in a child, an ignored one is not.
if signal.getsignal(signal.SIGINT) == signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"


@pytest.fixture
def block():
    return regrasp.Scene.load(EXAMPLES / "block-low-friction.toml")


def block_dict(w=0.05, h=0.08, mass=0.13, force=20.0, mu_s=0.6, pad=0.007, mu_p=0.3, face=3, line=True,
               at=0.0, gdir=0.0, g=9.81, pose=(0.0, 0.0, 0.0), com=(0.0, 0.0)):
    """A block scene with one pusher on face 0..3 (bottom, right, top, left)."""
    hw, hh = w / 2, h / 2
    faces = [
        ([[-0.8 * hw, -hh], [0.8 * hw, -hh]], [0.0, 1.0]),
        ([[hw, -0.8 * hh], [hw, 0.8 * hh]], [-1.0, 0.0]),
        ([[0.8 * hw, hh], [-0.8 * hw, hh]], [0.0, -1.0]),
        ([[-hw, 0.8 * hh], [-hw, -0.8 * hh]], [1.0, 0.0]),
    ]
    pts, n = faces[face]
    if not line:
        t = 0.5 + at
        pts = [[pts[0][0] * (1 - t) + pts[1][0] * t, pts[0][1] * (1 - t) + pts[1][1] * t]]
    return {
        "name": "prop",
        "object": {"outline": [[-hw, -hh], [hw, -hh], [hw, hh], [-hw, hh]], "mass": mass,
                   "com": [com[0] * hw, com[1] * hh]},
        "grasp": {"force": force, "friction": mu_s, "pad_radius": pad},
        "gravity": {"direction": [float(np.sin(gdir)), float(-np.cos(gdir))], "g": g},
        "pushers": [{"name": "p", "friction": mu_p, "points": pts, "normal": n}],
        "task": {"start": list(pose), "goal": list(pose), "tolerance": [1e-3, 1e-3, 1e-2]},
    }


def pad_pose(cx, cz, th):
    """Pose putting the pad centre (gripper origin) at object point (cx, cz): t = -R c."""
    c, s = np.cos(th), np.sin(th)
    return (-(c * cx - s * cz), -(s * cx + c * cz), th)


@st.composite
def block_scenes(draw, line=None, g=None):
    w = draw(st.floats(0.03, 0.1))
    h = draw(st.floats(0.03, 0.1))
    pad = draw(st.floats(0.003, 0.008))
    px, pz = draw(st.floats(-0.3, 0.3)), draw(st.floats(-0.3, 0.3))
    th = draw(st.floats(-0.6, 0.6))
    d = block_dict(
        w=w, h=h, mass=draw(st.floats(0.05, 0.5)), force=draw(st.floats(5.0, 60.0)),
        mu_s=draw(st.floats(0.3, 1.0)), pad=pad, mu_p=draw(st.floats(0.05, 1.2)),
        face=draw(st.integers(0, 3)), line=draw(st.booleans()) if line is None else line,
        at=draw(st.floats(-0.45, 0.45)), gdir=draw(st.floats(-0.6, 0.6)),
        g=draw(st.floats(0.0, 12.0)) if g is None else g,
        pose=pad_pose(px * (w / 2 - pad), pz * (h / 2 - pad), th),
        com=(draw(st.floats(-0.3, 0.3)), draw(st.floats(-0.3, 0.3))),
    )
    return d


def twist_dirs(n, L, rng):
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    return d * np.array([1.0, 1.0, 1.0 / L])


def run_cli(*args) -> tuple:
    """`regrasp ARGS` in this process: (exit status, stdout, stderr); help and errors exit."""
    import contextlib
    import io

    from regrasp.cli import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            status = main([str(a) for a in args])
        except SystemExit as e:
            status = e.code
    return status, out.getvalue(), err.getvalue()


def rotation_matrix(q):
    """The test suite's own rotation matrix of a quaternion [w, x, y, z] (the textbook formula,
    independent of regrasp.pose), for checks of poses against 4 x 4 matrices."""
    import numpy as np

    w, x, y, z = np.asarray(q, float) / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def pose_matrix(pose):
    """The 4 x 4 matrix of a pose [x, y, z, qw, qx, qy, qz] (m, unit quaternion)."""
    import numpy as np

    m = np.eye(4)
    m[:3, :3], m[:3, 3] = rotation_matrix(pose[3:]), pose[:3]
    return m


_PLANS: dict = {}


def plan_of(name: str) -> tuple:
    """(scene, plan) of bundled example ``name``, planned once per test process (seed 0)."""
    import regrasp

    if name not in _PLANS:
        scene = regrasp.load_scene(regrasp.examples.path(name))
        _PLANS[name] = (scene, regrasp.plan(scene, seed=0))
    return _PLANS[name]


def pad_faces(robot) -> tuple:
    """(left, right): each pad's contact face along the TCP's grasp axis [m] from the TCP, one
    value a contact sphere (its point nearest the other pad), asserted flat to 1e-9 m."""
    m, d = robot.model, robot.data
    tcp = robot.tcp_pose()
    R = rotation_matrix(tcp[3:])
    faces = []
    for side in robot.pad_geoms:
        c = np.array([d.geom_xpos[g] for g in side])
        y = (c - tcp[:3]) @ R[:, 1]
        faces.append(y - np.sign(y.mean()) * m.geom_size[side[0], 0])
        assert np.ptp(faces[-1]) < 1e-9, "a flat face"
    return tuple(faces)
