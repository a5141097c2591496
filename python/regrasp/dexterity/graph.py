"""The grasp graph of an object, measured in simulation (thesis Fig 1-2; ICRA 2014): its nodes
are the grasps of the object's taxonomy (:mod:`.taxonomy`), its edges the regrasp actions
(:mod:`.actions`): for each grasp that holds and each action that applies to it, ``trials``
runs of the arm in MuJoCo (:mod:`.trial`) in worlds drawn within ``spread`` (the pads'
friction, the grip force and the object's mass each ±spread; the object's start pose in the
hand ±``shift`` [m] and ±``turn`` [rad] about the grasp axis); each run's outcome classified to
the nearest grasp (or dropped / other). An edge carries the grasp the action is meant to reach
(the model's prediction), the measured success rate (the share of runs that reached it) and the
distribution of outcomes, with each run's end pose in the hand. With ``chain``, a second pass
measures every action again from where each other action left the object (:class:`Chain`: each
run of an edge that reached a grasp is continued once by each action from that grasp, from its
end pose in the hand and in its world), so that a sequence's prediction carries the poses one
action leaves, and the world it acted in, into the next. Runs go in parallel over processes or a Ray
cluster. The graph file (JSON, :class:`GraspGraph`: read and written here only) is documented in
docs/grasp-graph.md."""

from __future__ import annotations

import json
import multiprocessing
import signal
import time
import zlib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import ArgumentError
from ..fields import MAX_GRAPH_EDGES, MAX_GRAPH_NODES
from .graph_values import is_number, known_actions, check_node, check_seconds, check_settings
from ..files import parse_json, read_text, write_text
from .. import progress as bars

FORMAT, VERSION = "regrasp-grasp-graph", 1
TRIALS = 20  # runs per edge (the issue's minimum: ≥ 20 per edge)
SPREAD = 0.2  # ±20 % on the pads' friction, the grip force and the object's mass
SHIFT = 0.001  # m, ± on the object's start position in the hand (x and z)
TURN = 0.035  # rad, ± on its start turn about the grasp axis (2°)
FIT = 0.0005  # m, a grasp fits the hand when the object stays this far from the gripper's links besides the pads


@dataclass(frozen=True)
class Settings:
    """How the graph is measured: ``trials`` per edge, ``seed``, the world's ``spread``,
    ``shift`` [m], ``turn`` [rad] (see the module's doc), ``actions`` (names; None: all),
    ``chain``: also continue every run that reached a grasp by each action from that grasp
    (:class:`Chain`)."""

    trials: int = TRIALS
    seed: int = 0
    spread: float = SPREAD
    shift: float = SHIFT
    turn: float = TURN
    actions: tuple | None = None
    chain: bool = False

    def to_dict(self) -> dict:
        """The settings as the graph file records them."""
        return {"trials": self.trials, "seed": self.seed, "spread": self.spread, "shift": self.shift, "turn": self.turn,
                "actions": None if self.actions is None else list(self.actions), "chain": self.chain}


