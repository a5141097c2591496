"""What planar and 3-D scenes share: reading a scene file, telling the two kinds apart, and the
read-only properties that hand a value of the Rust core through."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import SceneError
from ..files import TOO_DEEP, as_path, parse_toml, read_text


def read_scene_file(path) -> tuple[Path, str]:
    """The path and text of a scene file; an :class:`ArgumentError` naming ``path`` when it
    cannot be read."""
    p = as_path(path, "path")
    return p, read_text(p, "path")


def is_3d_text(text: str) -> bool:
    """Whether scene text is a 3-D scene: it has a ``dimension`` key (a planar scene has none; the
    3-D loader checks that it is 3). Text that is not TOML counts as planar, whose loader then
    names the error."""
    try:
        d = parse_toml(text, "(toml)", lambda why: SceneError(f"scene field `(toml)`: {why}", "(toml)")
                       if why == TOO_DEEP else _NotToml())
    except _NotToml:
        return False
    return "dimension" in d


class _NotToml(Exception):
    """Scene text that is not TOML (the loader names the error)."""


def core_property(name: str, doc: str | None = None, wrap=None) -> property:
    """A read-only property that returns ``self._core.<name>`` (passed through ``wrap``)."""

    def get(self):
        v = getattr(self._core, name)
        return v if wrap is None else wrap(v)

    return property(get, doc=doc)


@dataclass(frozen=True)
class Task:
    """A regrasp task: ``start`` and ``goal`` poses (planar ``[x, z, theta]`` (m, m, rad); 3-D
    ``[x, y, z, qw, qx, qy, qz]`` (m, unit quaternion)) and the goal ``tolerance`` (planar: per
    coordinate (m, m, rad); 3-D: ``[x, y, z, angle]`` (m, m, m, rad)). Unpacks as
    ``start, goal, tolerance = task``."""
    start: np.ndarray
    goal: np.ndarray
    tolerance: np.ndarray

    def __iter__(self):
        return iter((self.start, self.goal, self.tolerance))

    def __getitem__(self, i):
        return (self.start, self.goal, self.tolerance)[i]

    def __len__(self) -> int:
        return 3
