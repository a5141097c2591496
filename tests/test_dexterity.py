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

import regrasp
from regrasp.dexterity.actions import ACTIONS
from regrasp.dexterity.graph import Chain, Edge, GraspGraph
from regrasp.dexterity.objects import load_object
from regrasp.dexterity.taxonomy import taxonomy_of
from regrasp.fields import MAX_GRAPH_NODES
from regrasp.dexterity.sequence import plan
from regrasp.dexterity.slip import Body, simulate
from regrasp.errors import ArgumentError, SceneError

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
    grasps = taxonomy_of(load_object("box")).grasps
    nodes = [dict(grasps[i].to_dict(), name=n) for i, n in enumerate(names)]
    return GraspGraph({"name": "t", "file": ""}, nodes, edges, [ACTIONS[a].to_dict() for a in sorted({e.action for e in edges})],
                      {})


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
    (lambda d: d.update(edges=5), "edges"),
    (lambda d: d.update(object=[1]), "object"),
    (lambda d: d.update(seconds="x"), "seconds"),
    (lambda d: d["nodes"][0].update(name=["g0"]), "nodes"),
    (lambda d: d["edges"][0].update(outcomes={"g1": 25, "dropped": -5}), "edges[0].outcomes"),
    (lambda d: d["edges"][0].update(outcomes={"g1": 15, "g9": 5}), "edges[0].outcomes"),
    (lambda d: d["edges"][0].update(trials=20.9), "edges[0].trials"),
    # nonsense a file could hold (issue 44): unknown actions, rates outside [0, 1], NaN settings, ...
    (lambda d: d["edges"][0].update(action="levitate"), "edges[0].action"),
    (lambda d: d.update(actions=[{"name": "levitate"}]), "actions[0]"),
    (lambda d: d.update(actions=["gravity-slide"]), "actions[0]"),
    (lambda d: d["actions"][0].update(name=[1e300]), "actions[0]"),  # not a name (found by the fuzz suite)
    (lambda d: d.update(seconds=10**400), "seconds"),  # too large for a float
    (lambda d: d["edges"][0].update(success_rate=5), "edges[0].success_rate"),
    (lambda d: d["edges"][0].update(success_rate=float("nan")), "edges[0].success_rate"),
    (lambda d: d["edges"][0].update(success_rate=0.5), "edges[0].success_rate"),
    (lambda d: d["settings"].update(spread=float("nan")), "settings.spread"),
    (lambda d: d["settings"].update(spread=3), "settings.spread"),
    (lambda d: d["settings"].update(trials=0), "settings.trials"),
    (lambda d: d["settings"].update(actions=["levitate"]), "settings.actions"),
    (lambda d: d["settings"].update(warp=1), "settings.warp"),
    (lambda d: d.update(version=True), "version"),
    (lambda d: d["nodes"].append({"name": "g0"}), "nodes[4].name"),
    (lambda d: d.update(seconds=-1), "seconds"),
    (lambda d: d["edges"][0].update(seconds=float("inf")), "edges[0].seconds"),
    (lambda d: d.update(nodes=[{"name": f"n{i}"} for i in range(MAX_GRAPH_NODES + 1)]), "nodes"),
    (lambda d: d["nodes"][1].update(width=float("nan")), "nodes[1].width"),
    (lambda d: d["nodes"][1].update(pose=[1e308, 0, 0, 1, 0, 0, 0]), "nodes[1].pose"),
    (lambda d: d["nodes"][1].pop("label"), "nodes[1].label"),
    (lambda d: d["nodes"][1].update(clearance=-11), "nodes[1].clearance"),
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


# --- chained measurements: each action from where the one before left the object ----------------


def chained_graph():
    """g0 -a-> g1 (from g1's own pose, b reaches g3 19 times in 20, but after a only 2) and g0 -c-> g2 -d-> g3."""
    pose = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]
    a = Edge("g0", "gravity-slide", "g1", 20, {"g1": 20}, runs=[("g1", np.array(pose), (1.0, 0.9, 1.1))] * 20)
    b = edge("g1", "g3", "push-down", 19)
    c = edge("g0", "g2", "inertial-slide", 16)
    d = edge("g2", "g3", "drop-catch", 16)
    g = graph_of([a, b, c, d])
    g.chained = [Chain(0, 1, 20, {"g3": 2, "dropped": 18})]
    return g