@dataclass
class Edge:
    """Runs of ``action`` from grasp ``source``: ``target`` the grasp it is meant to reach,
    ``trials`` run, ``outcomes`` {outcome: count}, ``detail`` the action's parameters as set up,
    ``seconds`` of wall time, ``runs`` each run's (outcome, end pose in the hand (7,) or None
    when dropped, its world (friction, grip, mass) factors) in order (empty in files written
    before they were recorded)."""

    source: str
    action: str
    target: str | None
    trials: int
    outcomes: dict
    detail: dict = field(default_factory=dict)
    seconds: float = 0.0
    runs: list = field(default_factory=list)

    @property
    def success_rate(self) -> float:
        """The share of the runs that reached ``target`` (0 without runs)."""
        return self.outcomes.get(self.target, 0) / self.trials if self.trials else 0.0

    @property
    def params(self) -> dict:
        """The action's parameters the edge was measured with (a re-pick's ``target``)."""
        return {"target": self.detail["target"]} if isinstance(self.detail.get("target"), str) else {}

    def ends(self, outcome: str) -> list:
        """(end pose (7,), world factors) of the runs that reached ``outcome``."""
        return [(pose, world) for o, pose, world in self.runs if o == outcome and pose is not None]

    def to_dict(self) -> dict:
        """The edge as the graph file writes it (docs/grasp-graph.md)."""
        return {"from": self.source, "to": self.target, "action": self.action, "success_rate": self.success_rate,
                "trials": self.trials, "outcomes": dict(self.outcomes), "detail": self.detail, "seconds": self.seconds,
                "runs": [{"outcome": o, "pose": None if pose is None else [float(x) for x in pose],
                          "world": [float(x) for x in world]} for o, pose, world in self.runs]}

    @classmethod
    def from_dict(cls, d: dict, i: int, names=None) -> "Edge":
        """The edge of a graph file's ``edges[i]`` ``d`` (``names``: the nodes' names, which an
        outcome other than dropped, other, unstable or refused must be); an ArgumentError naming the field."""
        from .trial import DROPPED, OTHER, REFUSED, UNSTABLE

        f = f"edges[{i}]"
        if not isinstance(d, dict):
            raise ArgumentError(f"invalid `{f}`: an object (got {type(d).__name__})", f)
        for key in ("from", "action", "trials", "outcomes"):
            if key not in d:
                raise ArgumentError(f"invalid `{f}`: `{key}` is required (an edge has from, to, action, trials, "
                                    f"outcomes)", f)
        for key in ("from", "action"):
            if not isinstance(d[key], str):
                raise ArgumentError(f"invalid `{f}.{key}`: a string (got {d[key]!r:.40})", f"{f}.{key}")
        if d.get("to") is not None and not isinstance(d["to"], str):
            raise ArgumentError(f"invalid `{f}.to`: a grasp's name or null (got {d['to']!r:.40})", f"{f}.to")
        count = lambda v: isinstance(v, int) and not isinstance(v, bool) and v >= 0  # noqa: E731
        if not count(d["trials"]):
            raise ArgumentError(f"invalid `{f}.trials`: a whole number >= 0 (got {d['trials']!r:.40})", f"{f}.trials")
        out = d["outcomes"]
        known = set(names or ()) | {DROPPED, OTHER, UNSTABLE, REFUSED}
        if not isinstance(out, dict) or not all(isinstance(k, str) and count(v) for k, v in out.items()):
            raise ArgumentError(f"invalid `{f}.outcomes`: {{outcome: whole number >= 0}}", f"{f}.outcomes")
        if names is not None and set(out) - known:
            raise ArgumentError(f"invalid `{f}.outcomes`: {sorted(set(out) - known)} are neither nodes nor "
                                f"{', '.join(sorted(known - set(names)))}", f"{f}.outcomes")
        if sum(out.values()) != d["trials"]:
            raise ArgumentError(f"invalid `{f}.outcomes`: the counts must add up to `trials` ({d['trials']})",
                                f"{f}.outcomes")
        detail = d.get("detail", {})
        if not isinstance(detail, dict):
            raise ArgumentError(f"invalid `{f}.detail`: an object", f"{f}.detail")
        seconds = check_seconds(d.get("seconds", 0.0), f"{f}.seconds")
        runs = _runs(d.get("runs", []), f"{f}.runs", d["trials"], out)
        return cls(d["from"], d["action"], d.get("to"), d["trials"], dict(out), dict(detail), seconds, runs)

    def check_rate(self, rate, f: str) -> None:
        """A file's ``success_rate`` of this edge (None: not given) is its outcomes' share that
        reached ``to``, in [0, 1]; else an ArgumentError naming ``f``."""
        if rate is not None and not (is_number(rate) and 0 <= rate <= 1 and abs(rate - self.success_rate) <= 1e-9):
            raise ArgumentError(f"invalid `{f}`: the share of `trials` that reached `to`, in [0, 1] "
                                f"({self.success_rate:g} by its outcomes; got {rate!r:.40})", f)


def _numbers(v, n: int, positive: bool = False) -> bool:
    """Whether ``v`` is a list of ``n`` finite numbers (> 0 with ``positive``)."""
    return isinstance(v, list) and len(v) == n and all(is_number(x) and (x > 0 or not positive) for x in v)


