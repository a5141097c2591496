"""Fuzz: the world side (issue 44). Every world file kind (workcell, plan, grasp graph,
trajectory, robot, a scene's mesh) mutated and read through its loader, then used when it was
accepted; the world commands (execute, pick-place, grasp-graph, regrasp-sequence) with bad
option values and bad files; generated valid runs that must succeed with finite outputs; SIGTERM
at random moments and closed streams, in real processes. Each case: the closed error set with
its field, no internal error or traceback, no NaN/inf in anything written, no temporary file
left, nothing over its memory limit."""

from __future__ import annotations

import json
import os
import shlex
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

import regrasp
from regrasp.dexterity.graph import GraspGraph
from regrasp.execution.trajectory import Trajectory
from regrasp.workcell import Workcell

from . import harness
from .harness import fuzz_settings, limit_child, run
from .strategies import EXAMPLES
from .test_fuzz_cli import SENTINEL, judge, run_main, text_non_finite
from .world_files import KINDS, MESH, MESH_SCENE, graph_base, mutated_file, mutated_mesh, plan_base, workcell_base

ROOT = Path(__file__).resolve().parents[2]
SCENE = EXAMPLES / "block-low-friction.toml"


def _scene():
    return regrasp.load_scene(SCENE)


def _use(kind: str, value):
    """What a user does next with an accepted file: its outputs are checked for NaN by the harness."""
    if kind == "workcell":
        return {"toml": Workcell.from_toml(value.to_toml()).to_dict(), "contacts": [c.frame for c in value.contacts()]}
    if kind == "plan":
        from regrasp.execution.execute import World, execute

        if len(value.poses) <= 12:  # a short plan runs in the planner's view (MuJoCo, a second or so)
            e = execute(World(_scene()), value)
            return {"success": e.success, "error": e.plan_end_error, "poses": e.poses}
        return {"valid": value.check(_scene())}
    if kind == "graph":
        from regrasp.dexterity.sequence import plan

        found = []
        for a in value.node_names[:2]:
            for b in value.node_names[:3]:
                try:
                    found.append(plan(value, a, b))
                except regrasp.ArgumentError as e:  # no measured sequence between them: a valid answer
                    if e.field != "to":
                        raise
        return found
    if kind == "robot":  # compiled: its bodies and joints checked against the model
        from regrasp.robot.model import build

        r = build(str(value))
        return {"tcp": r.tcp_pose(), "limits": r.joint_limits()}
    return Trajectory.from_json(value.to_json()).to_json()


def _load(kind: str, path: Path):
    if kind == "robot":
        from regrasp.robot.robot_file import load

        load(path)
        return path
    return {"workcell": Workcell.load, "plan": lambda p: regrasp.Plan.load(p, _scene()),
            "graph": GraspGraph.load, "trajectory": Trajectory.load}[kind](path)


@fuzz_settings(15, 9500)
@given(kind=st.sampled_from(sorted(KINDS)), data=st.data())
def test_mutated_world_files(kind, data, tmp_path_factory):
    text, what, must = data.draw(mutated_file(kind))
    path = tmp_path_factory.mktemp("world") / f"f.{KINDS[kind][1]}"
    path.write_text(text, errors="surrogateescape")
    run(f"world.{kind}", f"{kind}: {what}", lambda: _use(kind, _load(kind, path)), timeout=30, reject=must or None)


@fuzz_settings(8, 1500)
@given(case=mutated_mesh())
def test_mutated_meshes(case, tmp_path_factory):
    text, what, must = case
    base = tmp_path_factory.mktemp("mesh")
    (base / "meshes").mkdir()
    (base / "meshes" / MESH.name).write_text(text, errors="surrogateescape")
    shutil.copy(MESH_SCENE, base / MESH_SCENE.name)

    run("world.mesh", f"mesh: {what}", lambda: regrasp.plan(regrasp.load_scene(base / MESH_SCENE.name), seed=0,
                                                            time_limit=0.5), timeout=30, reject=must or None)


