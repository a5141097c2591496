"""Planning on the grasp graph (networkx): the most reliable sequence of regrasp actions between
two grasps — the path of maximum product of measured transition probabilities (Dijkstra on
−log p) — or the one of fewest expected attempts (Σ 1/p: each action retried until it succeeds,
a failure assumed to leave the grasp as it was). Every observed outcome of an (action, grasp)
is a transition, not only the intended one: an action that lands somewhere useful by a
different route counts. Where the graph has chained measurements (``chain``: each action run
again from the poses where another left the object), a step after the first takes its rate from
the runs that started where the previous step's action left the object, so the plan and its
prediction carry the poses one action leaves into the next: the search is over states (grasp,
the action that reached it). :func:`execute` runs a sequence end to end in MuJoCo, the arm
moving from one action's end to the next one's start with the grip firm."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ArgumentError
from ..extras import need
from .graph import GraspGraph
from .taxonomy import grasp_distance
from .trial import REFUSED, TRANSFER_SETTLE, execution, transfer

OBJECTIVES = ("reliable", "expected")


@dataclass(frozen=True)
class Step:
    """One action of a sequence: from grasp ``source`` by ``action`` to ``target`` with measured
    probability ``p`` (``trials`` runs); ``chained``: ``p`` measured from where the previous
    step's action left the object (else from the grasp's own pose); ``alone``: the edge's rate
    from the grasp's own pose."""

    source: str
    action: str
    target: str
    p: float
    trials: int
    params: dict | None = None
    chained: bool = False
    alone: float | None = None

    def to_dict(self) -> dict:
        """The step as JSON (``params``: the action's parameters as measured, e.g. a re-pick's
        ``target``)."""
        return {"from": self.source, "action": self.action, "to": self.target, "p": self.p, "trials": self.trials,
                "params": dict(self.params or {}), "chained": self.chained,
                "alone": self.p if self.alone is None else self.alone}


@dataclass(frozen=True)
class Sequence:
    """A planned sequence: its ``steps``, the predicted ``probability`` that it all succeeds (the
    product of the steps' p), the ``expected_actions`` (Σ 1/p) and the ``independent``
    probability (the product of the steps' ``alone``: as if each action started from its
    grasp's own pose); ``object``: the object file it was planned for (the graph's), which
    :meth:`run_in` runs it on."""

    steps: tuple
    probability: float
    expected_actions: float
    independent: float | None = None
    object: str | None = None

    def to_dict(self) -> dict:
        """The sequence as JSON (``regrasp regrasp-sequence --json``)."""
        return {"steps": [s.to_dict() for s in self.steps], "probability": self.probability,
                "expected_actions": self.expected_actions,
                "independent": self.probability if self.independent is None else self.independent}

    def run_in(self, world, loop: str, perturbation, observe=None):
        """The sequence run by :func:`regrasp.execution.execute` in ``world`` (the arm, open loop,
        ``world.scene`` the object's scene): an :class:`~regrasp.execution.Execution` whose task
        is the last step's grasp — ``goal_error`` ``[d]``, the distance [m] of the final in-hand
        pose from that grasp (:func:`~.taxonomy.grasp_distance`), success when every step reached
        its target; ``steps`` the per-step records, ``detail`` the :class:`SequenceRun`."""
        from ..execution.execute import check_hand_world

        check_hand_world(world, loop, perturbation, "a sequence of regrasp actions")
        if self.object is None:
            raise ArgumentError("invalid `plan`: a sequence without its object file (plan it from a grasp graph)",
                                "plan")
        if not self.steps:
            raise ArgumentError("invalid `plan`: an empty sequence (its start is its goal): nothing to run", "plan")
        _check_scene(world.scene, self.object)
        run, final, tax = _run(self.object, self, perturbation, world.robot, observe)
        final = tax.grasp(self.steps[0].source).pose if final is None else final  # the arm could not start
        err = [grasp_distance(tax.vertices, final, tax.grasp(self.steps[-1].target).pose)]
        return execution(world, loop, perturbation, final, err, run.success, [{"action": s.action, "from": s.source, "to": s.target,
                                        "reached": run.outcomes[i] if i < len(run.outcomes) else None}
                                       for i, s in enumerate(self.steps)], run)