def _runs(runs, f: str, trials: int, outcomes: dict) -> list:
    """The (outcome, pose or None, world) of an edge's ``runs`` JSON, checked against its
    ``trials`` and ``outcomes`` (none: a file written before runs were recorded); an
    ArgumentError naming ``f``."""
    if not isinstance(runs, list) or (runs and len(runs) != trials):
        raise ArgumentError(f"invalid `{f}`: a list of one {{outcome, pose, world}} per trial ({trials})", f)
    out = []
    for k, r in enumerate(runs):
        pose = r.get("pose") if isinstance(r, dict) else None
        if not isinstance(r, dict) or not isinstance(r.get("outcome"), str) or not (
                pose is None or _numbers(pose, 7)) or not _numbers(r.get("world"), 3, positive=True):
            raise ArgumentError(f"invalid `{f}[{k}]`: {{\"outcome\": a string, \"pose\": 7 numbers or null, "
                                f"\"world\": 3 numbers > 0}}", f"{f}[{k}]")
        out.append((r["outcome"], None if pose is None else np.array(pose, float), tuple(map(float, r["world"]))))
    counts: dict = {}
    for o, *_ in out:
        counts[o] = counts.get(o, 0) + 1
    if out and counts != {k: v for k, v in outcomes.items() if v}:
        raise ArgumentError(f"invalid `{f}`: its outcomes do not match the edge's `outcomes`", f)
    return out


@dataclass
class Chain:
    """Runs of ``edges[edge]`` continuing those of ``edges[after]`` that reached ``edge``'s
    grasp: each starts from one such run's end pose in the hand, in that run's world (its pads'
    friction, grip force and mass), with the hand where ``after``'s action ended, moving to
    ``edge``'s start as a sequence does, once: ``trials`` (= ``after``'s count of that grasp),
    ``outcomes`` {outcome: count}, ``seconds`` of wall time."""

    after: int
    edge: int
    trials: int
    outcomes: dict
    seconds: float = 0.0

    def to_dict(self) -> dict:
        """The chain as the graph file writes it (docs/grasp-graph.md)."""
        return {"after": self.after, "edge": self.edge, "trials": self.trials, "outcomes": dict(self.outcomes),
                "seconds": self.seconds}

    @classmethod
    def from_dict(cls, d, i: int, edges: list, names=()) -> "Chain":
        """The chain of a graph file's ``chained[i]`` ``d`` over its ``edges`` (``names``: the
        nodes', which an outcome other than dropped, other, unstable or refused must be); an
        ArgumentError naming the field."""
        f = f"chained[{i}]"
        if not isinstance(d, dict):
            raise ArgumentError(f"invalid `{f}`: an object (got {type(d).__name__})", f)
        whole = lambda v: isinstance(v, int) and not isinstance(v, bool) and v >= 0  # noqa: E731
        for key in ("after", "edge", "trials", "outcomes"):
            if key not in d:
                raise ArgumentError(f"invalid `{f}`: `{key}` is required (a chain has after, edge, trials, outcomes)", f)
        for key in ("after", "edge"):
            if not whole(d[key]) or d[key] >= len(edges):
                raise ArgumentError(f"invalid `{f}.{key}`: an index into `edges` (0 to {len(edges) - 1}; got "
                                    f"{d[key]!r:.40})", f"{f}.{key}")
        arrived = edges[d["after"]].outcomes.get(edges[d["edge"]].source, 0)
        if not arrived or edges[d["after"]].source == edges[d["edge"]].source:
            raise ArgumentError(f"invalid `{f}`: edge {d['after']} never reached grasp {edges[d['edge']].source!r}, "
                                f"where edge {d['edge']} starts", f)
        if d["trials"] != arrived:
            raise ArgumentError(f"invalid `{f}.trials`: one run per run of edge {d['after']} that reached "
                                f"{edges[d['edge']].source!r} ({arrived}; got {d['trials']!r:.40})", f"{f}.trials")
        from .trial import DROPPED, OTHER, REFUSED, UNSTABLE

        out = d["outcomes"]
        known = set(names) | {DROPPED, OTHER, UNSTABLE, REFUSED}
        if not isinstance(out, dict) or not all(isinstance(k, str) and whole(v) for k, v in out.items()) \
                or sum(out.values()) != d["trials"] or set(out) - known:
            raise ArgumentError(f"invalid `{f}.outcomes`: {{outcome (a grasp, dropped, other, unstable or refused): "
                                f"whole number >= 0}} adding up to `trials`", f"{f}.outcomes")
        seconds = d.get("seconds", 0.0)
        if not isinstance(seconds, (int, float)) or isinstance(seconds, bool):
            raise ArgumentError(f"invalid `{f}.seconds`: a number", f"{f}.seconds")
        return cls(d["after"], d["edge"], d["trials"], dict(out), float(seconds))