# --- the world commands -------------------------------------------------------------------------

def _files(base: Path) -> dict:
    files = {"base": str(base), "scene": str(base / "scene.toml"), "out": str(base / "out.json"),
             "plan": str(base / "plan.json"), "workcell": str(base / "w.toml"), "graph": str(base / "g.json"),
             "traj": str(base / "traj.json")}
    shutil.copy(SCENE, files["scene"])
    Path(files["plan"]).write_text(plan_base())
    Path(files["workcell"]).write_text(Workcell.from_dict(json.loads(workcell_base())).to_toml())
    Path(files["graph"]).write_text(graph_base())
    for k in ("out", "traj"):
        Path(files[k]).write_text(SENTINEL)
    return files


GRAPH_NODES = [n["name"] for n in json.loads(graph_base())["nodes"]]

#: command -> (valid argv, options that may be mutated: option -> (certainly bad values, maybe valid values))
WORLD = {
    "execute": (["execute", "{scene}", "--plan", "{plan}", "--robot", "free-gripper", "--workcell", "{workcell}",
                 "--trajectory", "{traj}", "--json"],
                {"--robot": (["nope", "", "UR5E"], []), "--scale-friction": (["nan", "-1", "0", "inf", "x"], ["1e9"]),
                 "--scale-grip": (["nan", "-1", "0", "x"], []), "--scale-mass": (["nan", "-inf", "0"], []),
                 "--start-error": (["nan,0,0", "0,0", "x", "1e300,0,0"], []),
                 "--plan": (["/dev/zero", "{base}", "{base}/missing.json", "{scene}"], []),
                 "--workcell": (["/dev/zero", "{base}/missing.toml", "{plan}", "{base}"], [])}),
    "execute-arm": (["execute", "{scene}", "--plan", "{plan}", "--json"],
                    {"--plan": (["/dev/zero", "{base}", "{scene}"], []),
                     "--workcell": (["/dev/zero", "{plan}"], []), "--robot": (["nope", "ur5"], [])}),
    "pick-place": (["pick-place", "{scene}", "--plan-only", "--json"],
                   {"--place": (["nan,0,0,1,0,0,0", "0,0,0", "0,0,0,0,0,0,0", "1e300,0,0,1,0,0,0"], []),
                    "--pick": (["x", "0,0,0,1,0,0", "inf,0,0,1,0,0,0"], []),
                    "--depth": (["nan", "-1", "x", "inf"], []), "--seed": (["-1", "x", "1.5"], []),
                    "--workcell": (["/dev/zero", "{plan}", "{base}/missing.toml"], [])}),
    "grasp-graph": (["grasp-graph", "box", "--trials", "1", "--actions", "gravity-slide", "--workers", "1", "--out",
                     "{out}", "--json"],
                    {"--trials": (["0", "-1", "x", "1.5", "100000000000"], []),
                     "--actions": (["levitate", "", "gravity-slide,levitate"], []),
                     "--workers": (["0", "-1", "x", "100000"], []), "--seed": (["-1", "x"], []),
                     "--out": (["{base}", "/proc/regrasp-fuzz/x.json"], [])}),
    "regrasp-sequence": (["regrasp-sequence", "{graph}", "--from", GRAPH_NODES[0], "--to", GRAPH_NODES[2], "--json"],
                         {"--from": (["nope", "", "G0"], []), "--to": (["nope", ""], []),
                          "--runs": (["0", "-1", "x"], []), "--objective": (["nope"], []),
                          "--seed": (["-1", "x"], [])}),
}
#: the command's positional argument that may be replaced by a bad file
POSITIONAL = {"execute": "{scene}", "execute-arm": "{scene}", "pick-place": "{scene}", "grasp-graph": "box",
              "regrasp-sequence": "{graph}"}
