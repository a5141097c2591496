"""The boundary of `regrasp._core`: every call with one argument replaced by a bad value either
succeeds or raises an exception of the closed set in `regrasp.errors` (never a bare TypeError,
ValueError, OverflowError or IndexError, and never a Rust panic), and the defaults Python reads
come from Rust.

Run with the extension built into the environment: `pytest crates/regrasp-py/tests`.
"""

from pathlib import Path

import numpy as np
import pytest

from regrasp import _core
from regrasp.errors import ArgumentError, InternalError, RegraspError

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
BAD = [-1, 2**70, 1.5, float("nan"), "x", None, [], [1.0, 2.0], [[1.0, 2.0, 3.0]], np.zeros((2, 2)), {}, object(), True,
       1e300, -1e300, float("inf"), 0, 0.0, -0.0, 1e-300, [1e300, 0.0, 0.0], [0.0, 0.0, float("inf")],
       [1e300, 0.0, 0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1e300, 0.0, 0.0, 0.0], np.full((2, 3), 1e300), ""]
# a bad value for every setting of the planner and of the MPC
BAD_SETTINGS = [-1, -1e300, 1e300, float("inf"), float("-inf"), float("nan"), 2**70, "x", None, [1], 1.5, True]

Q = [0.0, 0.0, 0.0]
Q3 = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]
POSES = np.zeros((2, 3))
TWISTS = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])


@pytest.fixture(scope="module")
def scene():
    return _core.Scene.from_toml((EXAMPLES / "block-low-friction.toml").read_text())


@pytest.fixture(scope="module")
def scene3():
    return _core.Scene3D.from_toml((EXAMPLES / "block-3d.toml").read_text(), str(EXAMPLES))


