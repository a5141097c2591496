"""The one validation module. Arguments of the API (``check_*``: numbers, counts, names, flags,
vectors, rows of vectors; a fault is an :class:`~regrasp.errors.ArgumentError` naming the
argument) and the values of every file regrasp reads besides scenes (:class:`FieldCheck`:
workcell, robot, trajectory, plan, graph; each value's type, finiteness, bounds and length, and
an object's keys; a fault is a :class:`~regrasp.errors.SceneError` naming the dotted field,
``samples[3].t``, ``features[2].pose[4]``, and the value found). Scene files are checked by the
Rust core, which bounds every number by ``MAX_MAGNITUDE``."""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass

import numpy as np

from . import _core
from .errors import ArgumentError, SceneError

#: The bound the core puts on the magnitude of every number argument (1e9).
MAX_MAGNITUDE = _core.MAX_MAGNITUDE

#: The input limits, stated once in the core (``crates/regrasp-core/src/scene/bounds.rs``) and
#: listed in docs/guarantees.md ("Limits"): what one input may hold, by name.
LIMITS = {k: int(v) if float(v).is_integer() else float(v) for k, v in _core.LIMITS.items()}
MAX_FILE_BYTES = LIMITS["file_bytes"]  # bytes of one input file
MAX_NESTING = LIMITS["nesting"]  # arrays and tables/objects nested in a TOML or JSON file
MAX_PLAN_STEPS = LIMITS["plan_steps"]  # steps of a plan
MAX_WORKCELL_FEATURES = LIMITS["workcell_features"]  # fixed features of a workcell
MAX_GRAPH_NODES = LIMITS["graph_nodes"]  # grasps of a grasp graph
MAX_GRAPH_EDGES = LIMITS["graph_edges"]  # regrasp actions of a grasp graph
MAX_TRAJECTORY_SAMPLES = LIMITS["trajectory_samples"]  # samples of a trajectory file
MAX_COORDINATE = LIMITS["coordinate"]  # m, any position's coordinate
MAX_ANGLE = LIMITS["angle"]  # rad, any angle of a pose


def check_array(x, name: str) -> np.ndarray:
    """``x`` as a float array, or an ArgumentError naming ``name`` (text, ragged lists, objects
    that are not numbers, integers too large for a float)."""
    if isinstance(x, (str, bytes)):
        raise ArgumentError(f"invalid `{name}`: expected numbers, got {type(x).__name__} {x!r:.60}", name)
    try:
        a = np.asarray(x)
        if a.dtype.kind not in "biuf":
            if a.dtype.kind != "O":
                raise TypeError(f"{a.dtype} values")
            a = a.astype(float)
        return np.asarray(a, dtype=float)
    except (TypeError, ValueError, OverflowError) as e:
        raise ArgumentError(f"invalid `{name}`: expected numbers ({e})", name) from None


def check_finite(a: np.ndarray, name: str) -> np.ndarray:
    """``a`` when every component is finite and at most ``MAX_MAGNITUDE`` (1e9) in
    magnitude, the bound the core puts on every number argument."""
    if not np.all(np.isfinite(a)):
        raise ArgumentError(f"invalid `{name}`: has a non-finite component", name)
    if a.size and np.max(np.abs(a)) > MAX_MAGNITUDE:
        raise ArgumentError(f"invalid `{name}`: components must be at most {MAX_MAGNITUDE:g} in magnitude", name)
    return a


def finite_number(x) -> bool:
    """Whether ``x`` is a real number (not a bool) that is finite as a float: an integer too
    large for one (a file's 10^400) is not."""
    if not isinstance(x, numbers.Real) or isinstance(x, (bool, np.bool_)):
        return False
    try:
        return math.isfinite(float(x))
    except OverflowError:
        return False


