"""Regrasp planning (T-RRT* with motion-cone propagation, thesis ch. 4) and plan files.

``plan(scene)`` returns a :class:`Plan`; ``Plan.to_json()`` is the plan file of
``interface.md``: ``{"scene", "found", "stop_reason", "planning_time_s", "nodes",
"switch_overs", "path": [{"pose", "pusher"}, ...]}`` plus the planner's statistics.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import ArgumentError, check_seed
from ..scene.planar import Scene

PROPAGATIONS = ("motion_cone", "stable_check", "mncp")


@dataclass
class Plan:
    scene: str
    found: bool
    stop_reason: str
    planning_time_s: float
    nodes: int
    switch_overs: int
    path: list  # [{"pose": [x, z, theta], "pusher": name or None}]
    iterations: int = 0
    cost: float = 0.0
    goal_distance: float = 0.0
    propagation: str = "motion_cone"
    seed: int = 0
    #: smallest exact-test margin along each step (≥ 0: every step sticks along its length)
    step_margins: list = field(default_factory=list)

    @property
    def poses(self) -> np.ndarray:
        return np.array([k["pose"] for k in self.path])

    @property
    def pushers(self) -> list:
        return [k["pusher"] for k in self.path]

    @property
    def valid(self) -> bool:
        """Every step passes the exact sticking test along its length."""
        return all(m >= -1e-9 for m in self.step_margins)

    def to_json(self) -> dict:
        return {
            "scene": self.scene,
            "found": self.found,
            "stop_reason": self.stop_reason,
            "planning_time_s": self.planning_time_s,
            "nodes": self.nodes,
            "switch_overs": self.switch_overs,
            "path": self.path,
            "iterations": self.iterations,
            "cost": self.cost,
            "goal_distance": self.goal_distance,
            "propagation": self.propagation,
            "seed": self.seed,
            "step_margins": self.step_margins,
            "valid": self.valid,
        }

    def save(self, path) -> None:
        Path(path).write_text(json.dumps(self.to_json(), indent=1))


def validate(scene: Scene, path: list, checks: int = 64) -> list:
    """Smallest exact-test margin along each step of ``path`` (see :attr:`Plan.step_margins`)."""
    poses = [list(map(float, k["pose"])) for k in path]
    pushers = [k["pusher"] for k in path]
    return scene._core.validate_path(poses, pushers, checks)


def plan(scene: Scene, start=None, goal=None, **settings) -> Plan:
    """Plans a regrasp from ``start`` to ``goal`` (default: the scene's task).

    ``settings`` override the planner's defaults (``regrasp._core.planner_defaults(2)``, the
    Rust core's): ``seed``, ``time_limit`` [s], ``propagation`` ("motion_cone": this library;
    "stable_check": random steps kept when a force-balance LP passes, ICRA 2018; "mncp": inverse
    quasi-static dynamics), ``max_nodes``, ``step`` [m], ``goal_bias``, ``margin``,
    ``neighbour_steps``, ``cost_threshold``, ``checks``, ``random_tries``, ``connect``, ``plain``.
    """
    if "seed" in settings:
        settings["seed"] = check_seed(settings["seed"])
    s = list(map(float, start)) if start is not None else None
    g = list(map(float, goal)) if goal is not None else None
    r = scene._core.plan(s, g, settings)
    p = Plan(**{k: r[k] for k in ("scene", "found", "stop_reason", "planning_time_s", "nodes", "switch_overs", "path",
                                  "iterations", "cost", "goal_distance", "propagation", "seed")})
    p.step_margins = validate(scene, p.path) if len(p.path) > 1 else []
    return p