def test_a_chained_rate_replaces_the_edges_own_after_the_action_it_was_measured_after(tmp_path):
    g = chained_graph()
    s = plan(g, "g0", "g3")  # alone: 1.0 × 0.95 beats 0.8 × 0.8; after the slide the push reaches g3 2 in 20
    assert [(x.source, x.action, x.target) for x in s.steps] == [("g0", "inertial-slide", "g2"),
                                                               ("g2", "drop-catch", "g3")]
    assert s.probability == pytest.approx(0.64) and s.independent == pytest.approx(0.64)
    s = plan(g, "g1", "g3")  # from g1's own pose the chain does not apply
    assert s.probability == pytest.approx(0.95) and not s.steps[0].chained
    g.chained = []
    s = plan(g, "g0", "g3")
    assert s.probability == pytest.approx(0.95) and [x.action for x in s.steps] == ["gravity-slide", "push-down"]
    g = chained_graph()
    g.chained[0].outcomes = {"g3": 20}
    s = plan(g, "g0", "g3")
    assert s.steps[1].chained and s.steps[1].alone == pytest.approx(0.95)
    assert s.probability == pytest.approx(1.0) and s.independent == pytest.approx(0.95)
    back = GraspGraph.load(g.save(tmp_path / "g.json"))
    assert back.to_dict() == g.to_dict() and plan(back, "g0", "g3").probability == pytest.approx(1.0)


def brute_force_chained(g, start, goal, depth):
    """The largest product over every walk of at most ``depth`` measured edges from ``start`` to
    ``goal`` (each outcome a transition), a step's rate the chain's after the walk's previous edge."""
    chains = {(c.after, c.edge): c for c in g.chained}
    best = 0.0

    def walk(at, prev, p, n):
        nonlocal best
        if at == goal and n:
            best = max(best, p)
            return
        if n == depth:
            return
        for j, e in enumerate(g.edges):
            if e.source != at or not e.trials:
                continue
            c = chains.get((prev, j)) if prev is not None else None
            counts, trials = (c.outcomes, c.trials) if c else (e.outcomes, e.trials)
            for o, k in counts.items():
                if o in g.node_names and o != at and k:
                    walk(o, j, p * k / trials, n + 1)

    walk(start, None, 1.0, 0)
    return best


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.integers(0, 3), st.integers(0, 3), st.integers(1, 10)), min_size=1, max_size=7),
       st.lists(st.tuples(st.integers(0, 6), st.integers(0, 6), st.integers(0, 10)), max_size=10))
def test_the_most_reliable_chained_sequence_is_the_brute_force_one(raw, raw_chains):
    names = [f"g{i}" for i in range(4)]
    edges = [Edge(names[a], "gravity-slide", names[b], 10, {names[b]: h, **({"dropped": 10 - h} if h < 10 else {})})
             for a, b, h in raw if a != b]
    assume = [(i, j, h) for i, j, h in raw_chains if i < len(edges) and j < len(edges)
              and edges[i].target == edges[j].source]
    g = graph_of(edges, names)
    g.chained = list({(i, j): Chain(i, j, 10, {edges[j].target: h, **({"other": 10 - h} if h < 10 else {})})
                      for i, j, h in assume}.values())
    truth = brute_force_chained(g, "g0", "g3", 2 * len(edges) + 1)
    if truth == 0.0:
        with pytest.raises(ArgumentError):
            plan(g, "g0", "g3")
    else:
        assert plan(g, "g0", "g3").probability == pytest.approx(truth, rel=1e-12)


@pytest.mark.parametrize("change, field", [
    (lambda d: d["chained"][0].update(after=7), "chained[0].after"),
    (lambda d: d["chained"][0].update(edge=-1), "chained[0].edge"),
    (lambda d: d["chained"][0].update(after=2), "chained[0]"),  # g0 -c-> g2 never reached g1
    (lambda d: d["chained"][0].update(outcomes={"g3": 3}), "chained[0].outcomes"),
    (lambda d: d["chained"][0].pop("trials"), "chained[0]"),
    (lambda d: d["chained"][0].update(trials=19, outcomes={"g3": 19}), "chained[0].trials"),
    (lambda d: d["edges"][0]["runs"][0].update(world=[1.0, 0.0, 1.0]), "edges[0].runs[0]"),
    (lambda d: d.update(chained={}), "chained"),
    (lambda d: d["chained"][0].update(outcomes={"g3": 2, "g9": 18}), "chained[0].outcomes"),
    (lambda d: d["chained"].append(dict(d["chained"][0])), "chained[1]"),
    (lambda d: d["edges"][0]["runs"].pop(), "edges[0].runs"),
    (lambda d: d["edges"][0]["runs"][0].update(pose=[0.0] * 6), "edges[0].runs[0]"),
    (lambda d: d["edges"][0]["runs"][0].update(outcome="g2"), "edges[0].runs"),
])
def test_a_bad_chained_graph_file_names_its_field(change, field):
    d = json.loads(json.dumps(chained_graph().to_dict()))
    change(d)
    with pytest.raises(ArgumentError) as e:
        GraspGraph.from_dict(d)
    assert e.value.field == field


