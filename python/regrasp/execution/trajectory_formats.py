"""A robot's trajectory in the formats a controller loads (docs/trajectory-file.md, "Formats"):

- ``"json"``: our trajectory file (:class:`~regrasp.execution.trajectory.Trajectory`);
- ``"ros2"``: a ROS 2 ``trajectory_msgs/msg/JointTrajectory`` document in YAML (``header``,
  ``joint_names``; ``points`` with ``positions``, ``velocities``, ``accelerations``, ``effort``
  and ``time_from_start`` as ``sec``/``nanosec``), as ``ros2 topic pub`` takes a message;
- ``"csv"``: a header row (``t``, the joints' positions, ``NAME.vel``, ``NAME.acc``,
  ``grip_force``) and a row per sample, every number written exactly (``repr``), so that
  :func:`read_csv` gives the same numbers back.

The ROS 2 and CSV formats carry a robot's joints, velocities and accelerations; a free gripper's
trajectory (no joints) is our JSON only."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import ArgumentError, SceneError
from ..fields import MAX_MAGNITUDE, MAX_TRAJECTORY_SAMPLES, FieldCheck

#: The formats and the extensions that choose them.
FORMATS = {"json": (".json",), "ros2": (".yaml", ".yml"), "csv": (".csv",)}
#: The CSV's first and last columns, and the suffixes of the joints' velocity and acceleration columns.
CSV_TIME, CSV_GRIP, CSV_VEL, CSV_ACC = "t", "grip_force", ".vel", ".acc"
_CHECK = FieldCheck("trajectory CSV")


def format_of(path, format: str | None) -> str:
    """``format`` (one of :data:`FORMATS`), or the one ``path``'s extension names; else an
    ArgumentError naming ``format``."""
    if format is not None:
        if format not in FORMATS:
            raise ArgumentError(f"invalid `format`: one of {', '.join(FORMATS)} (got {format!r})", "format")
        return format
    ext = Path(path).suffix.lower()
    for name, exts in FORMATS.items():
        if ext in exts:
            return name
    known = ", ".join(e for exts in FORMATS.values() for e in exts)
    raise ArgumentError(f"invalid `format`: the file's extension {ext or '(none)'!r} names no format (one of "
                        f"{known}; or give the format)", "format")


def text_as(tr, path, format: str | None) -> str:
    """The text of trajectory ``tr`` in ``format`` (default: by ``path``'s extension)."""
    f = format_of(path, format)
    if f == "json":
        return tr.to_json() + "\n"
    return ros2_yaml(tr) if f == "ros2" else csv_text(tr)


def _rates(tr, what: str):
    if not tr.joint_names or tr.qd is None or tr.qdd is None:
        raise ArgumentError(f"invalid `format`: {what} needs a robot's joints with their velocities and "
                            "accelerations (a trajectory made with an arm; a free gripper's is JSON only)", "format")
    return np.asarray(tr.qd, float), np.asarray(tr.qdd, float)


def _float(x: float) -> str:
    """``x`` as YAML 1.1 reads a float back exactly (a mantissa with a point: ``1.0e-05``)."""
    s = repr(float(x))
    if "e" in s and "." not in s.split("e")[0]:
        m, e = s.split("e")
        s = f"{m}.0e{e}"
    if "e" in s and s.split("e")[1][0] not in "+-":
        m, e = s.split("e")
        s = f"{m}e+{e}"
    return s


def _list(v) -> str:
    return "[" + ", ".join(_float(x) for x in v) + "]"


def stamp(t: float) -> tuple[int, int]:
    """``t`` [s] ≥ 0 as ROS 2's ``builtin_interfaces/Duration`` (sec, nanosec < 10⁹)."""
    sec = math.floor(t)
    nsec = int(round((t - sec) * 1e9))
    if nsec >= 1_000_000_000:
        sec, nsec = sec + 1, nsec - 1_000_000_000
    return int(sec), nsec


def ros2_yaml(tr) -> str:
    """Trajectory ``tr`` as a ``trajectory_msgs/msg/JointTrajectory`` YAML document."""
    qd, qdd = _rates(tr, "a ROS 2 JointTrajectory")
    lines = ["header:", "  stamp:", "    sec: 0", "    nanosec: 0", "  frame_id: ''",
             "joint_names: [" + ", ".join(tr.joint_names) + "]", "points:"]
    for i, t in enumerate(tr.times):
        sec, nsec = stamp(float(t))
        lines += [f"- positions: {_list(tr.q[i])}", f"  velocities: {_list(qd[i])}",
                  f"  accelerations: {_list(qdd[i])}", "  effort: []",
                  "  time_from_start:", f"    sec: {sec}", f"    nanosec: {nsec}"]
    return "\n".join(lines) + "\n"


def csv_text(tr) -> str:
    """Trajectory ``tr`` as CSV (see the module's doc)."""
    qd, qdd = _rates(tr, "CSV")
    names = list(tr.joint_names)
    head = [CSV_TIME, *names, *(n + CSV_VEL for n in names), *(n + CSV_ACC for n in names), CSV_GRIP]
    rows = [",".join(head)]
    for i, t in enumerate(tr.times):
        rows.append(",".join(repr(float(x)) for x in (t, *tr.q[i], *qd[i], *qdd[i], tr.grip_force[i])))
    return "\n".join(rows) + "\n"


@dataclass(frozen=True)
class CsvTrajectory:
    """A trajectory CSV's content: ``joint_names``; per row ``times`` (n,) [s], ``q``, ``qd``,
    ``qdd`` (n, joints) [rad, rad/s, rad/s²] and ``grip_force`` (n,) [N]."""
    joint_names: list
    times: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    grip_force: np.ndarray


def read_csv(path) -> CsvTrajectory:
    """The trajectory CSV at ``path`` (as :func:`csv_text` writes it); a SceneError naming the row
    and column at fault, an ArgumentError (``path``) when it cannot be read."""
    from ..files import read_text

    return parse_csv(read_text(path, "path"))


def parse_csv(text: str) -> CsvTrajectory:
    """The trajectory CSV of ``text`` (see :func:`read_csv`)."""
    lines = [ln for ln in text.splitlines() if ln.strip()]
    if not lines:
        raise SceneError("trajectory CSV: no header row", "(file)")
    head = lines[0].split(",")
    n = (len(head) - 2) // 3
    names = head[1:1 + n]
    want = [CSV_TIME, *names, *(x + CSV_VEL for x in names), *(x + CSV_ACC for x in names), CSV_GRIP]
    if n < 1 or head != want or len(set(names)) != n:
        raise _CHECK.fail("(header)", f"must be {CSV_TIME}, the joints, their {CSV_VEL} and {CSV_ACC} columns, "
                          f"{CSV_GRIP}", lines[0][:200])
    _CHECK.count(lines[1:], "rows", MAX_TRAJECTORY_SAMPLES, "rows")
    rows = []
    for i, ln in enumerate(lines[1:]):
        cells = ln.split(",")
        if len(cells) != len(head):
            raise _CHECK.fail(f"rows[{i}]", f"must have {len(head)} cells", len(cells))
        try:
            row = [float(c) for c in cells]
        except ValueError:
            raise _CHECK.fail(f"rows[{i}]", "must be numbers", ln[:200]) from None
        bad = next((j for j, x in enumerate(row) if not math.isfinite(x) or abs(x) > MAX_MAGNITUDE), None)
        if bad is not None:
            raise _CHECK.fail(f"rows[{i}].{head[bad]}", f"must be a finite number within {MAX_MAGNITUDE:g}", cells[bad])
        if rows and row[0] <= rows[-1][0]:
            raise _CHECK.fail(f"rows[{i}].{CSV_TIME}", "times must increase strictly", row[0])
        rows.append(row)
    if not rows:
        raise _CHECK.fail("rows", "must hold at least one sample", 0)
    a = np.array(rows)
    return CsvTrajectory(names, a[:, 0], a[:, 1:1 + n], a[:, 1 + n:1 + 2 * n], a[:, 1 + 2 * n:1 + 3 * n], a[:, -1])