def calls(scene, scene3):
    """(label, callable, valid arguments) of every `_core` entry point Python uses."""
    cone = scene.motion_cone(Q, "left", True)
    prob = scene.quasistatic_problem(Q, "left", "points", 0, 4, False, 1.0, 0.01)
    tw = prob.solve_forward([0.01, 0.0, 0.0])
    s3 = scene3.task[0]
    path = ([Q, [0.001, 0.0, 0.0]], [None, "left"])
    mpc = _core.Mpc(scene, *path)
    quick = {"time_limit": 0.05, "max_nodes": 30}
    return [
        ("Scene.from_toml", _core.Scene.from_toml, [(EXAMPLES / "block-low-friction.toml").read_text()]),
        ("pusher", scene.pusher, ["left"]),
        ("admissible", scene.admissible, [Q]),
        ("admissible_many", scene.admissible_many, [POSES]),
        ("hold_ratio", scene.hold_ratio, [Q]),
        ("with_grip_force", scene.with_grip_force, [20.0]),
        ("motion_cone", scene.motion_cone, [Q, "left", True]),
        ("generators_many", scene.generators_many, [POSES, "left", False]),
        ("classify_many", scene.classify_many, [POSES, TWISTS, "left"]),
        ("project_many", scene.project_many, [POSES, TWISTS, "left"]),
        ("quasistatic_problem", scene.quasistatic_problem, [Q, "left", "points", 0, 4, False, 1.0, 0.01]),
        ("push_outcomes", scene.push_outcomes, [POSES, "left", TWISTS * 0.01, "limit_surface", 1, 0, True]),
        ("simulate_push", scene.simulate_push, [Q, "left", [0.01, 0.0, 0.0], 0.05, 0.05, "points", 0, 4, True]),
        ("plan", scene.plan, [None, None, quick]),
        ("validate_path", scene.validate_path, [*path, 4]),
        ("scaled", scene.scaled, [1.0, 1.0, 1.0, 1.0, "robust"]),
        ("carries_weight", scene.carries_weight, [Q, "left"]),
        ("cone.ray", cone.ray, [[1.0, 0.0, 0.0]]),
        ("cone.classify", cone.classify, [[1.0, 0.0, 0.0]]),
        ("cone.margin", cone.margin, [TWISTS]),
        ("cone.contains", cone.contains, [[1.0, 0.0, 0.0]]),
        ("cone.contains_polyhedral", cone.contains_polyhedral, [TWISTS]),
        ("cone.gravity_free_margin", cone.gravity_free_margin, [[1.0, 0.0, 0.0]]),
        ("cone.project", cone.project, [TWISTS]),
        ("cone.project_polyhedral", cone.project_polyhedral, [[1.0, 0.0, 0.0], "gravity_free"]),
        ("cone.grip_force_range", cone.grip_force_range, [[1.0, 0.0, 0.0]]),
        ("cone.point_pusher_twist", cone.point_pusher_twist, [[0.01, 0.0]]),
        ("problem.solve_forward", prob.solve_forward, [[0.01, 0.0, 0.0]]),
        ("problem.solve_inverse", prob.solve_inverse, [[0.01, 0.0, 0.0]]),
        ("problem.residuals", prob.residuals, [list(tw["twist"]), list(tw["pusher_twist"]), list(tw["normal_forces"]),
                                               [list(f) for f in tw["friction_forces"]]]),
        ("Scene3D.from_toml", _core.Scene3D.from_toml, [(EXAMPLES / "block-3d.toml").read_text(), str(EXAMPLES)]),
        ("pusher_spec", scene3.pusher_spec, ["left", s3]),
        ("pusher_normal", scene3.pusher_normal, ["left"]),
        ("is_plane", scene3.is_plane, ["ground"]),
        ("pad_contacts", scene3.pad_contacts, [s3]),
        ("quasistatic_problem3", scene3.quasistatic_problem, [s3, "left", 1.0]),
        ("simulate_push3", scene3.simulate_push, [s3, "left", [0.01, 0, 0, 0, 0, 0], 0.02, 0.02]),
        ("validate_path3", scene3.validate_path, [[s3, s3], [None, "left"], [[0.0] * 6, [0.001, 0, 0, 0, 0, 0]]]),
        ("Mpc", _core.Mpc, [scene, *path, None, 0.1, 5, 0.01]),
        ("mpc.step", mpc.step, [Q]),
        ("mpc.solve_qp", mpc.solve_qp, [Q, 0]),
        ("planner_defaults", _core.planner_defaults, [2]),
        ("se3_log", _core.se3_log, [Q3, Q3]),
        ("se3_integrate", _core.se3_integrate, [Q3, [0.0] * 6, 1.0]),
        ("se3_compose", _core.se3_compose, [Q3, Q3]),
        ("se3_inverse", _core.se3_inverse, [Q3]),
    ]


def test_valid_calls_pass(scene, scene3):
    for label, f, args in calls(scene, scene3):
        try:
            f(*args)
        except RegraspError as e:  # a valid call may still be refused by the mechanics
            assert label in ("cone.point_pusher_twist", "problem.solve_inverse"), (label, e)


def test_every_bad_argument_is_a_regrasp_error(scene, scene3):
    escaped = []
    for label, f, args in calls(scene, scene3):
        for i in range(len(args)):
            for bad in BAD:
                a = list(args)
                a[i] = bad
                try:
                    f(*a)
                except RegraspError:
                    pass
                except BaseException as e:  # noqa: B036 — a panic is a BaseException
                    escaped.append(f"{label}(arg {i} = {bad!r}): {type(e).__name__}: {e}")
    assert not escaped, "\n".join(escaped)


def _finite(x) -> bool:
    """Whether every number in `x` (nested lists, tuples, dicts, arrays) is finite."""
    if isinstance(x, dict):
        return all(_finite(v) for v in x.values())
    if isinstance(x, (list, tuple)):
        return all(_finite(v) for v in x)
    if isinstance(x, np.ndarray) and x.dtype.kind == "f":
        return bool(np.isfinite(x).all())
    if isinstance(x, float):
        return np.isfinite(x)
    return True