def test_a_start_pose_in_the_hand_is_where_the_world_starts_the_object():
    # a trial from a given pose is the trial from the grasp when that pose is the grasp's, run for
    # run (the same world, deterministic); a pose 4 mm further along the fingers starts there
    from regrasp.dexterity.objects import load_object
    from regrasp.dexterity.actions import WORK_POINT, hand_pose
    from regrasp.dexterity.taxonomy import taxonomy_of
    from regrasp import Perturbation
    from regrasp.dexterity.world import HandWorld
    from regrasp.pose import compose

    scene = load_object("bar")
    g = taxonomy_of(scene).grasp("g9")
    w = HandWorld(scene, g.pose, hand_pose(0.0, WORK_POINT))
    a = w.reset(Perturbation(finger_friction=0.9, grip=1.1)).in_hand()
    b = w.reset(Perturbation(finger_friction=0.9, grip=1.1, pose=tuple(g.pose))).in_hand()
    assert np.array_equal(a, b)
    moved = compose(np.array([0.0, 0.0, 0.004, 1.0, 0.0, 0.0, 0.0]), g.pose)
    c = w.reset(Perturbation(pose=tuple(moved))).in_hand()
    assert np.linalg.norm(c[:3] - moved[:3]) < 5e-4 and np.linalg.norm(c[:3] - a[:3]) > 3.5e-3


def test_a_chained_graph_continues_each_run_that_reached_a_grasp_with_each_action_from_it(tmp_path):
    # the bar's lateral g9: gravity pivot to g0, then from g0 the gravity pivot on to g8 — continued
    # from the first's end poses, in its worlds (the real engine, one nominal run and two perturbed)
    from regrasp.dexterity.graph import Settings, build_graph, chains_to_measure, continuations, run_edge
    from regrasp.dexterity.objects import object_path

    path = str(object_path("bar"))
    g = build_graph(path, Settings(trials=3, actions=("gravity-pivot",), chain=True))
    assert g.settings["chain"] and all(len(e.runs) == e.trials for e in g.edges)
    for e in g.edges:
        for o, pose, world in e.runs:
            assert (pose is None) == (o == "dropped") and len(world) == 3
    pairs = [(c.after, c.edge) for c in g.chained]
    assert pairs == chains_to_measure(g.edges) and pairs, [e.to_dict() for e in g.edges]
    for c in g.chained:
        ends = g.edges[c.after].ends(g.edges[c.edge].source)
        assert c.trials == len(ends) == g.edges[c.after].outcomes[g.edges[c.edge].source]
        assert [(w.friction, w.grip, w.mass) for w in continuations(ends)] == [w for _, w in ends]
    # a chain's runs are the edge's runs from those worlds: run again, they end where they did
    c = g.chained[0]
    ends = g.edges[c.after].ends(g.edges[c.edge].source)
    e = g.edges[c.edge]
    a = g.edges[c.after]
    again = run_edge((path, e.source, e.action, e.params, Settings(), None, ends, (a.source, a.action, a.params)))
    assert again.outcomes == c.outcomes and again.trials == c.trials
    back = GraspGraph.load(g.save(tmp_path / "g.json"))
    assert back.to_dict() == g.to_dict()


# --- the bundled objects ------------------------------------------------------------------------------


def test_the_bundled_objects_load_without_task_or_pushers():
    from regrasp.dexterity.objects import OBJECTS, load_object
    from regrasp.dexterity.taxonomy import taxonomy_of

    counts = {}
    for name in OBJECTS:
        scene = load_object(name)
        counts[name] = len(taxonomy_of(scene).grasps)
    # prism: 2 orientations x 3 offsets; cylinder: ends 1 x 3, across 2 x 3; box: 3 face pairs x 2 x 3;
    # bar: 2 face pairs (its ends are 120 mm apart, beyond the 85 mm opening) x 2 x (3 offsets + 2 lateral)
    assert counts == {"prism": 6, "cylinder": 9, "box": 18, "bar": 20}


