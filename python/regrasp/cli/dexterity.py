"""`regrasp grasp-graph` and `regrasp regrasp-sequence`: extrinsic dexterity — an object's grasp
graph measured in MuJoCo and the most reliable sequence of regrasp actions on it (docs/cli.md,
docs/grasp-graph.md)."""

from __future__ import annotations

import json
import os
from pathlib import Path

from ..errors import ArgumentError
from . import CANNOT, MAX_WORKERS, OK, add_command, check_count, check_outputs, seed_arg

MAX_TRIALS = 100_000


def _object_file(text: str) -> Path:
    """An object file, or a bundled object's name (``prism``, ``cylinder``, ``box``, ``bar``)."""
    from ..dexterity.objects import OBJECTS, object_path

    p = Path(text)
    if not p.exists() and text in OBJECTS:
        return object_path(text)
    return p


def cmd_grasp_graph(a) -> int:
    from ..dexterity.graph import Settings, build_graph

    check_count(a, "trials", 1, MAX_TRIALS)
    check_count(a, "workers", 1, MAX_WORKERS)
    if a.workers is not None and a.ray is not None:
        raise ArgumentError("invalid `--workers`: give --workers or --ray, not both", "--workers")
    path = _object_file(a.object)
    check_outputs(a, {"out": (".json",), "plot": (".png", ".svg", ".pdf")}, [path])
    actions = None if a.actions is None else tuple(x.strip() for x in a.actions.split(",") if x.strip())
    workers = a.workers or max(1, min(os.cpu_count() or 1, 8))  # also a local Ray cluster's CPUs
    graph = build_graph(path, Settings(trials=a.trials, seed=a.seed, actions=actions, chain=a.chain), workers=workers,
                        ray_address=a.ray, robot=None, progress=True)
    if a.out:
        graph.save(a.out)
    if a.plot:
        from ..dexterity.draw import draw_graph

        draw_graph(graph, a.plot)
    if a.json:
        print(json.dumps(graph.summary(), allow_nan=False))
    else:
        trials = sum(e.trials for e in graph.edges)
        print(f"{graph.object['name']}: {len(graph.nodes)} grasps, {len(graph.edges)} edges, {trials} trials in "
              f"{graph.seconds:.0f} s ({trials / max(graph.seconds, 1e-9):.2f} trials/s)")
        for e in graph.edges:
            if e.trials:
                print(f"  {e.source} --{e.action}--> {e.target}: {e.success_rate:.0%} of {e.trials} "
                      f"({', '.join(f'{k} {v}' for k, v in sorted(e.outcomes.items()))})")
            else:
                print(f"  {e.source} --{e.action}--> refused: {e.detail.get('refused', '')}")
        for c in graph.chained:
            before, e = graph.edges[c.after], graph.edges[c.edge]
            print(f"  after {before.source} --{before.action}--> {e.source}: --{e.action}--> {e.target}: "
                  f"{c.outcomes.get(e.target, 0) / c.trials:.0%} of {c.trials} (alone {e.success_rate:.0%})")
        for p in (a.out, a.plot):
            if p:
                print(f"wrote {p}")
    return OK


