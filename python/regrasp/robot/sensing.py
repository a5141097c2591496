"""What the grip loop measures (:class:`~regrasp.robot.grip.GripController`): a real parallel
gripper does not know its pads' normal forces exactly. Three kinds, chosen per run:

- ``"ideal"``: MuJoCo's contact normal forces on the held object, exact, every loop period (the
  simulator's own numbers: no gripper has this sensor);
- ``"sensor"``: a force sensor in each finger: the pad's normal force delayed by ``delay`` [s],
  low-passed to ``bandwidth`` [Hz] (first order) and read with Gaussian ``noise`` [N] (standard
  deviation); the loop's time constant is kept at least ``SETTLE_DELAYS`` delays (a loop faster
  than its sensor's delay oscillates);
- ``"open-loop"``: no measurement at all: the actuator's command is the feed-forward through
  the calibrated linkage map, as a 2F-85's force setting (its motor current) or a Franka Hand's
  grasp force sets it.

The sensor's defaults are illustrative (a fingertip sensor read at 500 Hz), not a data sheet's:
state your gripper's."""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass

import numpy as np

from ..errors import ArgumentError

KINDS = ("ideal", "sensor", "open-loop")
#: The grip loop's time constant is at least this many sensor delays.
SETTLE_DELAYS = 4.0


@dataclass(frozen=True)
class GripSensing:
    """The grip loop's measurement (see the module's doc): ``kind`` one of :data:`KINDS`; for a
    ``"sensor"``: ``noise`` [N] (standard deviation of each reading), ``delay`` [s], ``bandwidth``
    [Hz] (first-order low-pass), ``seed`` of the noise."""
    kind: str = "ideal"
    noise: float = 0.05
    delay: float = 0.002
    bandwidth: float = 100.0
    seed: int = 0

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ArgumentError(f"invalid `grip_sensing.kind`: one of {', '.join(KINDS)} (got {self.kind!r:.40})",
                                "grip_sensing.kind")
        for k, lo in (("noise", 0.0), ("delay", 0.0), ("bandwidth", 1e-9)):
            v = getattr(self, k)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not (math.isfinite(v) and lo <= v <= 1e3):
                raise ArgumentError(f"invalid `grip_sensing.{k}`: a number in [{lo:g}, 1000] (got {v!r:.40})",
                                    f"grip_sensing.{k}")
        if isinstance(self.seed, bool) or not isinstance(self.seed, int) or self.seed < 0:
            raise ArgumentError(f"invalid `grip_sensing.seed`: an integer >= 0 (got {self.seed!r:.40})",
                                "grip_sensing.seed")

    @classmethod
    def parse(cls, text: str, field: str = "--grip-sensing") -> "GripSensing":
        """``ideal``, ``open-loop``, ``sensor`` or ``sensor:NOISE,DELAY,BANDWIDTH`` (N, s, Hz)."""
        kind, _, rest = str(text).partition(":")
        try:
            if kind == "sensor" and rest:
                noise, delay, bw = (float(x) for x in rest.split(","))
                return cls("sensor", noise, delay, bw)
            if rest:
                raise ValueError
            return cls(kind)
        except (ValueError, ArgumentError) as e:
            raise ArgumentError(f"invalid `{field}`: ideal, open-loop, sensor or sensor:NOISE,DELAY,BANDWIDTH (N, s, Hz) "
                                f"(got {text!r:.60}){': ' + str(e) if isinstance(e, ArgumentError) else ''}",
                                field) from None


class SensedForces:
    """The readings of a ``"sensor"`` :class:`GripSensing` of the true per-pad forces, sampled
    every ``period`` [s]: :meth:`read` takes the true forces now and returns what the sensor
    reports (delayed, filtered, noisy)."""

    def __init__(self, sensing: GripSensing, period: float, pads: int = 2):
        self.s, self.period = sensing, float(period)
        self.queue: deque = deque()
        self.steps = max(0, int(round(sensing.delay / period)))
        self.alpha = 1.0 - math.exp(-2.0 * math.pi * sensing.bandwidth * period)
        self.state = np.zeros(pads)
        self.rng = np.random.default_rng(sensing.seed)

    def read(self, true) -> np.ndarray:
        """The reported forces [N] given the ``true`` ones now (one call per period)."""
        self.queue.append(np.asarray(true, float))
        x = self.queue.popleft() if len(self.queue) > self.steps else np.zeros_like(self.state)
        self.state = self.state + self.alpha * (x - self.state)
        return self.state + self.rng.normal(0.0, self.s.noise, self.state.shape)
