"""What the commands print for people: the files written, warnings, the same units in both
simulators, plurals, no ``-0.0``, units on 3-D errors, no figures that do not apply."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from regrasp.cli import error3d, plural, pusher_runs, rounded

from .conftest import run_cli as run

#: a printed negative zero (``-0.0`` not followed by more digits)
NEG_ZERO = re.compile(r"-0\.0(?![\d])")
ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
T_SHAPE = EXAMPLES / "t-shape.toml"
PIVOT = EXAMPLES / "pivot-3d.toml"




@pytest.fixture(scope="module")
def t_plan(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("plans") / "t.json"
    status, _, err = run("plan", T_SHAPE, "--out", path)
    assert status == 0, err
    return path


def test_the_printing_helpers():
    assert plural(1, "switch-over") == "1 switch-over" and plural(2, "step") == "2 steps"
    assert rounded([-0.0, -1e-9, 0.123456]) == [0.0, 0.0, 0.12346]
    assert not NEG_ZERO.search(str(rounded([-0.0, -1e-7]))) and NEG_ZERO.search("[-0.0, 1]")
    assert pusher_runs(["start"]) == "no pushes" and pusher_runs([None, "a", "a", "b"]) == "a x2 -> b x1"
    assert error3d([-0.00022, 0.0, -6e-05, 0.00734]) == "position [-0.00022, 0.0, -6e-05] m, angle 0.00734 rad"


def test_plan_says_each_file_it_wrote_and_json_stays_the_plan(tmp_path):
    files = [tmp_path / "p.json", tmp_path / "p.html"]
    status, out, err = run("plan", T_SHAPE, "--out", files[0], "--html", files[1])
    assert status == 0, err
    assert [f"wrote {f}" for f in files] == [ln for ln in out.splitlines() if ln.startswith("wrote")], out
    head = out.splitlines()[0]  # the final plan's line (the first plan's may follow)
    status, out, err = run("plan", T_SHAPE, "--out", files[0], "--json")
    assert status == 0 and "wrote" not in out + err and json.loads(out)["found"] is True
    # the head line counts the final plan's switch-overs, in the singular for one
    m = re.search(r"(\d+) switch-over(s?),", head)
    assert m and (m.group(2) == "") == (int(m.group(1)) == 1), head


def test_an_mncp_plan_that_fails_the_exact_test_warns_but_is_found(tmp_path):
    status, out, err = run("plan", EXAMPLES / "block-xztheta.toml", "--propagation", "mncp", "--goal", "0.0,0.02,3.0")
    assert status == 0, err
    assert "(exact test): False" in out, out
    assert "warning" in err and "mncp propagation" in err and "exact motion-cone test" in err and "slip" in err, err
    status, out, err = run("plan", T_SHAPE)  # every step sticks: no warning
    assert status == 0 and "(exact test): True" in out and "warning" not in err


def test_simulate_reports_steps_and_pusher_runs_in_both_engines(t_plan):
    pytest.importorskip("mujoco")
    heads = {}
    for engine in ("quasistatic", "mujoco"):
        status, out, err = run("simulate", T_SHAPE, "--plan", t_plan, "--engine", engine)
        assert status == 0, err
        heads[engine] = out.splitlines()[0]
        assert not NEG_ZERO.search(out), out
    counts = {e: re.search(r"replayed (\d+ steps in \d+ pusher runs)", h) for e, h in heads.items()}
    assert all(counts.values()), heads
    pushers = [s["pusher"] for s in json.loads(t_plan.read_text())["path"][1:]]
    runs = 1 + sum(a != b for a, b in zip(pushers, pushers[1:]))
    assert counts["quasistatic"][1] == counts["mujoco"][1] == f"{len(pushers)} steps in {runs} pusher runs", heads


def test_control_open_loop_says_what_happened_in_user_terms(t_plan):
    status, out, err = run("control", T_SHAPE, "--plan", t_plan, "--open-loop", "--poke", "2,0.005,0,0")
    assert status == 1, err
    assert "MPC step" not in out and "re-plan" not in out, out
    assert "left the admissible region at t = " in out and "(m, m, rad)" in out, out
    assert "invalid `pose`" not in out and "the world failed" not in out, out
    status, out, err = run("control", T_SHAPE, "--plan", t_plan, "--poke", "2,0.002,0,0")
    assert status == 0 and "median MPC step" in out and "0 re-plans" in out and not NEG_ZERO.search(out), (out, err)


def test_3d_errors_carry_units(tmp_path):
    plan = tmp_path / "p.json"
    status, _, err = run("plan", PIVOT, "--out", plan, "--time-limit", "5", "--seed", "0")
    assert status == 0, err
    status, out, err = run("simulate", PIVOT, "--plan", plan)
    assert re.search(r"error position \[[^]]*\] m, angle \S+ rad", out), (out, err)


def test_a_short_push_needs_no_dt():
    status, out, err = run("push", T_SHAPE, "--pose", "0,0,0", "--pusher", "top", "--twist", "0,-0.01,0",
                           "--duration", "0.03")
    assert status == 0, err
    assert "for 0.03 s" in out and not NEG_ZERO.search(out), out


def test_bench_mujoco_steps_has_no_self_baseline():
    pytest.importorskip("mujoco")
    from regrasp import bench

    row = bench.run_mujoco(steps=200)["mujoco_steps"]
    assert row["baseline_median_s"] is None and row["ratio"] is None and row["baseline"].startswith("none"), row
    assert re.search(r"mujoco_steps +[\d.]+ms +- +- ", bench.format_results({"mujoco_steps": row}))


def test_the_plan_figure_legend_lists_only_the_pushers_used(tmp_path, t_plan):
    pytest.importorskip("matplotlib")
    import regrasp
    from regrasp.viz import plotting

    scene = regrasp.Scene.load(T_SHAPE)
    plan = regrasp.Plan.load(t_plan, scene)
    used = set(plan.pushers[1:])
    assert used < set(scene.pusher_names)  # the scene has pushers the plan does not use
    import matplotlib.axes

    labels = []
    legend = matplotlib.axes.Axes.legend

    def spy(ax, *a, **kw):
        labels.extend(ax.get_legend_handles_labels()[1])
        return legend(ax, *a, **kw)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(matplotlib.axes.Axes, "legend", spy)
        plotting.plot_plan(scene, plan, tmp_path / "p.png")
    shown = {lb.removeprefix("pusher ") for lb in labels if lb.startswith("pusher ")}
    assert shown == used, (shown, used)