def cmd_regrasp_sequence(a) -> int:
    from ..dexterity.graph import GraspGraph
    from ..dexterity.sequence import plan

    check_count(a, "runs", 1, MAX_TRIALS)
    graph = GraspGraph.load(a.graph)
    seq = plan(graph, a.source, a.target, a.objective)
    out = {"sequence": seq.to_dict()}
    if a.execute:
        from ..dexterity.graph import Settings, _object, perturbations
        from ..execution.execute import World, execute

        if not Path(str(graph.object.get("file", ""))).is_file():
            raise ArgumentError(f"invalid `object.file`: the graph's object file {graph.object.get('file')!r} is not "
                                "there to execute on", "object.file")
        spread = {k: graph.settings[k] for k in ("spread", "shift", "turn") if isinstance(graph.settings.get(k), (int, float))}
        world = World(_object(str(graph.object["file"]))[0], rig="arm")
        runs = [execute(world, seq, perturbation=p) if seq.steps else None for p in
                perturbations(Settings(trials=a.runs, seed=a.seed, **spread), f"sequence/{a.source}/{a.target}")]
        runs = [{"outcomes": [], "success": True, "goal_error": [0.0]} if r is None else
                {**r.detail.to_dict(), "goal_error": r.goal_error.tolist()} for r in runs]
        out["runs"] = runs
        out["measured"] = sum(r["success"] for r in runs) / len(runs)
    if a.json:
        print(json.dumps(out, allow_nan=False))
    else:
        alone = "" if seq.independent == seq.probability else f" (each action alone: {seq.independent:.0%})"
        print(f"{a.source} -> {a.target}: {len(seq.steps)} actions, predicted success {seq.probability:.0%}{alone}")
        for s in seq.steps:
            after = f", after the step before; alone {s.alone:.0%}" if s.chained else ""
            print(f"  {s.source} --{s.action}--> {s.target} ({s.p:.0%} of {s.trials}{after})")
        if a.execute:
            print(f"executed {a.runs} times: {out['measured']:.0%} succeeded")
    return OK if not a.execute or out["measured"] > 0 else CANNOT


def add_parsers(sub) -> None:
    from ..dexterity.graph import TRIALS
    from ..dexterity.sequence import OBJECTIVES

    g = add_command(sub, "grasp-graph", "measure an object's grasp graph in MuJoCo: its grasps, and regrasp actions "
                    "with gravity, inertia and the table as edges with their success rates",
                    "regrasp grasp-graph prism --trials 20 --out prism-graph.json --plot prism-graph.png",
                    cmd_grasp_graph)
    g.add_argument("object", help="the object: a 3-D scene file (its [object], [grasp] and [gravity] tables; "
                   "pushers and task optional) or a bundled object's name (prism, cylinder, box, bar)")
    g.add_argument("--trials", type=int, default=TRIALS, help="simulated runs per edge (grasp, action)")
    g.add_argument("--seed", type=seed_arg, default=0, help="the random seed of the perturbed worlds, a whole number >= 0")
    g.add_argument("--workers", type=int, help=f"local processes, 1 to {MAX_WORKERS} (default: the cores, at most 8)")
    g.add_argument("--ray", metavar="ADDRESS", help="spread the edges over a Ray cluster ('local' starts one)")
    g.add_argument("--actions", metavar="A,B", help="only these actions (default: all)")
    g.add_argument("--chain", action="store_true", help="also continue every run that reached a grasp by each "
                   "action from that grasp (from its end pose, in its world), so that a sequence's prediction "
                   "carries the poses one action leaves into the next")
    g.add_argument("--out", metavar="GRAPH.json", help="write the graph (docs/grasp-graph.md)")
    g.add_argument("--plot", metavar="PNG", help="draw the graph (grasps as small drawings, edges with their action "
                   "and success rate)")
    g.add_argument("--json", action="store_true", help="print the graph's nodes, edges and actions as JSON")

    s = add_command(sub, "regrasp-sequence", "the most reliable sequence of regrasp actions between two grasps of a "
                    "measured grasp graph, optionally executed in MuJoCo",
                    "regrasp regrasp-sequence prism-graph.json --from g0 --to g5 --execute --json",
                    cmd_regrasp_sequence)
    s.add_argument("graph", help="a grasp graph file (regrasp grasp-graph --out)")
    s.add_argument("--from", dest="source", required=True, metavar="GRASP", help="the grasp to start from")
    s.add_argument("--to", dest="target", required=True, metavar="GRASP", help="the grasp to reach")
    s.add_argument("--objective", choices=OBJECTIVES, default=OBJECTIVES[0],
                   help="reliable: the highest product of success rates; expected: the fewest expected actions")
    s.add_argument("--execute", action="store_true", help="run the sequence in MuJoCo (--runs times, perturbed "
                   "worlds) and compare the measured success with the graph's prediction")
    s.add_argument("--runs", type=int, default=20, help="executions with --execute")
    s.add_argument("--seed", type=seed_arg, default=0, help="the random seed of the executions' worlds")
    s.add_argument("--json", action="store_true", help="print the sequence (and the runs) as JSON")