BAD_POSITIONAL = ["/dev/zero", "{base}", "{base}/missing.toml", "{plan}", "nope"]


@st.composite
def world_invocation(draw):
    """(command, argv with one option or the positional argument replaced, the option named
    when the value is certainly bad)."""
    name = draw(st.sampled_from(sorted(WORLD)))
    argv, options = WORLD[name]
    argv = list(argv)
    if draw(st.integers(0, 4)) == 0:
        i = argv.index(POSITIONAL[name])
        argv[i] = draw(st.sampled_from(BAD_POSITIONAL))
        return name, argv, None
    opt = draw(st.sampled_from(sorted(options)))
    bad, maybe = options[opt]
    value = draw(st.sampled_from(bad + maybe))
    if opt in argv:
        argv[argv.index(opt) + 1] = value
    else:
        argv += [opt, value]
    i = argv.index(opt)
    argv[i:i + 2] = [f"{opt}={value}"]
    return name, argv, opt.lstrip("-") if value in bad else None


def _fill(argv: list, files: dict) -> list:
    return [a.format(**files) for a in argv]


@fuzz_settings(12, 1000)
@given(case=world_invocation())
def test_world_commands_with_bad_input(case, tmp_path_factory):
    name, argv, must = case
    files = _files(tmp_path_factory.mktemp("wcli"))
    argv = _fill(argv, files)
    r = run(f"cli.{name}", "regrasp " + " ".join(argv), lambda: run_main(argv), timeout=60)
    judge(f"cli.{name}", argv, r, must, files["out"] if files["out"] in argv else None, outputs=[files["traj"]])
    if r is not None and r[0] != 0 and Path(files["traj"]).read_text() != SENTINEL:
        harness.RECORDER.fail("clobbered", f"cli.{name}", " ".join(argv), "a failed run replaced the trajectory file")
    _no_temporary_files(f"cli.{name}", " ".join(argv), files["base"])


def _no_temporary_files(family: str, what: str, folder: str) -> None:
    left = [p.name for p in Path(folder).rglob(".*tmp*")]
    if left:
        harness.RECORDER.fail("temp_left", family, what, f"temporary files left behind: {left}")


@st.composite
def valid_run(draw):
    """A valid world run: the plan in MuJoCo in a perturbed world (the planner's view), in the
    quasi-static simulator at a drawn step, tracked by the MPC, or by the free gripper with its
    trajectory."""
    kind = draw(st.sampled_from(["mujoco", "quasistatic", "free-gripper", "control"]))
    if kind == "mujoco":
        scales = [f"{draw(st.floats(0.7, 1.3)):.3f}" for _ in range(3)]
        return ["simulate", "{scene}", "--plan", "{plan}", "--engine", "mujoco", "--scale-friction", scales[0],
                "--scale-grip", scales[1], "--scale-mass", scales[2], "--json"]
    if kind == "quasistatic":
        return ["simulate", "{scene}", "--plan", "{plan}", "--dt", f"{draw(st.floats(0.01, 0.1)):.4f}", "--json"]
    if kind == "control":  # closed loop: the MPC
        return ["control", "{scene}", "--plan", "{plan}", "--json"]
    return ["execute", "{scene}", "--plan", "{plan}", "--robot", "free-gripper", "--trajectory", "{traj}", "--json"]


@fuzz_settings(4, 100)
@given(argv=valid_run())
def test_valid_world_runs_succeed_with_finite_outputs(argv, tmp_path_factory):
    """Generated valid inputs must run (exit 0, or 1 when a perturbed world defeats the plan) and
    everything they print or write is finite; an open-loop execution writes its trajectory."""
    files = _files(tmp_path_factory.mktemp("valid"))
    argv = _fill(argv, files)
    what = "regrasp " + " ".join(argv)
    r = run("cli.valid-run", what, lambda: run_main(argv), timeout=60)
    judge("cli.valid-run", argv, r, None, None, outputs=[files["traj"]])
    if r is not None and r[0] not in (0, 1):
        harness.RECORDER.fail("exit_status", "cli.valid-run", what, f"a valid run exited {r[0]}: {r[2]}")
    if r is not None and r[0] == 0 and "--trajectory" in argv and Path(files["traj"]).read_text() == SENTINEL:
        harness.RECORDER.fail("exit_status", "cli.valid-run", what, "exit 0 without writing the trajectory")


