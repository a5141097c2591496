"""The trajectory file (docs/trajectory-file.md): a timed world-frame motion of the gripper (and,
with a robot, its joints) with the grip force, each sample labelled, and the feature of each
push. :class:`Trajectory` reads and writes it (JSON, written atomically); a
:class:`~regrasp.execution.WorldMotion` makes one with ``to_trajectory()``. The loader is
strict: a SceneError names the field at fault as a path (``samples[3].t``)."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import ArgumentError, SceneError
from ..fields import MAX_ANGLE, MAX_COORDINATE, MAX_TRAJECTORY_SAMPLES, FieldCheck
from ..files import parse_json

#: Sample labels, in the order a push meets them (a world motion's and its trajectory's).
LABELS = ("start", "transfer", "approach", "push", "retreat")

#: The file's ``format`` and ``version``.
FORMAT = "regrasp-trajectory"
VERSION = 1
#: How far [−] a quaternion's norm may be from 1 in the file.
UNIT_TOL = 1e-6
#: The keys of the file, of a sample and of an assignment (all required).
KEYS = ("format", "version", "scene", "workcell", "robot", "joint_names", "samples", "assignments")
SAMPLE_KEYS = ("t", "q", "gripper_pose", "grip_force", "label", "push")
#: A robot's samples may also carry the joint velocities and accelerations (both, in every sample).
MOTION_KEYS = ("qd", "qdd")
#: The most a joint velocity [rad/s] or acceleration [rad/s²] may be in the file.
MAX_RATE = 1e4
ASSIGNMENT_KEYS = ("pusher", "feature", "first", "last", "frame", "tilt", "penetration")


MAX_SECONDS = 1e6  # s, the latest time of a sample (11.6 days)
MAX_FORCE = 1e6  # N, the largest grip force (the core's largest normal force)

_CHECK = FieldCheck("trajectory")
_fail, _number, _integer, _name, _vector, _keys = (_CHECK.fail, _CHECK.number, _CHECK.integer, _CHECK.name,
                                                   _CHECK.vector, _CHECK.keys)


def _pose(x, where: str) -> np.ndarray:
    p = _vector(x, 7, where, -MAX_COORDINATE, MAX_COORDINATE, "m")
    if abs(np.linalg.norm(p[3:]) - 1) > UNIT_TOL:
        raise _fail(where, f"the quaternion [qw, qx, qy, qz] must have unit norm (within {UNIT_TOL:g})",
                    float(np.linalg.norm(p[3:])))
    return p


@dataclass(frozen=True)
class PushRecord:
    """The feature of push ``index``: ``pusher``, the workcell contact ``feature`` (a
    :class:`~regrasp.workcell.Contact` name), the plan's path indices ``first``/``last``, the
    contact ``frame`` in the world (m, unit quaternion), the gravity ``tilt`` [rad] and the
    ``penetration`` [m] (as in :class:`~regrasp.execution.WorldMotion`)."""
    pusher: str
    feature: str
    first: int
    last: int
    frame: np.ndarray
    tilt: float
    penetration: float


@dataclass(eq=False)
class Trajectory:
    """A trajectory file's content: ``scene`` (its name), ``workcell`` (its name), ``robot`` (its
    model name, None for a free gripper), ``joint_names`` (empty for a free gripper); per sample
    (n of them): ``times`` (n,) [s], strictly increasing; ``q`` (n, len(joint_names)) joint
    positions [rad]; ``gripper`` (n, 7) the gripper's world pose (m, unit quaternion);
    ``grip_force`` (n,) [N] per finger; ``labels`` (one of :data:`LABELS` each); ``push`` (n,)
    the push index (−1: none, ``null`` in the file); ``assignments``: a :class:`PushRecord` per
    push; with a robot, ``qd`` and ``qdd`` (n, len(joint_names)) the joint velocities [rad/s] and
    accelerations [rad/s²] (None: not given). Checked on construction (SceneError naming the
    field). :meth:`save` writes it as our JSON, a ROS 2 ``JointTrajectory`` or CSV
    (:mod:`.trajectory_formats`)."""
    scene: str
    workcell: str
    robot: str | None
    joint_names: list
    times: np.ndarray
    q: np.ndarray
    gripper: np.ndarray
    grip_force: np.ndarray
    labels: list
    push: np.ndarray
    assignments: list = field(default_factory=list)
    qd: np.ndarray | None = None
    qdd: np.ndarray | None = None

    def __post_init__(self):
        checked = _from_dict(self.to_dict(check=False))
        for k in ("times", "q", "gripper", "grip_force", "push", "labels", "assignments", "joint_names", "qd", "qdd"):
            setattr(self, k, getattr(checked, k))

    def __len__(self) -> int:
        """The number of samples."""
        return len(self.times)

    def __eq__(self, other) -> bool:
        """Trajectories are equal when their files are."""
        return isinstance(other, Trajectory) and self.to_dict() == other.to_dict()

    __hash__ = None  # type: ignore[assignment]

    @property
    def duration(self) -> float:
        """The last sample's time [s]."""
        return float(self.times[-1])

    def to_dict(self, check: bool = True) -> dict:
        """The file's content as JSON-ready lists (see docs/trajectory-file.md)."""
        def lst(x):
            return x.tolist() if isinstance(x, (np.ndarray, np.generic)) else x

        n = len(self.times) if hasattr(self.times, "__len__") else 0

        def row(a, i):
            try:
                return lst(a[i])
            except (IndexError, TypeError, KeyError):
                return None

        samples = [{"t": row(self.times, i), "q": row(self.q, i), "gripper_pose": row(self.gripper, i),
                    "grip_force": row(self.grip_force, i), "label": row(self.labels, i),
                    "push": None if row(self.push, i) is None or row(self.push, i) == -1 else row(self.push, i)}
                   for i in range(n)]
        if self.qd is not None or self.qdd is not None:
            for i, sample in enumerate(samples):
                sample["qd"], sample["qdd"] = row(self.qd, i), row(self.qdd, i)
        return {"format": FORMAT, "version": VERSION, "scene": self.scene, "workcell": self.workcell,
                "robot": self.robot, "joint_names": list(self.joint_names) if isinstance(self.joint_names,
                                                                                          (list, tuple)) else self.joint_names,
                "samples": samples,
                "assignments": [{"pusher": a.pusher, "feature": a.feature, "first": a.first, "last": a.last,
                                 "frame": lst(a.frame), "tilt": a.tilt, "penetration": a.penetration}
                                if isinstance(a, PushRecord) else a for a in self.assignments]}

    def to_json(self) -> str:
        """The file's JSON text: a key per line, a sample or an assignment per line."""
        d = self.to_dict()
        lines = []
        for k, v in d.items():
            if k in ("samples", "assignments"):
                rows = ",\n  ".join(json.dumps(r) for r in v)
                lines.append(f' "{k}": [\n  {rows}\n ]' if v else f' "{k}": []')
            else:
                lines.append(f" {json.dumps(k)}: {json.dumps(v)}")
        return "{\n" + ",\n".join(lines) + "\n}"

    def save(self, path, format: str | None = None) -> Path:
        """Writes the trajectory to ``path`` atomically (:func:`regrasp.files.write_text`) in
        ``format``: ``"json"`` (this file), ``"ros2"`` (a ``trajectory_msgs/JointTrajectory``
        document, YAML) or ``"csv"``; by default chosen by the extension (``.json``, ``.yaml`` /
        ``.yml``, ``.csv``). See :mod:`.trajectory_formats`."""
        from ..files import as_path, write_text
        from .trajectory_formats import text_as

        path = as_path(path, "path")
        return write_text(path, text_as(self, path, format))

    @classmethod
    def from_dict(cls, d) -> "Trajectory":
        """The trajectory of a dict laid out as the file; SceneError naming the field at fault."""
        return _from_dict(d)

    @classmethod
    def from_json(cls, text: str) -> "Trajectory":
        """The trajectory of the file's JSON text (SceneError ``(json)`` for a syntax error)."""
        if not isinstance(text, str):
            raise ArgumentError(f"invalid `text`: the trajectory file's text, a str (got {type(text).__name__})", "text")
        return _from_dict(parse_json(text, "(json)", lambda why: SceneError(f"trajectory file: {why}", "(json)"),
                                     constants=False))

    @classmethod
    def load(cls, path) -> "Trajectory":
        """The trajectory file at ``path``; ArgumentError when it cannot be read."""
        from ..files import read_text

        return cls.from_json(read_text(path, "path"))