def states(graph: GraspGraph):
    """The networkx DiGraph of the regrasp states: ``(None, g)`` the object held at grasp ``g``'s
    own pose, ``(j, g)`` at ``g`` where ``graph.edges[j]`` left it. An edge per state, measured
    edge ``j`` from its grasp and outcome grasp ``o`` of ``j``'s runs (every outcome, not only the
    intended one), to state ``(j, o)``: attributes ``action``, ``params`` (a re-pick's
    ``target``), ``p`` (the share of runs that reached ``o``: of the :class:`~.graph.Chain`
    from the state's edge where measured, else of ``j``'s own), ``trials``, ``chained``,
    ``alone`` (``j``'s own share)."""
    nx = need("networkx", "robot")
    G = nx.DiGraph()
    names = set(graph.node_names)
    chains = {(c.after, c.edge): c for c in graph.chained}
    grasp = lambda o, g: o in names and o != g  # noqa: E731
    found = [(None, n) for n in graph.node_names]
    found += [(j, o) for j, e in enumerate(graph.edges) for o, k in e.outcomes.items() if k and grasp(o, e.source)]
    leaving: dict = {}
    for j, e in enumerate(graph.edges):
        if e.trials:
            leaving.setdefault(e.source, []).append(j)
    G.add_nodes_from(found)
    for after, g in found:
        for j in leaving.get(g, ()):
            e = graph.edges[j]
            c = chains.get((after, j))
            counts, n = (c.outcomes, c.trials) if c is not None and c.trials else (e.outcomes, e.trials)
            for o, k in counts.items():
                if k and grasp(o, g):
                    G.add_edge((after, g), (j, o), action=e.action, params=e.params, p=k / n, trials=n,
                               chained=c is not None and c.trials > 0, alone=e.outcomes.get(o, 0) / e.trials)
    return G


def plan(graph: GraspGraph, start: str, goal: str, objective: str = "reliable") -> Sequence:
    """The best sequence from grasp ``start`` (at its own pose) to ``goal`` over the regrasp
    :func:`states` (``objective``: ``reliable`` or ``expected``, :data:`OBJECTIVES`); an
    ArgumentError naming ``from``/``to`` for an unknown grasp, ``objective`` for an unknown
    objective, and one naming ``to`` when no sequence of measured transitions reaches it."""
    nx = need("networkx", "robot")
    for field_, name in (("from", start), ("to", goal)):
        if name not in graph.node_names:
            raise ArgumentError(f"invalid `{field_}`: {name!r} is not a grasp of the graph "
                                f"(grasps: {', '.join(graph.node_names)})", field_)
    if objective not in OBJECTIVES:
        raise ArgumentError(f"invalid `objective`: {objective!r} (known: {', '.join(OBJECTIVES)})", "objective")
    obj = (graph.object.get("file") or None) if isinstance(graph.object, dict) else None
    if start == goal:
        return Sequence((), 1.0, 0.0, 1.0, obj)
    G = states(graph)
    end = ("goal", goal)
    G.add_edges_from(((s, end) for s in list(G.nodes) if s[1] == goal), p=1.0, end=True)
    weight = (lambda u, v, d: 0.0 if d.get("end") else -math.log(d["p"])) if objective == "reliable" else \
        (lambda u, v, d: 0.0 if d.get("end") else 1.0 / d["p"])
    try:
        nodes = nx.dijkstra_path(G, (None, start), end, weight=weight)[:-1]
    except nx.NetworkXNoPath:
        raise ArgumentError(f"invalid `to`: no sequence of measured regrasps reaches {goal!r} from {start!r}",
                            "to") from None
    steps = tuple(Step(u[1], G[u][v]["action"], v[1], float(G[u][v]["p"]), int(G[u][v]["trials"]),
                       G[u][v]["params"], bool(G[u][v]["chained"]), float(G[u][v]["alone"]))
                  for u, v in zip(nodes, nodes[1:]))
    return Sequence(steps, float(np.prod([s.p for s in steps])), float(sum(1 / s.p for s in steps)),
                    float(np.prod([s.alone for s in steps])), obj)