@fuzz_settings(3, 60)
@given(ab=st.sampled_from([(0, 1), (0, 2), (1, 2)]), objective=st.sampled_from(["reliable", "expected"]))
def test_valid_sequences_succeed_with_finite_outputs(ab, objective, tmp_path_factory):
    """Between grasps the base graph connects (g0 -> g1 -> g2), a sequence is found: exit 0."""
    a, b = GRAPH_NODES[ab[0]], GRAPH_NODES[ab[1]]
    files = _files(tmp_path_factory.mktemp("seq"))
    argv = _fill(["regrasp-sequence", "{graph}", "--from", a, "--to", b, "--objective", objective, "--json"], files)
    r = run("cli.valid-sequence", "regrasp " + " ".join(argv), lambda: run_main(argv))
    judge("cli.valid-sequence", argv, r, None, None)
    if r is not None and r[0] != 0:
        harness.RECORDER.fail("exit_status", "cli.valid-sequence", " ".join(argv), f"exit {r[0]}: {r[2]}")


# --- real processes: SIGTERM and closed streams -------------------------------------------------

def _process(args: list, tail: str = "", cwd=None):
    """`regrasp ARGS` in its own process (``tail``: shell redirections, run by the shell, which
    execs the command so that a signal reaches it), under the harness's memory limit."""
    cmd = [sys.executable, "-m", "regrasp.cli", *args]
    if tail:
        cmd = ("" if "|" in tail else "exec ") + " ".join(shlex.quote(a) for a in cmd) + tail
    return subprocess.Popen(cmd, shell=bool(tail), cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=limit_child, start_new_session=True)


SIGTERM_CASES = [
    ["plan", "{scene}", "--time-limit", "5", "--seed", "0", "--out", "{out}", "--plot", "{base}/p.png"],
    ["execute", "{scene}", "--plan", "{plan}", "--robot", "free-gripper", "--trajectory", "{traj}", "--json"],
    ["grasp-graph", "box", "--trials", "1", "--actions", "gravity-slide", "--workers", "2", "--out", "{out}"],
    ["validate", "{scene}", "--pushes", "200", "--seed", "0", "--json"],
]


#: the signal -> (the status after it, the last line on stderr)
STOPS = {signal.SIGTERM: (143, "regrasp: terminated"), signal.SIGINT: (130, "regrasp: interrupted")}


