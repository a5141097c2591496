"""The input limits and the physical sense of every world value (issue 44), at the command line:
each example of the issue is refused quickly with exit 2 naming its field, no traceback, no
internal error. The limits themselves are stated once, in the core (``bounds.rs``)."""

from __future__ import annotations

import contextlib
import io
import json
import time
from pathlib import Path

import pytest

import regrasp
from regrasp import cli
from regrasp.dexterity.actions import ACTIONS
from regrasp.dexterity.graph import Edge, GraspGraph
from regrasp.dexterity.objects import load_object
from regrasp.dexterity.taxonomy import taxonomy_of
from regrasp.fields import LIMITS, MAX_NESTING, MAX_PLAN_STEPS, MAX_WORKCELL_FEATURES
from regrasp.files import nesting
from regrasp.workcell import Workcell, bundled

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "examples" / "block-low-friction.toml"


def regrasp_cli(*argv) -> tuple[int, str, float]:
    """``regrasp ARGV`` in this process: (status, stderr, seconds)."""
    err = io.StringIO()
    t0 = time.perf_counter()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
        try:
            status = cli.main([str(a) for a in argv])
        except SystemExit as e:
            status = e.code
    return status, err.getvalue(), time.perf_counter() - t0


def refused(result, field: str, within: float = 10.0) -> None:
    status, err, took = result
    assert status == 2, err
    assert f"`{field}" in err and "internal error" not in err and "Traceback" not in err, err
    assert took < within, f"took {took:.1f} s to refuse"


@pytest.fixture(scope="module")
def plan_json() -> dict:
    return regrasp.plan(regrasp.load_scene(SCENE), seed=0, time_limit=1.0).to_json()


def write(tmp_path, name: str, value) -> Path:
    p = tmp_path / name
    p.write_text(value if isinstance(value, str) else json.dumps(value))
    return p


def test_the_limits_are_the_cores_and_documented():
    assert LIMITS == {k: (int(v) if float(v).is_integer() else v) for k, v in regrasp._core.LIMITS.items()}
    text = (ROOT / "docs" / "guarantees.md").read_text()
    for name, value in LIMITS.items():
        assert f"`{name}`" in text and f"{value:,}" in text, f"docs/guarantees.md does not state the limit {name}"


@pytest.mark.parametrize("command", ["simulate", "execute"])
@pytest.mark.parametrize("steps, field", [(10**6, "plan"),  # its file is larger than file_bytes
                                          (2 * 10**4, "plan.path"), (MAX_PLAN_STEPS + 1, "plan.path")])
def test_a_plan_with_too_many_steps_is_refused_at_once(tmp_path, plan_json, command, steps, field):
    d = dict(plan_json, path=[plan_json["path"][0]] + [dict(plan_json["path"][1])] * steps)
    d.pop("step_margins", None)
    refused(regrasp_cli(command, SCENE, "--plan", write(tmp_path, "p.json", d)), field, within=30.0)


@pytest.mark.parametrize("pose, field", [([1e308, 0.0, 0.0], "plan.path[1].pose"),  # "cannot convert float NaN"
                                         ([0.0, 0.0, 1e6], "plan.path[1].pose")])  # 1e6 rad "executed"
@pytest.mark.parametrize("command", ["simulate", "execute"])
def test_a_plan_pose_out_of_the_world_is_refused(tmp_path, plan_json, pose, field, command):
    d = json.loads(json.dumps(plan_json))
    d["path"][1]["pose"] = pose
    refused(regrasp_cli(command, SCENE, "--plan", write(tmp_path, "p.json", d)), field)


def test_a_plan_of_the_largest_size_is_read(plan_json):
    d = dict(plan_json, path=[plan_json["path"][0]] + [dict(plan_json["path"][1])] * MAX_PLAN_STEPS)
    d.pop("step_margins", None)
    assert len(regrasp.Plan.from_json(d).poses) == MAX_PLAN_STEPS + 1


def test_a_workcell_with_too_many_features_is_refused_at_once(tmp_path, plan_json):
    d = Workcell.load(bundled()).to_dict()
    d["features"] = [dict(d["features"][0], name=f"f{i}") for i in range(2000)]
    w = write(tmp_path, "w.toml", _toml(d))
    refused(regrasp_cli("execute", SCENE, "--plan", write(tmp_path, "p.json", plan_json), "--workcell", w), "features")
    assert 2000 > MAX_WORKCELL_FEATURES


def _toml(d: dict) -> str:
    """A workcell dict's TOML text, written without the reader's checks (2,000 features)."""
    from regrasp.workcell.file import toml_value

    lines = [f"name = {toml_value(d['name'])}"]
    for table in ("table", "robot", "object"):
        if table in d:
            lines += [f"[{table}]"] + [f"{k} = {toml_value(v)}" for k, v in d[table].items()]
    for f in d["features"]:
        lines += ["[[features]]"] + [f"{k} = {toml_value(v)}" for k, v in f.items()]
    return "\n".join(lines) + "\n"


