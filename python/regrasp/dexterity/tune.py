"""Tuning an action's parameter per object by a search in simulation (beyond the thesis, whose
twelve actions were hand-scripted): for each candidate value of one parameter (e.g. the grip
of a gravity slide as a share of the weight, the acceleration of an inertial slide), the
action's edges from every grasp it applies to are run ``trials`` times in perturbed worlds
(:mod:`.graph`'s draws, a seed of their own), and the value with the most runs reaching their
intended grasp is kept (ties: the default's side). The gain is measured against the default on
fresh worlds (another seed), so that the choice is not graded on the runs that chose it."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ArgumentError
from .actions import ACTIONS, DEFAULTS
from .graph import FIT, Settings, _object, fitting, perturbations

SEARCH_SEED, CHECK_SEED = 1, 2  # the worlds of the search, and of the comparison


@dataclass(frozen=True)
class Tuning:
    """One parameter tuned: the ``action``, ``param``, the ``default`` and ``best`` values, the
    search's success rate per value (``search``, {value: rate}), and on fresh worlds the
    ``default_rate`` and ``tuned_rate`` over ``trials`` runs each on the same edges."""

    action: str
    param: str
    default: float
    best: float
    search: dict
    default_rate: float
    tuned_rate: float
    trials: int

    def to_dict(self) -> dict:
        """The tuning as JSON."""
        return {"action": self.action, "param": self.param, "default": self.default, "best": self.best,
                "search": {str(k): v for k, v in self.search.items()}, "default_rate": self.default_rate,
                "tuned_rate": self.tuned_rate, "trials": self.trials}


def _rate(path: str, edges: list, action: str, params: dict, trials: int, seed: int) -> tuple:
    """(hits, runs) of ``action`` with ``params`` on ``edges`` (grasp names), ``trials`` each."""
    from .trial import Runner

    scene, tax, obj = _object(path)
    hits = runs = 0
    for grasp in edges:
        g = tax.grasp(grasp)
        try:
            setup = ACTIONS[action].setup(obj, g, params)
        except ArgumentError:
            continue
        runner = Runner(scene, tax, g, setup)
        runs += trials
        try:
            hits += sum(runner.run(p).outcome == setup.intended
                        for p in perturbations(Settings(trials=trials, seed=seed), f"tune/{grasp}/{action}"))
        except ArgumentError:  # the arm cannot do it with this value (IK): every run failed
            pass
    return hits, runs


def tune(path, action: str, param: str, values, trials: int = 10) -> Tuning:
    """Tunes ``param`` of ``action`` (:data:`~.actions.DEFAULTS`) for the object file ``path``
    over the candidate ``values`` (see the module's doc)."""
    if action not in ACTIONS:
        raise ArgumentError(f"invalid `action`: unknown action {action!r} (known: {', '.join(ACTIONS)})", "action")
    if param not in DEFAULTS:
        raise ArgumentError(f"invalid `param`: unknown parameter {param!r} (known: {', '.join(DEFAULTS)})", "param")
    path = str(path)
    scene, tax, obj = _object(path)
    clear = fitting(scene, tax)
    usable = {g.name for g in tax.grasps if g.holds and clear[g.name] >= FIT}
    edges = [g.name for g in tax.grasps if g.name in usable and ACTIONS[action].applies(obj, g) is None
             and ACTIONS[action].setup(obj, g).intended in usable - {g.name}]
    if not edges:
        raise ArgumentError(f"invalid `action`: {action} applies to no grasp of {scene.name} that holds and fits",
                            "action")
    default = float(DEFAULTS[param])
    search = {}
    for v in sorted({float(x) for x in values} | {default}):
        hits, runs = _rate(path, edges, action, {param: v}, trials, SEARCH_SEED)
        search[v] = hits / runs if runs else 0.0
    best = max(search, key=lambda v: (search[v], -abs(v - default)))
    d_hits, d_runs = _rate(path, edges, action, {param: default}, trials, CHECK_SEED)
    t_hits, t_runs = _rate(path, edges, action, {param: best}, trials, CHECK_SEED)
    return Tuning(action, param, default, float(best), search, d_hits / max(d_runs, 1), t_hits / max(t_runs, 1),
                  int(d_runs))
