"""3-D scenes (``dimension = 3``): a box or a convex mesh in a parallel-jaw grasp, pushers as
rigid point sets; poses are ``[x, y, z, qw, qx, qy, qz]`` of the object frame in the gripper
frame, twists ``[vx, vy, vz, wx, wy, wz]`` body twists of the object frame. The format is
documented in ``crates/regrasp-core/src/scene3d.rs`` and the README."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import numpy as np

from . import _core
from .errors import ArgumentError


class Scene3D:
    def __init__(self, core: "_core.Scene3D", path: Optional[Path] = None):
        self._core = core
        self.path = path

    @classmethod
    def load(cls, path) -> "Scene3D":
        p = Path(path)
        try:
            text = p.read_text()
        except OSError as e:
            raise ArgumentError(f"invalid `path`: cannot read {p}: {e}", "path") from e
        return cls(_core.Scene3D.from_toml(text, str(p.parent)), p)

    @classmethod
    def from_toml(cls, text: str, base=None) -> "Scene3D":
        return cls(_core.Scene3D.from_toml(text, None if base is None else str(base)))

    def __repr__(self) -> str:
        return f"Scene3D({self.name!r}, pushers={self.pusher_names})"

    name = property(lambda self: self._core.name)
    pusher_names = property(lambda self: self._core.pusher_names)
    length = property(lambda self: self._core.length)
    mass = property(lambda self: self._core.mass)
    inertia = property(lambda self: self._core.inertia)

    @property
    def task(self):
        s, g, t = self._core.task
        return np.array(s), np.array(g), np.array(t)

    def mesh(self):
        return self._core.mesh()

    def pad_contacts(self, pose) -> list:
        return [np.array(p) for p in self._core.pad_contacts(list(np.asarray(pose, float)))]

    def quasistatic_problem(self, pose, pusher: str, h: float = 1.0):
        return self._core.quasistatic_problem(list(np.asarray(pose, float)), pusher, h)

    def simulate_push(self, pose, pusher: str, twist, duration: float, dt: float = 0.05) -> dict:
        return self._core.simulate_push(list(np.asarray(pose, float)), pusher, list(np.asarray(twist, float)),
                                        float(duration), float(dt))


def is_3d(path) -> bool:
    """Whether a scene file is a 3-D scene (``dimension = 3``)."""
    import tomllib

    try:
        return tomllib.loads(Path(path).read_text()).get("dimension") == 3
    except (OSError, tomllib.TOMLDecodeError):
        return False