def test_an_object_under_the_table_is_refused(tmp_path, plan_json):
    d = Workcell.load(bundled()).to_dict()
    d["object"]["pose"][2] = d["table"]["height"] - 10.0
    refused(regrasp_cli("execute", SCENE, "--plan", write(tmp_path, "p.json", plan_json), "--workcell",
                        write(tmp_path, "w.toml", _toml(d))), "object.pose[2]")


def test_a_deeply_nested_workcell_is_refused(tmp_path, plan_json):
    deep = 'name = "w"\nx = ' + "[" * 100_000 + "]" * 100_000 + "\n"
    refused(regrasp_cli("execute", SCENE, "--plan", write(tmp_path, "p.json", plan_json), "--workcell",
                        write(tmp_path, "w.toml", deep)), "(toml)")


@pytest.fixture(scope="module")
def graph(tmp_path_factory) -> dict:
    grasps = taxonomy_of(load_object("box")).grasps
    nodes = [g.to_dict() for g in grasps[:3]]
    a, b = nodes[0]["name"], nodes[1]["name"]
    edge = Edge(a, "gravity-slide", b, 20, {b: 15, "dropped": 5})
    g = GraspGraph({"name": "box", "file": "box"}, nodes, [edge], [ACTIONS["gravity-slide"].to_dict()],
                   {"trials": 20, "seed": 0, "spread": 0.2, "shift": 0.001, "turn": 0.035, "actions": None, "chain": False})
    return g.to_dict()


def sequence(tmp_path, d) -> tuple:
    a, b = d["nodes"][0]["name"], d["nodes"][1]["name"]
    return regrasp_cli("regrasp-sequence", write(tmp_path, "g.json", d), "--from", a, "--to", b)


def test_a_valid_graph_file_is_read(tmp_path, graph):
    status, err, _ = sequence(tmp_path, graph)
    assert status == 0, err


@pytest.mark.parametrize("change, field", [
    (lambda d: d["edges"][0].update(action="levitate"), "edges[0].action"),
    (lambda d: d["edges"][0].update(success_rate=5), "edges[0].success_rate"),
    (lambda d: d["edges"][0].update(success_rate=float("nan")), "edges[0].success_rate"),
    (lambda d: d["settings"].update(spread=float("nan")), "settings.spread"),
    (lambda d: d.update(version=True), "version"),
    (lambda d: d["nodes"].append(dict(d["nodes"][0])), "nodes[3].name"),
])
def test_nonsense_in_a_graph_file_is_refused(tmp_path, graph, change, field):
    d = json.loads(json.dumps(graph))
    change(d)
    refused(sequence(tmp_path, d), field)


def test_a_deeply_nested_graph_file_is_refused(tmp_path):
    status, err, _ = regrasp_cli("regrasp-sequence", write(tmp_path, "g.json", "[" * 100_000 + "]" * 100_000),
                                 "--from", "g0", "--to", "g1")
    assert status == 2 and "`graph`" in err and "nested" in err and "internal error" not in err, err


@pytest.mark.parametrize("text, depth", [
    ('{"a": [1, [2, {"b": "]]]]"}]]}', 4),  # brackets in strings do not count
    ('{"a": "\\"[[[["}', 1),  # nor after an escaped quote
    ('x = [[1], [2]] # [[[[[\ny = "[[["\nz = \'[[[[\'\nw = """\n[[[[\n"""', 2),  # nor in TOML comments and strings
])
def test_nesting_is_counted_outside_strings_and_comments(text, depth):
    assert nesting(text, toml="=" in text) == depth


def test_nesting_at_the_limit_is_read_and_one_deeper_is_refused(tmp_path):
    from regrasp.errors import ArgumentError
    from regrasp.files import parse_json, parse_toml

    assert parse_json("[" * MAX_NESTING + "]" * MAX_NESTING, "x") is not None
    assert parse_toml("x = " + "[" * (MAX_NESTING - 1) + "]" * (MAX_NESTING - 1), "x") is not None
    for text, parse in (("[" * (MAX_NESTING + 1) + "]" * (MAX_NESTING + 1), parse_json),
                        ("x = " + "[" * MAX_NESTING + "]" * MAX_NESTING, parse_toml),
                        ("a" + ".a" * (MAX_NESTING + 1) + " = 1", parse_toml)):  # dotted keys: depth after parsing
        with pytest.raises(ArgumentError, match="nested more than"):
            parse(text, "x")


@pytest.mark.parametrize("place, field", [("0.45,-0.2,-5,1,0,0,0", "place"),  # 5 m under the table
                                          ("50,0,0.8,1,0,0,0", "place")])  # beside it
def test_a_place_off_the_table_is_refused(place, field):
    refused(regrasp_cli("pick-place", SCENE, "--place", place, "--plan-only"), field)