@fuzz_settings(3, 60)
@given(argv=st.sampled_from(SIGTERM_CASES), after=st.floats(0.8, 4.0), sig=st.sampled_from(sorted(STOPS)))
def test_sigterm_at_any_moment(argv, after, sig, tmp_path_factory):
    """SIGTERM (or Ctrl-C's SIGINT) at a random moment — planning, MuJoCo, the arm's world, a
    process pool: exit 143 with "regrasp: terminated" (130, "interrupted"), or the run's own
    status when it had finished; no traceback, the outputs as they were or complete, no temporary
    file, no worker left."""
    status, line = STOPS[sig]
    files = _files(tmp_path_factory.mktemp("term"))
    argv = _fill(argv, files)
    what = f"regrasp {' '.join(argv)} + {signal.Signals(sig).name} after {after:.2f} s"
    harness.RECORDER.case("process.sigterm")
    p = _process(argv, cwd=files["base"])
    time.sleep(after)
    p.send_signal(sig)
    try:
        out, err = p.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)
        p.communicate()
        harness.RECORDER.fail("hang", "process.sigterm", what, "still running 30 s after SIGTERM")
        return
    if "Traceback" in err or "internal error" in err:
        harness.RECORDER.fail("traceback", "process.sigterm", what, err)
    stopped = err.strip().endswith(line)
    if p.returncode == status and not stopped:
        harness.RECORDER.fail("exit_status", "process.sigterm", what, f"{status} but stderr {err!r}")
    # -15 (SIGTERM) or 130 without the line (SIGINT, Python's own KeyboardInterrupt exit): the
    # signal came before the command set its handler (Python still importing) or after it
    # restored the default one (the interpreter ending); its outputs are then untouched or complete
    if p.returncode not in (0, 1, status, -sig) or (p.returncode == status and "Traceback" in err):
        harness.RECORDER.fail("exit_status", "process.sigterm", what, f"exit {p.returncode}\n{err}")
    for k in ("out", "traj"):
        text = Path(files[k]).read_text(errors="replace")
        if stopped and text != SENTINEL:
            harness.RECORDER.fail("clobbered", "process.sigterm", what, f"stopped, but {files[k]} was written")
        elif text != SENTINEL and text_non_finite(text, json_text=True):
            harness.RECORDER.fail("nan", "process.sigterm", what, f"{files[k]} (incomplete?): {text_non_finite(text, True)}")
    _no_temporary_files("process.sigterm", what, files["base"])
    _no_workers_left("process.sigterm", what, p.pid)


def _no_workers_left(family: str, what: str, pid: int) -> None:
    """No process of the stopped command's session (its pool workers) outlives it by a second."""
    deadline = time.monotonic() + 1.0
    while time.monotonic() < deadline:
        left = [d for d in os.listdir("/proc") if d.isdigit() and _session(int(d)) == pid]
        if not left:
            return
        time.sleep(0.1)
    harness.RECORDER.fail("hang", family, what, f"processes of its session still running: {left}")


def _session(pid: int) -> int | None:
    """The session of a live process ``pid`` (None for a zombie, which has ended: an init that
    does not reap, as in some containers, leaves them)."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            state, _, _, session = f.read().rsplit(")", 1)[1].split()[:4]
        return None if state in "ZX" else int(session)
    except (OSError, ValueError, IndexError):
        return None


STREAM_CASES = [
    (["cone", "{scene}", "--pose", "0,0,0", "--pusher", "left", "--json"], " >&-"),
    (["cone", "{scene}", "--pose", "0,0,0", "--pusher", "left", "--json"], " 2>&-"),
    (["plan", "{scene}", "--time-limit", "0.3", "--out", "{out}"], " >&- 2>&-"),
    (["execute", "{scene}", "--plan", "/dev/zero"], " >&-"),
    (["regrasp-sequence", "{graph}", "--from", GRAPH_NODES[0], "--to", GRAPH_NODES[1], "--json"], " >&-"),
    (["examples"], " | head -c 1"),
]


@pytest.mark.parametrize("argv,tail", STREAM_CASES, ids=lambda a: str(a)[:40])
def test_closed_streams(argv, tail, tmp_path):
    files = _files(tmp_path)
    argv = _fill(argv, files)
    what = f"regrasp {' '.join(argv)}{tail}"
    harness.RECORDER.case("process.streams")
    p = _process(argv, tail, cwd=tmp_path)
    try:
        _, err = p.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)
        harness.RECORDER.fail("hang", "process.streams", what, "ran past 60 s")
        return
    if "Traceback" in err or "internal error" in err:
        harness.RECORDER.fail("traceback", "process.streams", what, err)
    if p.returncode not in (0, 1, 2):
        harness.RECORDER.fail("exit_status", "process.streams", what, f"exit {p.returncode}\n{err}")
    if "/dev/zero" in argv and p.returncode != 2:
        harness.RECORDER.fail("accepted", "process.streams", what, f"exit {p.returncode} for --plan /dev/zero")
