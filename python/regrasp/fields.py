"""Checks of the values in a file that regrasp reads besides scenes (workcell, trajectory): each
value's type, finiteness, bounds and length, and an object's keys. A fault is a
:class:`~regrasp.errors.SceneError` naming the dotted field (``samples[3].t``,
``features[2].pose[4]``) and the value found. Scene files are checked by the Rust core."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .errors import SceneError


@dataclass(frozen=True)
class FieldCheck:
    """The checks of one kind of file: ``file`` (e.g. ``"workcell"``) starts every message."""

    file: str

    def fail(self, where: str, what: str, got) -> SceneError:
        """The error of field ``where``: ``what`` it must be, and what it is (``got``)."""
        return SceneError(f"{self.file} field `{where}`: {what} (got {got!r:.80})", where)

    def number(self, x, where: str, lo: float = -math.inf, hi: float = math.inf, unit: str = "") -> float:
        """``x`` as a float: a finite number in [``lo``, ``hi``] (in ``unit``, e.g. m)."""
        if isinstance(x, bool) or not isinstance(x, (int, float, np.integer, np.floating)):
            raise self.fail(where, "must be a number", x)
        v = float(x)
        if not math.isfinite(v) or not lo <= v <= hi:
            raise self.fail(where, f"must be finite and in [{lo:g}, {hi:g}]{' ' + unit if unit else ''}", x)
        return v

    def integer(self, x, where: str, lo: int, hi: int) -> int:
        """``x`` as an int: a whole number in [``lo``, ``hi``] (not a bool)."""
        if isinstance(x, bool) or not isinstance(x, (int, np.integer)) or not lo <= int(x) <= hi:
            raise self.fail(where, f"must be an integer in [{lo}, {hi}]", x)
        return int(x)

    def name(self, x, where: str) -> str:
        """``x``: a non-blank string."""
        if not isinstance(x, str) or not x.strip():
            raise self.fail(where, "must be a non-blank string", x)
        return x

    def vector(self, x, n: int, where: str, lo: float = -math.inf, hi: float = math.inf, unit: str = "",
               what: str = "") -> np.ndarray:
        """``x`` as an array of exactly ``n`` numbers (``what`` they are, e.g. ``[x, y, z]``), each
        as :meth:`number` (a component named ``where[i]``)."""
        if isinstance(x, np.ndarray):
            x = x.tolist()
        if not isinstance(x, (list, tuple)) or len(x) != n:
            got = f"{len(x)} numbers" if isinstance(x, (list, tuple)) else x
            raise self.fail(where, f"expected {n} numbers{' ' + what if what else ''}", got)
        return np.array([self.number(v, f"{where}[{i}]", lo, hi, unit) for i, v in enumerate(x)], float)

    def keys(self, d, keys, where: str) -> None:
        """``d``: an object with exactly the (required) ``keys``, the unknown one named first."""
        if not isinstance(d, dict):
            raise self.fail(where or "(file)", "must be an object", type(d).__name__)
        pre = f"{where}." if where else ""
        for k in d:
            if k not in keys:
                raise self.fail(f"{pre}{k}", f"unknown key (the keys: {', '.join(keys)})", k)
        for k in keys:
            if k not in d:
                raise self.fail(f"{pre}{k}", "is required", None)