def test_a_bad_object_file_names_its_field(tmp_path):
    from regrasp.dexterity.objects import load_object
    from regrasp.errors import SceneError

    p = tmp_path / "o.toml"
    p.write_text('name = "x"\n[object]\nshape = "box"\nsize = [0.04, 0.03, 0.07]\nmass = 0.2\n'
                 '[grasp]\nforce = 5.0\nfriction = 0.5\npad_radius = 0.008\n')
    with pytest.raises(SceneError) as e:
        load_object(p)
    assert e.value.field == "dimension"
    p.write_text(p.read_text().replace('name = "x"', 'dimension = 3\nname = "x"').replace("mass = 0.2", "mass = -1"))
    with pytest.raises(SceneError) as e:
        load_object(p)
    assert e.value.field == "object.mass"
    p.write_text(p.read_text().replace("mass = -1", "mass = 0.2") + "[taxonomy]\nlateral = [0.6]\n")
    with pytest.raises(SceneError) as e:
        load_object(p)
    assert e.value.field == "taxonomy.lateral" and "0.5" in str(e.value)
    p.write_text(p.read_text().replace("lateral = [0.6]", "sideways = [0.3]"))
    with pytest.raises(SceneError) as e:
        load_object(p)
    assert e.value.field.startswith("taxonomy")


def test_a_slide_along_the_fingers_keeps_a_lateral_grasp_lateral():
    from regrasp.dexterity.actions import ACTIONS, ObjectModel, turn_target
    from regrasp.dexterity.objects import load_object
    from regrasp.dexterity.taxonomy import taxonomy_of

    scene = load_object("bar")
    tax = taxonomy_of(scene)
    obj = ObjectModel.of(scene, tax)
    g9 = tax.grasp("g9")  # 42 mm off its centre across the fingers: no grasp along the fingers at that lateral
    assert g9.lateral == pytest.approx(0.042) and g9.offset == 0
    for name in ("gravity-slide", "inertial-slide", "drop-catch"):
        assert "no grasp further" in ACTIONS[name].applies(obj, g9)
    turn, target, _ = turn_target(obj, g9)  # a quarter turn hangs it along the fingers
    assert turn == pytest.approx(-np.pi / 2) and tax.grasp(target).offset == pytest.approx(-0.042)


# --- in MuJoCo, with the arm ----------------------------------------------------------------------------

mujoco = pytest.importorskip("mujoco")
pytest.importorskip("mink")


@pytest.fixture(scope="module")
def box():
    from regrasp.dexterity.actions import ObjectModel
    from regrasp.dexterity.objects import load_object
    from regrasp.dexterity.taxonomy import taxonomy_of

    scene = load_object("box")
    tax = taxonomy_of(scene)
    return scene, tax, ObjectModel.of(scene, tax)


def test_a_grasp_whose_object_goes_into_the_fingers_links_does_not_fit(box):
    from regrasp.dexterity.graph import FIT, fitting

    scene, tax, obj = box
    clear = fitting(scene, tax)
    # g1: the 70 mm side along the fingers, 40 mm across the pads: the 2F-85's spring links close in
    # above the pads and hold the box instead of them (MuJoCo: its only contacts are with the links)
    assert clear["g1"] < 0 and clear["g6"] > FIT


def test_the_pivot_breaks_away_at_the_limit_surface_angle_in_mujoco(box):
    # the hanging box (g0: its centre of mass 23 mm below the pads' patch) at the grip where the
    # limit surface lets it lag 30° behind the hand: the hand turns 90°; the largest lag is 30°
    from regrasp import pose as P
    from regrasp.dexterity.actions import RAMP, GripPivot, _angle, com_in_hand, contact_centre, hand_pose
    from regrasp.dexterity.world import HandPath, HandWorld, ramps, solve_path

    scene, tax, obj = box
    g = tax.grasp("g0")
    lag = math.radians(30.0)
    N = GripPivot().grip_for_lag(obj, g, lag)
    c, centre = com_in_hand(obj, g), contact_centre(obj, g)
    a0, T = float(np.angle(np.exp(1j * (-np.pi / 2 - _angle(c))))), 1.5
    times = np.linspace(0.0, T + 2 * RAMP, int((T + 2 * RAMP) / 0.01) + 1)
    path = HandPath(times, np.array([hand_pose(a0 + 0.5 * math.pi * smooth((t - RAMP) / T)) for t in times]))
    world = HandWorld(scene, g.pose, path.poses[0])
    lags = []

    def observe(w):
        v = P.transform(w.object_pose(), obj.com) - P.transform(w.hand_frame(), [centre[0], 0.0, centre[1]])
        lags.append(math.degrees(math.atan2(v[0], -v[2])))

    world.follow(path, solve_path(world.robot, path, world.robot.q), ramps((0, obj.grip), (RAMP, N)), 0.0, observe)
    assert max(lags) == pytest.approx(30.0, abs=4.0)