@dataclass
class GraspGraph:
    """A measured grasp graph: the ``object`` (its name and file), the ``taxonomy``'s grasps
    (nodes), the ``edges``, the ``actions`` measured, the ``settings`` and the ``chained``
    measurements (:class:`Chain`; empty unless measured with ``chain``)."""

    object: dict
    nodes: list
    edges: list
    actions: list
    settings: dict
    seconds: float = 0.0
    chained: list = field(default_factory=list)

    def to_dict(self) -> dict:
        """The graph file's JSON (docs/grasp-graph.md)."""
        return {"format": FORMAT, "version": VERSION, "object": self.object, "nodes": self.nodes,
                "edges": [e.to_dict() for e in self.edges], "actions": self.actions, "settings": self.settings,
                "seconds": self.seconds, "chained": [c.to_dict() for c in self.chained]}

    def save(self, path) -> Path:
        """Writes the graph as JSON to ``path`` (atomically)."""
        return write_text(Path(path), json.dumps(self.to_dict(), indent=1, allow_nan=False) + "\n")

    @classmethod
    def load(cls, path) -> "GraspGraph":
        """The graph file ``path``; an ArgumentError naming the field of a bad file."""
        d = parse_json(read_text(path, "graph"), "graph",
                       lambda why: ArgumentError(f"invalid `graph`: {str(path)!r}: {why}", "graph"))
        return cls.from_dict(d)

    @classmethod
    def from_dict(cls, d) -> "GraspGraph":
        """The graph of a graph file's JSON ``d``; an ArgumentError naming the field of a bad one."""
        if not isinstance(d, dict) or d.get("format") != FORMAT:
            raise ArgumentError(f"invalid `format`: a grasp graph file has \"format\": \"{FORMAT}\"", "format")
        if isinstance(d.get("version"), bool) or d.get("version") != VERSION:
            raise ArgumentError(f"invalid `version`: {d.get('version')!r} (this regrasp reads version {VERSION})", "version")
        for key, kind in (("object", dict), ("nodes", list), ("edges", list), ("actions", list), ("settings", dict)):
            if key not in d:
                raise ArgumentError(f"invalid `{key}`: is required", key)
            if not isinstance(d[key], kind):
                raise ArgumentError(f"invalid `{key}`: a JSON {'object' if kind is dict else 'array'}", key)
        for key, most in (("nodes", MAX_GRAPH_NODES), ("edges", MAX_GRAPH_EDGES)):
            if len(d[key]) > most:
                raise ArgumentError(f"invalid `{key}`: has {len(d[key])}; at most {most} are allowed "
                                    "(docs/guarantees.md, Limits)", key)
        if not all(isinstance(n, dict) and isinstance(n.get("name"), str) and n["name"].strip() for n in d["nodes"]):
            raise ArgumentError("invalid `nodes`: a list of grasps, each with a `name` (a non-blank string)", "nodes")
        names = [n["name"] for n in d["nodes"]]
        for i, n in enumerate(names):
            if n in names[:i]:
                raise ArgumentError(f"invalid `nodes[{i}].name`: repeats nodes[{names.index(n)}].name ({n!r})",
                                    f"nodes[{i}].name")
        for i, n in enumerate(d["nodes"]):
            check_node(n, f"nodes[{i}]")
        known = known_actions()
        for i, a in enumerate(d["actions"]):
            if not (isinstance(a, dict) and isinstance(a.get("name"), str) and a["name"] in known):
                raise ArgumentError(f"invalid `actions[{i}]`: a regrasp action, {{\"name\": one of "
                                    f"{', '.join(sorted(known))}, ...}} (got {a!r:.60})", f"actions[{i}]")
        measured = [a["name"] for a in d["actions"]]
        settings = check_settings(d["settings"], known)
        if not isinstance(d["object"].get("file", ""), str) or not isinstance(d["object"].get("name", ""), str):
            raise ArgumentError("invalid `object`: its `name` and `file` are strings", "object")
        seconds = check_seconds(d.get("seconds", 0.0), "seconds")
        edges = [Edge.from_dict(e, i, names) for i, e in enumerate(d["edges"])]
        for i, e in enumerate(edges):
            if e.action not in measured:
                raise ArgumentError(f"invalid `edges[{i}].action`: {e.action!r:.40} is not one of the graph's `actions` "
                                    f"({', '.join(measured)})", f"edges[{i}].action")
        for i, e in enumerate(edges):
            for key, v in (("from", e.source), ("to", e.target)):
                if v is not None and v not in names:
                    raise ArgumentError(f"invalid `edges[{i}].{key}`: {v!r} is not a node", f"edges[{i}].{key}")
            e.check_rate(d["edges"][i].get("success_rate"), f"edges[{i}].success_rate")
        if not isinstance(d.get("chained", []), list):
            raise ArgumentError("invalid `chained`: a JSON array", "chained")
        chained = [Chain.from_dict(c, i, edges, names) for i, c in enumerate(d.get("chained", []))]
        pairs = [(c.after, c.edge) for c in chained]
        if len(set(pairs)) != len(pairs):
            i = next(k for k, p in enumerate(pairs) if p in pairs[:k])
            raise ArgumentError(f"invalid `chained[{i}]`: a second chain of edge {pairs[i][1]} after edge "
                                f"{pairs[i][0]}", f"chained[{i}]")
        return cls(dict(d["object"]), list(d["nodes"]), edges, list(d["actions"]), settings, seconds, chained)

    @property
    def node_names(self) -> list:
        """The grasps' names, in the taxonomy's order."""
        return [n["name"] for n in self.nodes]

    def summary(self) -> dict:
        """The ``--json`` form: nodes, edges (from, to, action, success_rate, trials, outcomes), actions."""
        return {"nodes": self.nodes, "edges": [{k: v for k, v in e.to_dict().items()
                                                if k not in ("detail", "seconds", "runs")} for e in self.edges],
                "actions": self.actions, "trials": sum(e.trials for e in self.edges), "seconds": self.seconds,
                "chained": [c.to_dict() for c in self.chained]}