def test_no_output_is_nan_or_infinite(scene, scene3):
    """Whatever a call returns, with valid or bad arguments, holds no NaN or infinity."""
    bad = []
    for label, f, args in calls(scene, scene3):
        for i in range(-1, len(args)):
            for v in BAD if i >= 0 else [None]:
                a = list(args)
                if i >= 0:
                    a[i] = v
                try:
                    r = f(*a)
                except RegraspError:
                    continue
                if label == "cone.grip_force_range" and r is not None:
                    r = r[0] if r[1] == float("inf") else r  # documented: max = inf when no force is too high
                if label == "planner_defaults":
                    r = {k: x for k, x in r.items() if k != "cost_threshold"}  # may be inf (the first path)
                if not _finite(r if not hasattr(r, "generators") else r.generators):
                    bad.append(f"{label}(arg {i} = {v!r}) returned {r!r}"[:300])
    assert not bad, "\n".join(bad)


@pytest.mark.parametrize("dimension", [2, 3])
def test_every_bad_setting_is_an_argument_error_naming_it(scene, scene3, dimension):
    plan = scene.plan if dimension == 2 else scene3.plan
    escaped = []
    for key in _core.planner_defaults(dimension):
        for bad in BAD_SETTINGS:
            try:
                plan(None, None, {"time_limit": 0.05, "max_nodes": 30, key: bad})
            except ArgumentError as e:
                if e.field != key:
                    escaped.append(f"{key} = {bad!r}: field {e.field!r}: {e}")
            except RegraspError:
                pass
            except BaseException as e:  # noqa: B036
                escaped.append(f"{key} = {bad!r}: {type(e).__name__}: {e}")
    assert not escaped, "\n".join(escaped)


def test_every_bad_mpc_setting_is_an_argument_error(scene):
    path = ([Q, [0.001, 0.0, 0.0]], [None, "left"])
    escaped = []
    for key in _core.mpc_defaults():
        for bad in BAD_SETTINGS:
            try:
                _core.Mpc(scene, *path, **{key: bad}).step(Q)
            except RegraspError:
                pass
            except BaseException as e:  # noqa: B036
                escaped.append(f"{key} = {bad!r}: {type(e).__name__}: {e}")
    assert not escaped, "\n".join(escaped)


def test_magnitudes_are_bounded(scene, scene3):
    """Physically absurd magnitudes are errors naming the argument, not NaN, inf or a long run."""
    s3 = scene3.task[0]
    cases = [
        (lambda: scene.with_grip_force(1e200), "force"),
        (lambda: scene.with_grip_force(1e300), "force"),
        (lambda: scene.scaled(1.0, 1e300, 1.0, 1.0, None), "grip"),
        (lambda: scene.simulate_push(Q, "left", [1e6, 0.0, 0.0], 0.05, 0.05), "twist"),
        (lambda: scene.simulate_push(Q, "left", [0.01, 0.0, 0.0], 0.0, 0.05), "duration"),
        (lambda: scene.simulate_push(Q, "left", [0.01, 0.0, 0.0], 0.05, 0.0), "dt"),
        (lambda: scene.simulate_push(Q, "left", [0.01, 0.0, 0.0], 0.05, 0.1), "dt"),
        (lambda: scene.simulate_push(Q, "left", [0.01, 0.0, 0.0], 1e9, 1e-3), "dt"),
        (lambda: scene.simulate_push(Q, "left", [0.01, 0.0, 0.0], float("inf"), 0.05), "duration"),
        (lambda: scene3.simulate_push(s3, "left", [1e300, 0, 0, 0, 0, 0], 0.02, 0.02), "twist"),
        (lambda: scene3.simulate_push(s3, "left", [0.01, 0, 0, 0, 0, 0], 0.0, 0.02), "duration"),
        (lambda: scene3.simulate_push(s3, "left", [0.01, 0, 0, 0, 0, 0], 0.02, 0.0), "dt"),
        (lambda: scene.quasistatic_problem(Q, "left", "points", 10**6, 4), "rings"),
        (lambda: scene.quasistatic_problem(Q, "left", "points", 2, 10**9), "points"),
        (lambda: scene.validate_path([Q, Q], [None, "left"], 10**12), "checks"),
    ]
    for f, field in cases:
        with pytest.raises(ArgumentError) as e:
            f()
        assert e.value.field == field, (field, str(e.value))
    # an instantaneous push of a huge twist is reported per entry, at once
    sticks, twists, residuals, errors = scene.push_outcomes(POSES, "left", TWISTS * 1e300, "limit_surface", 1, 0, True)
    assert all(e is not None and "twist" in e for e in errors)
    assert np.isfinite(twists).all() and np.isfinite(residuals).all()