@pytest.mark.parametrize("name, grasp, action, params", [
    ("box", "g4", "gravity-slide", {}),
    ("box", "g4", "inertial-slide", {}),
    ("box", "g7", "drop-catch", {}),
    ("box", "g7", "toss-catch", {}),
    ("box", "g7", "table-slide", {}),
    ("prism", "g4", "table-slide", {}),
    ("box", "g6", "post-push", {}),
    ("box", "g6", "place-repick", {"target": "g12"}),
    ("box", "g12", "place-repick", {"target": "g6"}),  # another width: the TCP corrected for the linkage
    ("box", "g7", "topple-repick", {"target": "g12"}),
    ("prism", "g1", "table-pivot", {}),
    ("bar", "g9", "gravity-pivot", {}),  # held 42 mm off its centre across the fingers: a quarter turn hangs it
    ("bar", "g0", "grip-pivot", {}),  # hanging along the fingers: the turning hand lifts it sideways
])
def test_an_action_reaches_its_intended_grasp_in_the_nominal_world(name, grasp, action, params):
    from regrasp.dexterity.actions import ACTIONS, ObjectModel
    from regrasp.dexterity.objects import load_object
    from regrasp.dexterity.taxonomy import taxonomy_of
    from regrasp.dexterity.trial import Runner

    scene = load_object(name)
    tax = taxonomy_of(scene)
    obj = ObjectModel.of(scene, tax)
    g = tax.grasp(grasp)
    assert ACTIONS[action].applies(obj, g) is None
    setup = ACTIONS[action].setup(obj, g, params)
    assert setup.intended not in (None, grasp)
    r = Runner(scene, tax, g, setup).run()
    assert r.outcome == setup.intended, (r.outcome, r.distance)


@pytest.mark.parametrize("action", ["drop-catch", "toss-catch"])
def test_a_catch_lands_where_the_release_model_predicts(box, action):
    # the fall (½ g t²) or the flight (½ (b − g) t²) over the free time measured from the gripper's
    # release (a δ + b) is what MuJoCo does, within a fifth of it
    from regrasp.dexterity.actions import ACTIONS
    from regrasp.dexterity.trial import Runner

    scene, tax, obj = box
    g = tax.grasp("g7")
    setup = ACTIONS[action].setup(obj, g)
    predicted = setup.detail["fall" if action == "drop-catch" else "fly"]
    r = Runner(scene, tax, g, setup).run()
    from regrasp import pose as P

    moved = -P.compose(r.pose, P.inverse(g.pose))[2]  # along the fingers, towards their tips
    assert predicted > 0.005
    assert moved == pytest.approx(predicted, rel=0.2)


def test_a_table_slide_moves_the_object_in_the_hand_by_the_hands_rise(box):
    # the table, not a timed fall, sets the distance: the object stays on it while the pads slide up
    # it, so MuJoCo's slide is the hand's rise (one offset step) within 1 mm, and the object ends
    # no higher in the world than it stood
    from regrasp import pose as P
    from regrasp.dexterity.actions import ACTIONS
    from regrasp.dexterity.trial import Runner

    scene, tax, obj = box
    g = tax.grasp("g7")
    setup = ACTIONS["table-slide"].setup(obj, g)
    heights = []
    runner = Runner(scene, tax, g, setup)
    r = runner.run(observe=lambda w: heights.append((float(w.robot.data.time), float(w.object_pose()[2]))))
    moved = -P.compose(r.pose, P.inverse(g.pose))[2]  # along the fingers, towards their tips
    assert setup.detail["slide"] > 0.005
    assert moved == pytest.approx(setup.detail["slide"], abs=1e-3)
    t, z = np.array(heights).T
    t -= t[0]
    standing = (t > setup.detail["stand"][0]) & (t < setup.detail["stand"][1])  # from the touch to the lift
    assert standing.sum() > 100 and np.ptp(z[standing]) < 1e-3