# --- measuring -----------------------------------------------------------------------------------


def _ignore_sigint() -> None:
    """A pool worker's signals: Ctrl-C is the parent's to handle; SIGTERM (the pool's terminate)
    ends it at once (not the command's SIGTERM handler, inherited by a fork)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


_CACHE: dict = {}


def _object(path: str):
    """(scene, taxonomy, ObjectModel) of an object file, once per process."""
    if path not in _CACHE:
        from .actions import ObjectModel
        from .objects import load_object
        from .taxonomy import taxonomy_of

        scene = load_object(path)
        tax = taxonomy_of(scene)
        _CACHE[path] = (scene, tax, ObjectModel.of(scene, tax))
    return _CACHE[path]


def perturbations(settings: Settings, key: str) -> list:
    """The ``settings.trials`` worlds of the edge ``key`` (the first nominal), drawn from a seed
    made of ``settings.seed`` and ``key`` (an edge's worlds do not depend on the others)."""
    from ..scene.perturbation import Perturbation

    rng = np.random.default_rng([settings.seed, zlib.crc32(key.encode())])
    out = [Perturbation()]
    while len(out) < settings.trials:
        out.append(Perturbation.draw(rng, settings.spread, shift=settings.shift, turn=settings.turn))
    return out[:settings.trials]


def continuations(ends: list) -> list:
    """The worlds of a chain: one per (end pose, world factors) of ``ends``
    (:meth:`Edge.ends`): that world, the object starting at that pose (no extra shift or turn)."""
    from ..scene.perturbation import Perturbation

    return [Perturbation(*map(float, world), pose=tuple(float(x) for x in pose)) for pose, world in ends]


def run_edge(job: tuple) -> Edge:
    """Runs the trials of one edge: ``job`` = (object path, grasp name, action name, the
    action's params (a dict: place-repick's ``target``), settings, robot[, ends, before]): a
    chain's, with ``ends`` (:meth:`Edge.ends` of the edge before) the worlds of
    :func:`continuations`, each run starting where the action ``before`` (its grasp, name and
    params) ends and moving to this one's start as a sequence does (:class:`~.trial.Runner`'s
    lead-in)."""
    from ..execution.execute import World, check_hand_world, execute
    from ..scene.perturbation import Perturbation
    from .actions import action
    from .trial import REFUSED, Runner

    path, grasp_name, action_name, params, settings, robot, *chain = job
    scene, tax, obj = _object(path)
    grasp = tax.grasp(grasp_name)
    t0 = time.perf_counter()
    setup = action(action_name).setup(obj, grasp, params)
    lead_in = None
    if chain:
        source, name, before = chain[1]
        lead_in = (action(name).setup(obj, tax.grasp(source), before).path.poses[-1], obj.grip)
    runner = Runner(scene, tax, grasp, setup, robot, lead_in, action_name)
    world = World(scene, rig="arm", robot=robot)
    check_hand_world(world, "open", Perturbation(), "a regrasp action")  # here: below, an ArgumentError is the arm's
    outcomes: dict = {}
    runs: list = []
    if chain:
        worlds = continuations(chain[0])
    else:
        worlds = perturbations(settings, "/".join([grasp_name, action_name, *(str(v) for v in params.values())]))
    for i, p in enumerate(worlds):
        try:
            r = execute(world, runner, perturbation=p).detail  # the one executor: a trial judged on its task
            outcome, pose = r.outcome, r.pose
        except ArgumentError as e:
            if i == 0 and not chain:  # the arm cannot do the action here at all (IK in the nominal world): no edge
                return Edge(grasp_name, action_name, setup.intended, 0, {}, {"refused": str(e), **params},
                            time.perf_counter() - t0)
            outcome, pose = REFUSED, None  # this world only (e.g. a grip beyond the gripper's range)
        outcomes[outcome] = outcomes.get(outcome, 0) + 1
        runs.append((outcome, pose, (p.finger_friction, p.grip, p.mass)))
    detail = {k: (float(v) if isinstance(v, (float, np.floating)) else v) for k, v in setup.detail.items()}
    return Edge(grasp_name, action_name, setup.intended, len(worlds), outcomes, detail, time.perf_counter() - t0,
                runs)


def chains_to_measure(edges: list) -> list:
    """(after, edge) of every pair of measured edges where ``after`` reached the grasp ``edge``
    starts from in some run."""
    return [(i, j) for i, a in enumerate(edges) for j, e in enumerate(edges)
            if e.trials and e.source != a.source and a.ends(e.source)]


def fitting(scene, taxonomy, robot: str | None = None) -> dict:
    """{grasp name: clearance [m]} of the grasps whose object stays :data:`FIT` clear of the
    gripper's links (:func:`~.world.hand_clearances`)."""
    from .world import hand_clearances

    return {k: v[0] for k, v in hand_clearances(scene, taxonomy.grasps, robot).items()}


def edges_to_measure(obj, settings: Settings, clear: dict | None = None) -> list:
    """(grasp name, action name, params) of every grasp that holds (and fits the hand: ``clear``
    {name: clearance [m]}, :func:`fitting`) and every action that applies to it and is meant to
    reach another grasp that holds and fits."""
    from .actions import ACTIONS

    names = list(ACTIONS) if settings.actions is None else list(settings.actions)
    if not names:
        raise ArgumentError(f"invalid `actions`: name at least one action (None: all; known: {', '.join(ACTIONS)})",
                            "actions")
    for n in names:
        if n not in ACTIONS:
            raise ArgumentError(f"invalid `actions`: unknown action {n!r} (known: {', '.join(ACTIONS)})", "actions")
    tax = obj.taxonomy
    usable = {g.name for g in tax.grasps if g.holds and (clear is None or clear[g.name] >= FIT)}
    out = []
    for g in tax.grasps:
        if g.name not in usable:
            continue
        for n in names:
            if ACTIONS[n].applies(obj, g) is not None:
                continue
            if n in ("place-repick", "topple-repick"):  # an edge per new grasp
                out.extend((g.name, n, {"target": t}) for t in ACTIONS[n].targets(obj, g, usable))
                continue
            target = ACTIONS[n].setup(obj, g).intended
            if target in usable and target != g.name:
                out.append((g.name, n, {}))
    return out


def _each(run, jobs: list, workers: int, ray_address, take) -> None:
    """``take(run(job))`` for every job, in any order, over ``workers`` processes or Ray."""
    if ray_address is not None:
        from ..mujoco.validation import ray_init

        ray = ray_init(ray_address, workers)
        remote = ray.remote(run)
        pending = [remote.remote(j) for j in jobs]
        while pending:
            done, pending = ray.wait(pending, num_returns=1)
            take(ray.get(done[0]))
    elif workers <= 1:
        for j in jobs:
            take(run(j))
    else:
        with multiprocessing.get_context("spawn").Pool(workers, initializer=_ignore_sigint) as pool:
            for e in pool.imap_unordered(run, jobs):
                take(e)


def build_graph(path, settings: Settings = Settings(), workers: int = 1, ray_address: str | None = None,
                robot: str | None = None, progress: bool = False) -> GraspGraph:
    """Measures the grasp graph of the object file ``path`` (see the module's doc)."""
    from .actions import ACTIONS

    if not (isinstance(settings.trials, int) and settings.trials >= 1):
        raise ArgumentError(f"invalid `trials`: an integer >= 1 (got {settings.trials!r})", "trials")
    if not (isinstance(workers, int) and workers >= 1):
        raise ArgumentError(f"invalid `workers`: an integer >= 1 (got {workers!r})", "workers")
    path = str(Path(path).resolve())
    scene, tax, obj = _object(path)
    clear = fitting(scene, tax, robot)
    todo = edges_to_measure(obj, settings, clear)
    jobs = [(path, g, a, params, settings, robot) for g, a, params in todo]
    edges: list = []
    t0 = time.perf_counter()
    with bars.bar(len(jobs) * settings.trials, f"grasp graph ({scene.name})", unit="trial", show=progress) as bar:
        def take(e: Edge) -> None:
            edges.append(e)
            bar.update(settings.trials)

        _each(run_edge, jobs, workers, ray_address, take)
    order = {(j[1], j[2], j[3].get("target")): i for i, j in enumerate(jobs)}
    edges.sort(key=lambda e: order[(e.source, e.action, e.detail.get("target"))])
    chained = _chain(path, edges, settings, workers, ray_address, robot, progress) if settings.chain else []
    used = sorted({e.action for e in edges})
    from ..execution.arm import HAND_REACH

    nodes = [{**g.to_dict(), "clearance": float(min(clear[g.name], HAND_REACH)), "fits": clear[g.name] >= FIT}
             for g in tax.grasps]
    return GraspGraph({"name": scene.name, "file": path}, nodes, edges,
                      [ACTIONS[a].to_dict() for a in used], settings.to_dict(), time.perf_counter() - t0, chained)


def _chain(path: str, edges: list, settings: Settings, workers: int, ray_address, robot, progress: bool) -> list:
    """The :class:`Chain` of every pair of :func:`chains_to_measure`."""
    todo = chains_to_measure(edges)
    jobs = [(path, edges[j].source, edges[j].action, edges[j].params, settings, robot, edges[i].ends(edges[j].source),
             (edges[i].source, edges[i].action, edges[i].params), (i, j)) for i, j in todo]
    done: dict = {}
    with bars.bar(sum(len(j[6]) for j in jobs), "chained", unit="trial", show=progress) as bar:
        def take(result: tuple) -> None:
            e, (i, j) = result
            done[(i, j)] = Chain(i, j, e.trials, e.outcomes, e.seconds)
            bar.update(e.trials)

        _each(run_chain, jobs, workers, ray_address, take)
    return [done[k] for k in todo]


def run_chain(job: tuple) -> tuple:
    """(the :func:`run_edge` of a chain's ``job``, its (after, edge))."""
    return run_edge(job[:8]), job[8]