def test_internal_error_is_in_the_closed_set():
    assert issubclass(InternalError, RegraspError) and issubclass(InternalError, RuntimeError)
    assert "report" in InternalError.__doc__


def test_errors_name_the_argument(scene):
    cases = [
        (lambda: scene.plan(None, None, {"max_nodes": -1}), "max_nodes"),
        (lambda: scene.plan(None, None, []), "settings"),
        (lambda: scene.motion_cone([0.0, 0.0], "left", True), "pose"),
        (lambda: scene.admissible(["a", 0, 0]), "pose"),
        (lambda: scene.validate_path([Q, Q], [None, "left"], -3), "checks"),
        (lambda: scene.quasistatic_problem(Q, "left", "points", -1), "rings"),
        (lambda: _core.Mpc(scene, [Q, Q], [None, "left"], horizon=-5), "horizon"),
        (lambda: _core.Mpc(scene, [Q, Q], [None, "left"], speed="fast"), "speed"),
        (lambda: _core.Mpc(scene, [Q, Q], [None, "left"], nonsense=1), "nonsense"),
        (lambda: _core.Mpc(scene, [Q, [0.0, 0.0]], [None, "left"]), "plan.path[1].pose"),
        (lambda: _core.se3_integrate(Q3, [0.0] * 6, float("inf")), "t"),
        (lambda: _core.planner_defaults(-2), "dimension"),
    ]
    for f, field in cases:
        with pytest.raises(ArgumentError) as e:
            f()
        assert e.value.field == field, (field, str(e.value))


def test_defaults_come_from_rust(scene):
    mpc = _core.mpc_defaults()
    assert {"dt", "horizon", "speed", "stage_weight", "terminal_weight", "effort_weight", "margin", "stall_steps",
            "max_replans", "replan_time_limit", "seed", "progress", "replan_error", "goal_fraction"} <= set(mpc)
    path = ([Q, [0.001, 0.0, 0.0]], [None, "left"])
    # every default is accepted back, by keyword
    _core.Mpc(scene, *path, **mpc)
    qs = _core.quasistatic_defaults()
    assert qs["support"] in ("points", "limit_surface")
    p = scene.quasistatic_problem(Q, "left", **qs)
    q = scene.quasistatic_problem(Q, "left")
    assert p.data()["h"] == q.data()["h"] == qs["h"]
    assert len(p.labels) == len(q.labels)


def test_the_controller_may_be_used_from_any_thread_one_at_a_time(scene):
    """`_core.Mpc` holds its state behind a lock: another thread may use it (no panic about an
    unsendable object), and a call while another thread's runs is an ArgumentError, not a wait."""
    import threading

    m = _core.Mpc(scene, [Q, [0.001, 0.0, 0.0]], [None, "left"])
    outcomes = []

    def steps():
        for _ in range(5):
            try:
                outcomes.append(m.step(Q)["status"])
            except ArgumentError as e:
                outcomes.append(e.field)
            except BaseException as e:  # noqa: BLE001 - anything else is the failure under test
                outcomes.append(repr(e))

    threads = [threading.Thread(target=steps) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len(outcomes) == 20
    assert all(o == "self" or o in ("tracking", "at_goal", "replanned", "stuck") for o in outcomes), outcomes
    assert any(o != "self" for o in outcomes)
