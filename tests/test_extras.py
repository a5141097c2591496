"""The lean core: with the optional dependencies made unimportable (a meta-path finder installed
by a sitecustomize on PYTHONPATH), the package imports and its core works; each command that needs
an extra exits 1 naming the extra to install, in one line without a traceback; the demo works
and says its figures were skipped."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from .conftest import EXAMPLES

OPTIONAL = ("mujoco", "matplotlib", "casadi", "scipy", "ray")

BLOCKER = textwrap.dedent('''
    import os, sys

    BLOCKED = set(os.environ["REGRASP_TEST_BLOCK"].split(","))

    class _Blocked:
        """Makes the blocked top-level packages (and their submodules) unimportable."""

        def find_spec(self, name, path=None, target=None):
            if name.split(".")[0] in BLOCKED:
                raise ModuleNotFoundError(f"No module named {name!r} (blocked by the test)", name=name)
            return None

    sys.meta_path.insert(0, _Blocked())
''')


@pytest.fixture(scope="module")
def blocker(tmp_path_factory) -> Path:
    d = tmp_path_factory.mktemp("blocker")
    (d / "sitecustomize.py").write_text(BLOCKER)
    return d


def run(blocker: Path, args: list, blocked=OPTIONAL, cwd=None) -> subprocess.CompletedProcess:
    """``python args`` with the modules of ``blocked`` unimportable."""
    inherited = [str(Path(p).absolute()) for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]
    env = dict(os.environ, REGRASP_TEST_BLOCK=",".join(blocked), PYTHONPATH=os.pathsep.join([str(blocker)] + inherited))
    env.pop("REGRASP_TRACEBACK", None)
    return subprocess.run([sys.executable, *args], capture_output=True, text=True, env=env, cwd=cwd, timeout=300)


def cli(blocker: Path, args: list, blocked=OPTIONAL, cwd=None) -> subprocess.CompletedProcess:
    return run(blocker, ["-m", "regrasp.cli", *args], blocked, cwd)


def test_the_blocker_blocks(blocker):
    r = run(blocker, ["-c", "import mujoco"])
    assert r.returncode == 1 and "blocked by the test" in r.stderr
    r = run(blocker, ["-c", "import matplotlib.pyplot"], blocked=("mujoco",))
    assert r.returncode == 0, r.stderr


def test_core_works_without_extras(blocker):
    code = textwrap.dedent(f'''
        import sys
        import numpy as np
        import regrasp
        from regrasp import examples
        assert issubclass(regrasp.MissingExtraError, (regrasp.RegraspError, ImportError))
        s = regrasp.load_scene(examples.path("block-low-friction"))
        cone = s.motion_cone([0.0, 0.0, 0.0], "left")
        assert cone.generators.shape == (4, 3) and cone.contains([0.01, 0.0, 0.0])
        p = regrasp.plan(regrasp.load_scene(examples.path("t-shape")), seed=0)
        assert p.found and p.valid
        from regrasp.sim.quasistatic import replay_plan
        assert replay_plan(regrasp.load_scene(examples.path("t-shape")), p).success
        s3 = regrasp.load_scene(examples.path("prism-3d"))   # a mesh, quaternions without scipy
        p3 = regrasp.plan(s3, seed=0)
        assert p3.found and s3.replay(p3)["success"]
        import regrasp.bench, regrasp.cli, regrasp.control, regrasp.reference, regrasp.viz.viewer, regrasp.mujoco.validation
        loaded = sorted(m for m in {OPTIONAL!r} if m in sys.modules)
        assert not loaded, loaded
        print("core ok")
    ''')
    r = run(blocker, ["-c", code])
    assert r.returncode == 0 and "core ok" in r.stdout, r.stderr


@pytest.fixture(scope="module")
def planar_plan(blocker, tmp_path_factory) -> Path:
    """A plan of block-high-friction made without any extra."""
    out = tmp_path_factory.mktemp("plan") / "plan.json"
    r = cli(blocker, ["plan", str(EXAMPLES / "block-high-friction.toml"), "--out", str(out)])
    assert r.returncode == 0, r.stderr
    return out


CASES = [  # (id, command line after `regrasp`, the extra it needs, the modules blocked)
    ("plan --plot", ["plan", "{ex}/t-shape.toml", "--plot", "{tmp}/p.png"], "plot", OPTIONAL),
    ("cone --plot", ["cone", "{ex}/block-low-friction.toml", "--pose", "0,0,0", "--pusher", "left", "--plot", "{tmp}/c.png"],
     "plot", OPTIONAL),
    ("simulate --engine mujoco", ["simulate", "{ex}/block-high-friction.toml", "--plan", "{plan}", "--engine", "mujoco"],
     "mujoco", OPTIONAL),
    ("simulate --plot", ["simulate", "{ex}/block-high-friction.toml", "--plan", "{plan}", "--plot", "{tmp}/r.png"],
     "plot", OPTIONAL),
    ("validate --engines mujoco", ["validate", "{ex}/block-low-friction.toml", "--engines", "mujoco", "--pushes", "2"],
     "mujoco", OPTIONAL),
    ("validate --ray", ["validate", "{ex}/block-low-friction.toml", "--engines", "mujoco", "--pushes", "2", "--ray", "local"],
     "ray", ("ray",)),
    ("control --engine mujoco", ["control", "{ex}/block-high-friction.toml", "--plan", "{plan}", "--engine", "mujoco"],
     "mujoco", OPTIONAL),
    ("validate --engines drake", ["validate", "{ex}/block-low-friction.toml", "--engines", "drake", "--pushes", "2"],
     "drake", ("pydrake",)),
    ("simulate --engine drake", ["simulate", "{ex}/block-high-friction.toml", "--plan", "{plan}", "--engine", "drake"],
     "drake", ("pydrake",)),
]


@pytest.mark.parametrize("args, extra, blocked", [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_commands_name_the_missing_extra(blocker, planar_plan, tmp_path, args, extra, blocked):
    args = [a.format(ex=EXAMPLES, tmp=tmp_path, plan=planar_plan) for a in args]
    r = cli(blocker, args, blocked)
    assert r.returncode == 1, (r.returncode, r.stdout, r.stderr)
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in r.stderr, r.stderr
    assert f"pip install 'regrasp[{extra}]'" in lines[0] and f"`regrasp {args[0]}` needs" in lines[0], lines
    assert not any(p.name.endswith(".png") for p in tmp_path.iterdir())


def test_reference_and_bench_baselines_name_their_extra(blocker):
    code = textwrap.dedent('''
        import regrasp
        from regrasp import bench, examples
        from regrasp.reference import mncp
        s = regrasp.Scene.load(examples.path("block-low-friction"))
        p = s._core.quasistatic_problem([0.0, 0.0, 0.0], "left", "points", 0, 4, False)
        try:
            mncp.solve(p, pusher_twist=[0.01, 0.0, 0.0])
        except regrasp.MissingExtraError as e:
            assert (e.module, e.extra) == ("casadi", "reference"), (e.module, e.extra)
            print("reference:", e)
        assert bench._unless_missing("MuJoCo's speed", bench.run_mujoco) == {}
        assert bench._unless_missing("the MPC step against SciPy", bench.run_mpc) == {}
    ''')
    r = run(blocker, ["-c", code])
    assert r.returncode == 0, r.stderr
    assert "reference: CasADi (IPOPT) is not installed (module `casadi`): pip install 'regrasp[reference]'" in r.stdout
    assert "MuJoCo's speed skipped" in r.stderr and "regrasp[mujoco]" in r.stderr, r.stderr
    assert "MPC step against SciPy skipped" in r.stderr and "regrasp[reference]" in r.stderr, r.stderr


def test_demo_without_extras_writes_the_plan_and_skips_the_figures(blocker, tmp_path):
    r = cli(blocker, ["demo", "--out", "demo"], cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "figures skipped: pip install 'regrasp[plot]'" in r.stdout
    assert "plan found" in r.stdout
    assert sorted(p.name for p in (tmp_path / "demo").iterdir()) == ["t-shape-plan.json"]
    assert json.loads((tmp_path / "demo" / "t-shape-plan.json").read_text())["found"] is True


DRAWN_CASES = [  # (id, command line after `regrasp`): each asks for a drawn output
    ("plan --plot", ["plan", "{ex}/t-shape.toml", "--out", "{tmp}/plan.json", "--plot", "{tmp}/p.png"]),
    ("plan --animate", ["plan", "{ex}/t-shape.toml", "--out", "{tmp}/plan.json", "--animate", "{tmp}/p.gif"]),
    ("cone --plot", ["cone", "{ex}/block-low-friction.toml", "--pose", "0,0,0", "--pusher", "left", "--plot", "{tmp}/c.png"]),
    ("simulate --plot", ["simulate", "{ex}/block-high-friction.toml", "--plan", "{plan}", "--plot", "{tmp}/r.png"]),
    ("simulate --video", ["simulate", "{ex}/block-high-friction.toml", "--plan", "{plan}", "--engine", "mujoco",
                          "--video", "{tmp}/v.gif"]),
    ("push --plot", ["push", "{ex}/t-shape.toml", "--pose", "0,0,0", "--pusher", "top", "--twist", "0,-0.01,0",
                     "--plot", "{tmp}/p.png"]),
    ("control --plot", ["control", "{ex}/block-high-friction.toml", "--plan", "{plan}", "--plot", "{tmp}/k.png"]),
]


@pytest.mark.parametrize("args", [c[1] for c in DRAWN_CASES], ids=[c[0] for c in DRAWN_CASES])
def test_a_missing_plot_extra_is_found_before_any_work(blocker, planar_plan, tmp_path, args):
    """Without matplotlib, a command asked for a figure, animation or video exits 1 naming
    regrasp[plot] before it loads the scene (so before any plan or simulation is made)."""
    args = [a.format(ex=EXAMPLES, tmp=tmp_path, plan=planar_plan) for a in args]
    code = textwrap.dedent(f'''
        import sys
        import regrasp.cli
        def loaded(*args, **kw):
            print("the scene was loaded", file=sys.stderr)
            raise SystemExit(3)
        regrasp.cli.load_scene = loaded
        sys.exit(regrasp.cli.main({args!r}))
    ''')
    r = run(blocker, ["-c", code], ("matplotlib",))
    assert r.returncode == 1, (r.returncode, r.stdout, r.stderr)
    assert "the scene was loaded" not in r.stderr and r.stdout == "", r.stderr
    assert f"`regrasp {args[0]}` needs matplotlib: pip install 'regrasp[plot]'" in r.stderr, r.stderr
    assert list(tmp_path.iterdir()) == []


def _no_nan(constant: str):
    raise ValueError(f"not JSON: {constant}")


def test_bench_json_without_reference_is_valid_json(blocker):
    """`regrasp bench --json` with the baselines' extras missing prints valid JSON (no NaN):
    a skipped baseline has None as its time and ratio. Made small: fewer cones, one seed, one
    example of each planner, two seeds of the limit surfaces' comparison."""
    code = textwrap.dedent('''
        import sys
        from regrasp import bench
        import regrasp.cli
        full_run, planner, plan3d, wm = bench.run, bench.run_planner, bench.run_plan3d, bench.run_world_motion
        hard = bench.run_hard_plans
        bench.run_hard_plans = lambda: hard(seeds=1, time_limit=1.0, names=("neck-unreachable",))
        bench.run = lambda **kw: full_run(**{**kw, "n": 300, "reps": 1, "baseline_reps": 1})
        bench.run_planner = lambda: planner(seeds=1, time_limit=5.0, examples=("block-high-friction",))
        bench.run_plan3d = lambda: plan3d(seeds=1, examples=("offset-3d",))
        bench.run_world_motion = lambda: wm(reps=1, examples=("block-low-friction",))
        ls = bench.run_limit_surface
        bench.run_limit_surface = lambda: ls(seeds=2, time_limit=5.0, examples=("block-high-friction",))
        sys.exit(regrasp.cli.main(["bench", "--quick", "--json"]))
    ''')
    r = run(blocker, ["-c", code], ("casadi", "scipy", "mujoco", "ompl"))
    assert r.returncode == 0, r.stderr
    res = json.loads(r.stdout, parse_constant=_no_nan)
    skipped = res["plan3d_offset-3d"]
    assert skipped["baseline_median_s"] is None and skipped["ratio"] is None, skipped
    assert "regrasp[reference]" in skipped["baseline"]
    assert "cone_batch_300" in res and not any(k.startswith(("mncp_", "mpc_step_", "mujoco_", "ik_", "arm_", "plan_only_", "plan_node_")) for k in res), sorted(res)
    assert res["world_motion_block-low-friction"]["median_s"] > 0 and res["mpc_horizon_20"]["median_s"] > 0  # need no extra
    assert res["cli_start_version"]["ratio"] > 0 and res["cli_start_plan_t_shape"]["baseline_median_s"] > 0
    assert res["hard_neck-unreachable"]["unreachable"] == 1 and res["hard_neck-unreachable"]["median_s"] < 1.0