@dataclass(frozen=True)
class SequenceRun:
    """One execution: the grasp reached after each step (``outcomes``), ``success`` (every step
    reached its target)."""

    outcomes: tuple
    success: bool

    def to_dict(self) -> dict:
        """The run as JSON."""
        return {"outcomes": list(self.outcomes), "success": self.success}


def execute(path, sequence: Sequence, perturbation=None, robot: str | None = None, observe=None) -> SequenceRun:
    """Runs ``sequence`` on the object file ``path`` in MuJoCo, open loop: the world built at the
    first grasp and the first action's start; before each later action the hand moves to its
    start (:func:`~.trial.transfer`, grip firm); each action set up for the grasp the plan expects
    there (with its measured parameters: a re-pick's target). Stops at the first step that misses
    its target; a step the arm cannot reach from where the last one left it (IK) ends the run as
    ``refused``. (``regrasp.execution.execute(World(scene, rig="arm"), sequence)`` runs it too,
    with the result every rig gives.)"""
    from ..scene.perturbation import Perturbation

    if not sequence.steps:
        return SequenceRun((), True)
    return _run(str(path), sequence, perturbation or Perturbation(), robot, observe)[0]


def _run(path: str, sequence: Sequence, p, robot, observe) -> tuple:
    """(:class:`SequenceRun`, the final in-hand pose (None when the arm could not start), the
    taxonomy) of ``sequence`` run on the object file ``path`` in the world ``p``."""
    from .actions import action
    from .graph import _object
    from .trial import classify
    from .world import HandWorld, constant, solve_path

    scene, tax, obj = _object(str(path))
    first = action(sequence.steps[0].action).setup(obj, tax.grasp(sequence.steps[0].source), sequence.steps[0].params)
    try:
        world = HandWorld(scene, tax.grasp(sequence.steps[0].source).pose, first.start, p, robot)
    except ArgumentError:  # no IK for the start: the run fails there
        return SequenceRun((REFUSED,), False), None, tax
    outcomes = []
    for i, step in enumerate(sequence.steps):
        setup = first if i == 0 else action(step.action).setup(obj, tax.grasp(step.source), step.params)
        try:
            if i > 0:
                move, q_move = transfer(world.robot, world.robot.tcp_pose(), setup.start)
                world.follow(move, q_move, constant(obj.grip), TRANSFER_SETTLE, observe)
            q = solve_path(world.robot, setup.path, world.robot.q)
        except ArgumentError:  # the arm cannot go on from where the last action left it (IK)
            return SequenceRun((*outcomes, REFUSED), False), world.in_hand(), tax
        world.follow(setup.path, q, setup.grip, setup.settle, observe)
        outcome = classify(world, tax)[0]
        outcomes.append(outcome)
        if outcome != step.target:
            return SequenceRun(tuple(outcomes), False), world.in_hand(), tax
    return SequenceRun(tuple(outcomes), True), world.in_hand(), tax


def _check_scene(scene, path: str) -> None:
    """An ArgumentError naming ``world.scene`` unless ``scene`` is the object file ``path``'s."""
    from .graph import _object

    own = _object(str(path))[0]
    if getattr(scene, "name", None) != own.name:
        raise ArgumentError(f"invalid `world.scene`: the object's scene {own.name!r} (got "
                            f"{getattr(scene, 'name', type(scene).__name__)!r})", "world.scene")