def test_a_table_slide_needs_the_gripper_to_come_down_to_its_grip(box):
    from regrasp.dexterity.actions import ACTIONS

    scene, tax, obj = box
    g = tax.grasp("g13")  # 70 mm wide: the 2F-85's linkage springs alone press more than the slide's grip
    why = ACTIONS["table-slide"].applies(obj, g)
    assert why is not None and "presses at least" in why
    with pytest.raises(ArgumentError) as e:
        ACTIONS["table-slide"].setup(obj, g)
    assert e.value.field == "grasp" and "g13" in str(e.value)
    with pytest.raises(ArgumentError) as e:  # the table must keep part of the weight
        ACTIONS["table-slide"].setup(obj, tax.grasp("g7"), {"rest_ratio": 1.2})
    assert e.value.field == "params.rest_ratio"


def test_the_release_line_predicts_an_opening_it_was_not_fitted_on(box):
    # the free time a δ + b, fitted at 4–20 ms, at δ = 10 ms against MuJoCo's, within 2 ms;
    # openings outside the measured range are clamped into it
    from regrasp.dexterity.actions import hand_pose, release
    from regrasp.dexterity.world import OPEN, RELEASE_AT, HandWorld, release_timing

    scene, tax, obj = box
    g = tax.grasp("g7")
    rel = release(obj, g)
    assert rel.a > 0 and (rel.low, rel.high) == (0.004, 0.020)
    assert rel.opening(1.0) == rel.high and rel.opening(0.0) == rel.low
    w = HandWorld(scene, g.pose, hand_pose(0.0))
    loose: list = []
    force = w.grip_force
    w.wait(RELEASE_AT + 0.13, lambda t: OPEN if RELEASE_AT <= t < RELEASE_AT + 0.010 else force,
           lambda w: loose.append(w.robot.data.time) if w.loose() else None)
    assert w.held()
    assert loose[-1] - loose[0] == pytest.approx(rel.free(0.010), abs=0.002)
    with pytest.raises(ArgumentError) as e:
        release_timing(w, (0.01, 0.01))
    assert e.value.field == "releases"
    with pytest.raises(SceneError) as e:  # opened this long, the object falls out every time
        release_timing(w, (0.2, 0.3))
    assert e.value.field == "grasp"


def test_the_release_is_the_grippers_fingers_up_as_down(box):
    # the toss (fingers up) uses the release measured fingers down: the free times agree within
    # 2 ms over the measured openings
    from regrasp.dexterity.actions import hand_pose, release
    from regrasp.dexterity.world import HandWorld, release_timing

    scene, tax, obj = box
    g = tax.grasp("g7")
    down = release(obj, g)
    up = release_timing(HandWorld(scene, g.pose, hand_pose(np.pi)))
    for delta in np.linspace(max(down.low, up.low), min(down.high, up.high), 5):
        assert up.free(delta) == pytest.approx(down.free(delta), abs=0.002)


@pytest.mark.parametrize("friction, ratio, found", [(0.5, 1.6, False), (0.5, 2.4, True), (1.0, 1.6, True)])
def test_the_post_push_is_planned_where_the_posts_friction_carries_the_weight(box, friction, ratio, found):
    # the pads slide, so the post's friction, pressed by their friction 2 μ N = ratio · m g, must
    # carry the weight across the push: μ_post · ratio ≥ 1 (at μ_post 0.5: ratio ≥ 2; at 1.0, ≥ 1)
    from regrasp import pose as P
    from regrasp.dexterity.actions import post_scene

    scene, tax, obj = box
    g, deeper = tax.grasp("g6"), tax.grasp("g7")
    plan = post_scene(obj, g.pose, deeper.pose, obj.holding(ratio), friction=friction).plan(
        seed=0, max_iterations=20, time_limit=60.0)
    assert plan.found == found
    if found:  # the push ends at the deeper grasp, every step inside the motion cone
        assert plan.valid
        assert np.linalg.norm(P.compose(plan.poses[-1], P.inverse(deeper.pose))[:3]) < 1.5e-3