def _from_dict(d) -> Trajectory:
    _keys(d, KEYS, "")
    if d["format"] != FORMAT:
        raise _fail("format", f"must be {FORMAT!r}", d["format"])
    if isinstance(d["version"], bool) or d["version"] != VERSION:
        raise _fail("version", f"must be {VERSION}", d["version"])
    scene, workcell = _name(d["scene"], "scene"), _name(d["workcell"], "workcell")
    robot = None if d["robot"] is None else _name(d["robot"], "robot")
    joints = d["joint_names"]
    if not isinstance(joints, list):
        raise _fail("joint_names", "must be a list of joint names", joints)
    joints = [_name(j, f"joint_names[{i}]") for i, j in enumerate(joints)]
    if len(set(joints)) != len(joints):
        raise _fail("joint_names", "must not repeat a name", joints)
    if robot is None and joints:
        raise _fail("joint_names", "must be empty for a free gripper (robot null)", joints)
    if robot is not None and not joints:
        raise _fail("joint_names", f"must name the joints of robot {robot!r}", joints)
    A = d["assignments"]
    if not isinstance(A, list):
        raise _fail("assignments", "must be a list", A)
    records = []
    for k, a in enumerate(A):
        w = f"assignments[{k}]"
        _keys(a, ASSIGNMENT_KEYS, w)
        first = _integer(a["first"], f"{w}.first", 0, 10**9)
        last = _integer(a["last"], f"{w}.last", first + 1, 10**9)
        records.append(PushRecord(_name(a["pusher"], f"{w}.pusher"), _name(a["feature"], f"{w}.feature"), first, last,
                                  _pose(a["frame"], f"{w}.frame"), _number(a["tilt"], f"{w}.tilt", 0.0, math.pi),
                                  _number(a["penetration"], f"{w}.penetration", 0.0, 1.0, "m")))
    S = d["samples"]
    if not isinstance(S, list) or not S:
        raise _fail("samples", "must be a non-empty list", S)
    rates = isinstance(S[0], dict) and any(k in S[0] for k in MOTION_KEYS)
    if rates and robot is None:
        raise _fail("samples[0].qd", "joint velocities need a robot (robot is null)", S[0].get("qd"))
    _CHECK.count(S, "samples", MAX_TRAJECTORY_SAMPLES, "samples")
    _CHECK.count(A, "assignments", len(S), "assignments (at most one per sample)")
    t, q, g, f, lab, push, qd, qdd = [], [], [], [], [], [], [], []
    for i, s in enumerate(S):
        w = f"samples[{i}]"
        _keys(s, SAMPLE_KEYS + MOTION_KEYS if rates else SAMPLE_KEYS, w)
        if rates:
            qd.append(_vector(s["qd"], len(joints), f"{w}.qd", -MAX_RATE, MAX_RATE, "rad/s"))
            qdd.append(_vector(s["qdd"], len(joints), f"{w}.qdd", -MAX_RATE, MAX_RATE, "rad/s²"))
        t.append(_number(s["t"], f"{w}.t", 0.0, MAX_SECONDS, "s"))
        if i and t[-1] <= t[-2]:
            raise _fail(f"{w}.t", f"times must increase strictly (samples[{i - 1}].t is {t[-2]!r})", s["t"])
        q.append(_vector(s["q"], len(joints), f"{w}.q", -MAX_ANGLE, MAX_ANGLE, "rad"))
        g.append(_pose(s["gripper_pose"], f"{w}.gripper_pose"))
        f.append(_number(s["grip_force"], f"{w}.grip_force", 0.0, MAX_FORCE, "N"))
        if s["label"] not in LABELS:
            raise _fail(f"{w}.label", f"must be one of {', '.join(LABELS)}", s["label"])
        lab.append(s["label"])
        push.append(-1 if s["push"] is None else _integer(s["push"], f"{w}.push", 0, max(len(records) - 1, 0)))
        if s["push"] is not None and not records:
            raise _fail(f"{w}.push", "must be null: there are no assignments", s["push"])
    tr = Trajectory.__new__(Trajectory)
    tr.scene, tr.workcell, tr.robot, tr.joint_names = scene, workcell, robot, joints
    tr.times, tr.q, tr.gripper = np.array(t), np.array(q, float).reshape(len(t), len(joints)), np.array(g)
    tr.grip_force, tr.labels, tr.push, tr.assignments = np.array(f), lab, np.array(push, int), records
    tr.qd, tr.qdd = (np.array(qd, float).reshape(len(t), len(joints)), np.array(qdd, float).reshape(len(t), len(joints))) \
        if rates else (None, None)
    return tr