def plain_numbers(x, n: int) -> list | None:
    """The ``n`` numbers of ``x`` (a list, tuple or 1-D numeric array) as a list when they are
    plain numbers within ``MAX_MAGNITUDE``, else None: the common case checked without numpy's
    reductions, which cost a few µs per call."""
    if type(x) is np.ndarray:
        if x.shape != (n,) or x.dtype.kind not in "fiu":
            return None
        x = x.tolist()
    elif type(x) not in (list, tuple) or len(x) != n:
        return None
    return list(x) if all(type(v) in (float, int) and -MAX_MAGNITUDE <= v <= MAX_MAGNITUDE for v in x) else None


def check_vector(x, n: int, name: str) -> np.ndarray:
    """A vector of ``n`` finite numbers."""
    plain = plain_numbers(x, n)
    if plain is not None:
        return np.array(plain, dtype=float)
    a = check_array(x, name)
    if a.shape != (n,):
        raise ArgumentError(f"invalid `{name}`: expected {n} numbers, got shape {a.shape}", name)
    return check_finite(a, name)


def check_rows(x, name: str, n: int = 3, finite: bool = False) -> np.ndarray:
    """An (m, n) array (one vector of ``n`` is one row), m >= 1; of finite numbers with ``finite``
    (batches report a non-finite row in its status instead)."""
    a = np.ascontiguousarray(check_array(x, name))
    if a.ndim == 1 and a.shape == (n,):
        a = a[None, :]
    if a.ndim != 2 or a.shape[1] != n or a.shape[0] == 0:
        raise ArgumentError(f"invalid `{name}`: expected an (m, {n}) array with m >= 1, got shape {a.shape}", name)
    return check_finite(a, name) if finite else a


def check_vec_or_rows(x, name: str):
    """One 3-vector (a list for the core) or an (m, 3) array: what the cone tests take."""
    a = check_array(x, name)
    return check_rows(a, name, finite=True) if a.ndim == 2 else list(check_vector(a, 3, name))


def check_twists(x, name: str) -> np.ndarray:
    """Twists: one 3-vector or an array of them (shape (..., 3)), finite."""
    a = check_array(x, name)
    if a.ndim == 0 or a.shape[-1] != 3:
        raise ArgumentError(f"invalid `{name}`: expected twists of 3 numbers, got shape {a.shape}", name)
    return check_finite(a, name)


def check_number(x, name: str, low: float = 0.0, strict: bool = True, high: float = np.inf) -> float:
    """A finite real number in (low, high] (``strict``) or [low, high]."""
    ok = isinstance(x, (int, float, np.integer, np.floating)) and not isinstance(x, (bool, np.bool_))
    v = float(x) if ok and abs(x) < 1e308 else np.nan
    if not (np.isfinite(v) and (v > low if strict else v >= low) and v <= high):
        what = f"{'>' if strict else '>='} {low:g}" + ("" if high == np.inf else f" and <= {high:g}")
        raise ArgumentError(f"invalid `{name}`: must be a finite number {what} (got {x!r:.60})", name)
    return v


def check_count(x, name: str, low: int = 1, high: int = 2**31 - 1) -> int:
    """A whole number in [low, high]."""
    ok = isinstance(x, (int, np.integer)) and not isinstance(x, (bool, np.bool_))
    if not (ok and low <= int(x) <= high):
        raise ArgumentError(f"invalid `{name}`: must be a whole number in [{low}, {high}] (got {x!r:.60})", name)
    return int(x)


def check_name(x, name: str) -> str:
    """A name (of a pusher, a mode): a non-empty string."""
    if not isinstance(x, str) or not x.strip():
        raise ArgumentError(f"invalid `{name}`: must be a non-empty name (got {x!r:.60})", name)
    return x


def check_flag(x, name: str) -> bool:
    """``True`` or ``False`` (a bool, not a number)."""
    if not isinstance(x, (bool, np.bool_)):
        raise ArgumentError(f"invalid `{name}`: must be True or False (got {x!r:.60})", name)
    return bool(x)


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

    def count(self, items, where: str, most: int, what: str) -> None:
        """At most ``most`` ``items`` (the input limit of ``what``, e.g. ``"features"``)."""
        if len(items) > most:
            raise SceneError(f"{self.file} field `{where}`: has {len(items)} {what}; at most {most} are allowed "
                             "(docs/guarantees.md, Limits)", where)

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