def test_actions_refuse_a_grasp_they_do_not_apply_to_naming_it(box):
    from regrasp.dexterity.actions import ACTIONS, post_scene

    scene, tax, obj = box
    shallow, deep = tax.grasp("g6"), tax.grasp("g8")  # the outermost and the deepest of one face pair and turn
    for name in ("gravity-slide", "drop-catch", "toss-catch", "table-slide"):
        assert ACTIONS[name].applies(obj, shallow) is not None
        with pytest.raises(ArgumentError) as e:
            ACTIONS[name].setup(obj, shallow)
        assert e.value.field == "grasp" and "g6" in str(e.value)
    for name in ("inertial-slide", "push-down", "post-push"):
        assert ACTIONS[name].applies(obj, deep) is not None
        with pytest.raises(ArgumentError) as e:
            ACTIONS[name].setup(obj, deep)
        assert e.value.field == "grasp" and "g8" in str(e.value)
    with pytest.raises(ArgumentError) as e:  # counts are whole
        ACTIONS["post-push"].setup(obj, shallow, {"plan_iterations": 0.5})
    assert e.value.field == "params.plan_iterations"
    path, scene.path = scene.path, None  # a scene that was not loaded from a file
    try:
        with pytest.raises(ArgumentError) as e:
            post_scene(obj, shallow.pose, deep.pose, obj.grip)
        assert e.value.field == "scene"
    finally:
        scene.path = path


def test_a_topple_rolls_the_outline_towards_its_centre_of_mass():
    from regrasp.dexterity.actions import _topple

    square = np.array([[0.0, 0.0], [0.02, 0.0], [0.02, 0.02], [0.0, 0.02]])
    for a, turn in ((0.3, -0.3), (1.2, math.pi / 2 - 1.2)):  # turned by a (x towards z) onto its corner (0, 0)
        tilted = square @ np.array([[math.cos(a), math.sin(a)], [-math.sin(a), math.cos(a)]])
        tilted[:, 1] -= tilted[:, 1].min()
        got, pivot = _topple(tilted, tilted.mean(axis=0))
        # by less than 45° it falls back onto its face (clockwise), by more onto the next one (counter-clockwise)
        assert got == pytest.approx(turn) and np.allclose(pivot, tilted[np.argmin(tilted[:, 1])])
    assert _topple(square, square.mean(axis=0))[0] == 0.0  # flat: it stays


def test_a_table_pivot_that_would_take_the_object_into_the_table_does_not_apply(box):
    from regrasp.dexterity.actions import ACTIONS, turn_target

    scene, tax, obj = box
    g = tax.grasp("g6")  # its next orientation is half a turn away: about any vertex, through the table
    assert abs(turn_target(obj, g)[0]) == pytest.approx(math.pi)
    assert "into the table" in ACTIONS["table-pivot"].applies(obj, g)


def test_a_planned_repick_is_executed_towards_the_grasp_it_was_measured_for(tmp_path):
    # topple-repick from the box's g7 has two new grasps (g12 first); the plan to g6 must run the g6 one
    import dataclasses

    from regrasp.dexterity.graph import _object
    from regrasp.dexterity.objects import object_path
    from regrasp.execution import World, execute

    g = graph_of([Edge("g7", "topple-repick", "g12", 20, {"g12": 20}, {"target": "g12"}),
                  Edge("g7", "topple-repick", "g6", 20, {"g6": 20}, {"target": "g6"})], ("g6", "g7", "g12"))
    s = plan(g, "g7", "g6")
    assert [(x.action, x.params) for x in s.steps] == [("topple-repick", {"target": "g6"})]
    with pytest.raises(regrasp.ArgumentError) as e:  # planned on a graph without its object file
        execute(World(regrasp.load_scene(regrasp.examples.path("block-3d")), rig="arm"), s)
    assert e.value.field == "plan"
    s = dataclasses.replace(s, object=str(object_path("box")))
    scene, tax, _ = _object(s.object)
    for world, field in ((World(scene), "world.rig"), (World(regrasp.load_scene(regrasp.examples.path("block-3d")),
                                                              rig="arm"), "world.scene")):
        with pytest.raises(regrasp.ArgumentError) as e:
            execute(world, s)
        assert e.value.field == field
    x = execute(World(scene, rig="arm"), s)  # the one executor runs a sequence of regrasp actions too
    assert x.detail.outcomes == ("g6",) and x.success
    assert x.steps == [{"action": "topple-repick", "from": "g7", "to": "g6", "reached": "g6"}]
    name, d = tax.nearest(x.final_pose)  # judged against the goal grasp: the classification's own distance
    assert name == "g6" and x.goal_error == pytest.approx([d], abs=1e-12)


