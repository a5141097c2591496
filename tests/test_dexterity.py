"""Extrinsic dexterity (regrasp.dexterity): the slip model against closed forms, the grasp graph
file, planning on the graph against brute force, the bundled objects, and (MuJoCo, the real
engine) the arm's actions: the pivot's break-away angle against the limit-surface prediction,
the actions that reach their intended grasp in the nominal world."""

from __future__ import annotations

import itertools
import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from regrasp.dexterity.graph import Edge, GraspGraph
from regrasp.dexterity.sequence import plan
from regrasp.dexterity.slip import Body, simulate
from regrasp.errors import ArgumentError

G = 9.81


def still(alpha=0.0):
    return lambda t: (np.zeros(2), alpha)


# --- the slip model --------------------------------------------------------------------------------


def test_a_gravity_slide_accelerates_at_g_less_the_pads_friction():
    m, mu = 0.2, 0.5
    N = 0.8 * m * G / (2 * mu)  # the pads carry 80 % of the weight: a = 0.2 g
    s = simulate(Body(m, 1e-4, (0.0, 0.0), 0.005, mu), 0.1, still(), lambda t: N, (0.0, -G))
    assert s.shift[1] == pytest.approx(-0.5 * 0.2 * G * 0.1 ** 2, rel=0.01)
    assert abs(s.shift[0]) < 1e-9 and abs(s.turn) < 1e-9


def test_inside_the_limit_surface_nothing_slips():
    m, mu, k, d = 0.2, 0.5, 0.005, 0.004
    N = 1.5 * m * G / (2 * mu) * math.hypot(1, d / k)  # (mg/2μN)² + (mgd/2kμN)² = 1/1.5² < 1
    s = simulate(Body(m, 1e-4, (d, 0.0), k, mu), 0.3, still(), lambda t: N, (0.0, -G))
    assert np.abs(s.shift).max() < 1e-7 and abs(s.turn) < 1e-5


def smooth(s: float) -> float:
    s = min(max(s, 0.0), 1.0)
    return s * s * (3 - 2 * s)


@pytest.mark.parametrize("lag_deg", [20.0, 35.0])
def test_a_hanging_object_breaks_away_from_the_turning_hand_at_the_limit_surface_angle(lag_deg):
    # at the grip where (m g / 2μN)² + (m g d sin φ / 2kμN)² = 1 the hanging object turns with the
    # hand until its centre of mass is φ from the vertical, then slips (and swings back: dynamics)
    m, mu, k, d, lag = 0.2, 0.5, 0.006, 0.02, math.radians(lag_deg)
    N = m * G * math.sqrt(1 + (d * math.sin(lag) / k) ** 2) / (2 * mu)
    T = 2.0  # the hand turns by 90° about the grasp axis (through the contact centre, the origin)
    angles = []
    simulate(Body(m, 1e-5, (0.0, -d), k, mu), T, lambda t: (np.zeros(2), 0.5 * math.pi * smooth(t / T)),
             lambda t: N, (0.0, -G), observe=lambda t, x: angles.append(math.degrees(math.atan2(x[0], -x[1]))))
    assert max(angles) == pytest.approx(lag_deg, abs=1.5)


# --- the graph file and planning on it --------------------------------------------------------------


def graph_of(edges, names=("g0", "g1", "g2", "g3")):
    nodes = [{"name": n} for n in names]
    return GraspGraph({"name": "t", "file": ""}, nodes, edges, [], {})


def edge(a, b, action, hits, trials=20, **more):
    out = {b: hits, **more}
    rest = trials - sum(out.values())
    if rest:
        out["dropped"] = out.get("dropped", 0) + rest
    return Edge(a, action, b, trials, out)


def test_the_graph_file_round_trips(tmp_path):
    g = graph_of([edge("g0", "g1", "gravity-slide", 15), edge("g1", "g2", "push-down", 20)])
    path = g.save(tmp_path / "g.json")
    back = GraspGraph.load(path)
    assert back.to_dict() == json.loads(path.read_text()) == g.to_dict()
    assert back.edges[0].success_rate == 0.75


@pytest.mark.parametrize("change, field", [
    (lambda d: d.update(format="x"), "format"),
    (lambda d: d.update(version=9), "version"),
    (lambda d: d.pop("nodes"), "nodes"),
    (lambda d: d["edges"][0].update(to="g9"), "edges[0].to"),
    (lambda d: d["edges"][0].update(trials=3), "edges[0].outcomes"),
    (lambda d: d["edges"][0].pop("action"), "edges[0]"),
])
def test_a_bad_graph_file_names_its_field(tmp_path, change, field):
    d = graph_of([edge("g0", "g1", "gravity-slide", 15)]).to_dict()
    change(d)
    with pytest.raises(ArgumentError) as e:
        GraspGraph.from_dict(d)
    assert e.value.field == field


def brute_force(g, start, goal):
    """The largest product of transition probabilities over every simple path (every outcome a transition)."""
    best = {}
    for e in g.edges:
        for o, c in e.outcomes.items():
            if o in g.node_names and o != e.source and c:
                best[(e.source, o)] = max(best.get((e.source, o), 0.0), c / e.trials)
    others = [n for n in g.node_names if n not in (start, goal)]
    out = 0.0
    for r in range(len(others) + 1):
        for mid in itertools.permutations(others, r):
            path = (start, *mid, goal)
            p = math.prod(best.get(uv, 0.0) for uv in zip(path, path[1:]))
            out = max(out, p)
    return out


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.integers(0, 4), st.integers(0, 4), st.integers(1, 20), st.integers(0, 4)),
                min_size=1, max_size=12))
def test_the_most_reliable_sequence_is_the_brute_force_one(raw):
    names = [f"g{i}" for i in range(5)]
    edges = []
    for a, b, hits, other in raw:
        if a == b:
            continue
        out = {names[b]: hits}
        if other not in (a, b) and hits < 20:
            out[names[other]] = 1  # a useful side outcome counts as a transition too
        rest = 20 - sum(out.values())
        if rest:
            out["dropped"] = rest
        edges.append(Edge(names[a], "gravity-slide", names[b], 20, out))
    g = graph_of(edges, names)
    truth = brute_force(g, "g0", "g4")
    if truth == 0.0:
        with pytest.raises(ArgumentError) as e:
            plan(g, "g0", "g4")
        assert e.value.field == "to"
    else:
        s = plan(g, "g0", "g4")
        assert s.probability == pytest.approx(truth, rel=1e-12)
        assert [x.source for x in s.steps][0] == "g0" and s.steps[-1].target == "g4"


def test_planning_refuses_unknown_grasps_and_objectives():
    g = graph_of([edge("g0", "g1", "gravity-slide", 15)])
    for kw, field in ((dict(start="g9", goal="g1"), "from"), (dict(start="g0", goal="g9"), "to")):
        with pytest.raises(ArgumentError) as e:
            plan(g, kw["start"], kw["goal"])
        assert e.value.field == field
    with pytest.raises(ArgumentError) as e:
        plan(g, "g0", "g1", "fastest")
    assert e.value.field == "objective"
