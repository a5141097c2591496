"""The values of a grasp-graph file checked one by one (docs/grasp-graph.md): numbers, wall
times, the settings it was measured with, its nodes (grasps) and the regrasp actions it names.
Each fault is an ArgumentError naming the field (``settings.spread``, ``nodes[3].width``)."""

from __future__ import annotations


import numpy as np

from ..errors import ArgumentError
from ..fields import finite_number as is_number


def check_node(n: dict, f: str) -> None:
    """A graph file's node ``f``: a grasp (:meth:`~regrasp.dexterity.taxonomy.Grasp.from_dict`)
    with its hand's signed ``clearance`` [m] (< 0: the hand collides) and whether it ``fits``; an ArgumentError naming the
    node's field."""
    from .taxonomy import Grasp

    try:
        Grasp.from_dict(n)
    except ArgumentError as e:
        raise ArgumentError(str(e).replace(f"`{e.field}`", f"`{f}.{e.field}`", 1), f"{f}.{e.field}") from None
    if "clearance" in n and not (is_number(n["clearance"]) and abs(n["clearance"]) <= 10):
        raise ArgumentError(f"invalid `{f}.clearance`: metres in [-10, 10] (got {n['clearance']!r:.40})", f"{f}.clearance")
    if "fits" in n and not isinstance(n["fits"], bool):
        raise ArgumentError(f"invalid `{f}.fits`: true or false (got {n['fits']!r:.40})", f"{f}.fits")


def check_seconds(v, f: str) -> float:
    """A wall time [s] of a graph file: a finite number >= 0; else an ArgumentError naming ``f``."""
    if not (is_number(v) and v >= 0):
        raise ArgumentError(f"invalid `{f}`: seconds, a finite number >= 0 (got {v!r:.40})", f)
    return float(v)


def known_actions() -> set:
    """The names of the regrasp actions."""
    from .actions import ACTIONS

    return set(ACTIONS)


def check_settings(s: dict, known: set) -> dict:
    """A graph file's ``settings`` (those of :class:`Settings`), each value checked; an
    ArgumentError naming ``settings.KEY``."""
    whole = lambda v, lo: isinstance(v, int) and not isinstance(v, bool) and v >= lo  # noqa: E731
    checks = {"trials": (lambda v: whole(v, 1), "a whole number >= 1"),
              "seed": (lambda v: whole(v, 0), "a whole number >= 0"),
              "spread": (lambda v: is_number(v) and 0 <= v < 1, "a share in [0, 1)"),
              "shift": (lambda v: is_number(v) and 0 <= v <= 1, "metres in [0, 1]"),
              "turn": (lambda v: is_number(v) and 0 <= v <= np.pi, "radians in [0, pi]"),
              "actions": (lambda v: v is None or (isinstance(v, list) and all(a in known for a in v if isinstance(a, str))
                                                  and all(isinstance(a, str) for a in v)),
                          "null or a list of regrasp actions"),
              "chain": (lambda v: isinstance(v, bool), "true or false")}
    for k, v in s.items():
        if k not in checks:
            raise ArgumentError(f"invalid `settings.{k}`: unknown setting (the settings: {', '.join(checks)})",
                                f"settings.{k}")
        ok, what = checks[k]
        if not ok(v):
            raise ArgumentError(f"invalid `settings.{k}`: {what} (got {v!r:.40})", f"settings.{k}")
    return dict(s)