def run_cli(*args):
    import subprocess
    import sys

    return subprocess.run([sys.executable, "-m", "regrasp", *args], capture_output=True, text=True, timeout=600)


def test_the_cli_measures_a_graph_and_plans_on_it(tmp_path):
    out = tmp_path / "g.json"
    r = run_cli("grasp-graph", "box", "--trials", "1", "--actions", "gravity-slide", "--workers", "1", "--out",
                str(out), "--json", "--chain")
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    assert {"nodes", "edges", "actions", "chained"} <= set(d) and d["edges"]
    assert all({"after", "edge", "trials", "outcomes"} <= set(c) and c["trials"] == 1 for c in d["chained"])
    assert GraspGraph.load(out).settings["chain"]
    assert all({"from", "to", "action", "success_rate", "trials"} <= set(e) for e in d["edges"])
    assert [a["name"] for a in d["actions"]] == ["gravity-slide"]
    hits = [e for e in d["edges"] if e["success_rate"] > 0]
    assert hits, d["edges"]  # one nominal run per edge: the gravity slide reaches its grasp on some
    e = hits[0]
    r = run_cli("regrasp-sequence", str(out), "--from", e["from"], "--to", e["to"], "--json")
    assert r.returncode == 0, r.stderr
    s = json.loads(r.stdout)["sequence"]
    assert s["steps"][0]["from"] == e["from"] and s["steps"][-1]["to"] == e["to"] and 0 < s["probability"] <= 1
    assert 0 < s["independent"] <= 1 and all({"chained", "alone", "params"} <= set(x) for x in s["steps"])


@pytest.mark.parametrize("args, field", [
    (["grasp-graph", "box", "--trials", "0"], "--trials"),
    (["grasp-graph", "box", "--actions", "juggle"], "actions"),
    (["grasp-graph", "no-such-object.toml"], "`object`"),
    (["grasp-graph", "box", "--out", "g.txt"], "--out"),
])
def test_bad_grasp_graph_input_is_refused_naming_the_field(args, field):
    r = run_cli(*args)
    assert r.returncode == 2 and field in r.stderr and "Traceback" not in r.stderr, r.stderr


def test_bad_regrasp_sequence_input_is_refused_naming_the_field(tmp_path):
    g = graph_of([edge("g0", "g1", "gravity-slide", 15)])
    g.save(tmp_path / "g.json")
    (tmp_path / "bad.json").write_text("{}")
    for args, field in ((["--from", "g0", "--to", "g7"], "to"), (["--from", "g5", "--to", "g1"], "from")):
        r = run_cli("regrasp-sequence", str(tmp_path / "g.json"), *args)
        assert r.returncode == 2 and f"`{field}`" in r.stderr, r.stderr
    r = run_cli("regrasp-sequence", str(tmp_path / "bad.json"), "--from", "g0", "--to", "g1")
    assert r.returncode == 2 and "`format`" in r.stderr, r.stderr


def test_a_transfer_the_arm_cannot_turn_in_place_goes_through_the_hand_level_above():
    # fingers up (a toss's end) to fingers down (an inertial slide's start) at the work point:
    # the straight turn has no IK; the transfer lifts the hand and turns it level on the way
    from regrasp.dexterity.actions import WORK_POINT, hand_pose
    from regrasp.dexterity.objects import load_object
    from regrasp.dexterity.trial import TRANSFER_LIFT, _line, transfer
    from regrasp.dexterity.taxonomy import taxonomy_of
    from regrasp.dexterity.world import HandWorld, solve_path
    from regrasp.robot.ik import IKError

    scene = load_object("prism")
    g = taxonomy_of(scene).grasp("g3")
    up, down = hand_pose(np.pi, WORK_POINT + np.array([0.0, 0.0, 0.095])), hand_pose(0.0, WORK_POINT + np.array([0.0, 0.0, 0.05]))
    w = HandWorld(scene, g.pose, up)
    with pytest.raises(IKError):
        solve_path(w.robot, _line(w.robot.tcp_pose(), down), w.robot.q)
    path, q = transfer(w.robot, w.robot.tcp_pose(), down)
    assert q.shape == (len(path.times), 6) and np.allclose(path.poses[-1], down)
    assert path.poses[:, 2].max() == pytest.approx(up[2] + TRANSFER_LIFT, abs=1e-4)  # from the measured TCP
