"""Which workcell feature renders each push of a plan (thesis Fig 1-7: the pusher of the plan is
a fixed feature of the world; the gripper moves so that the feature pushes the object as planned).

A *push* is a run of consecutive plan steps with one pusher. Its pusher's contact frame C in the
object frame has its origin at the contact points' centroid, +z along the pusher's normal (the
direction it pushes the object) and +x along a line pusher's segment. A feature's contact
(:meth:`Workcell.contacts`) serves a pusher when

* the kinds fit: a point pusher on a corner; a line pusher on an edge at least as long as the
  segment, or, when it pushes from below (its normal within 45° of the scene's "up", the object
  resting on it), on a face that holds it; a patch (3 or more points) or a plane on a face that holds
  its points;
* the feature's friction is at least the pusher's (the plan's sticking relies on it).

A contact serves only when it keeps the scene's gravity (fixed in the gripper frame, as the
plan's mechanics assumed it) within ``max_tilt`` (default :data:`MAX_TILT`) of the world's −z at
the push's start. Among the contacts that serve it, one at the pusher's own friction (what the
plan assumed) beats one with more; then the one that keeps gravity closest wins
(ties: for a patch the smaller face, then the first in :meth:`Workcell.contacts` order); the contact frame's free turn about its +z (a corner's or a
face's any angle, an edge's half turn) is chosen for the same reason. When none serves a push,
an ExecutionError names the push (its index, pusher and the plan's path entries) and why.
:func:`candidates` lists the others too, for a world motion whose first choice collides."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import pose as P
from ..errors import ArgumentError, ExecutionError
from ..workcell.description import Contact, Workcell

#: Geometric tolerance [m] of the fits (a footprint within a face, a segment on an edge).
FIT_TOL = 1e-9
#: What each kind of pusher needs (for error messages).
NEEDS = {"point": "a corner", "line": "an edge at least as long as it (or, pushing from below, a face)",
         "patch": "a face that holds its points", "plane": "a face that holds its contact points"}
#: The default most [rad] a push may turn the plan's gravity (fixed in the gripper frame) away
#: from the world's −z: the plan's mechanics assumed the scene's gravity.
MAX_TILT = float(np.radians(10.0))
#: A line pusher pushes from below when its normal is within this angle [rad] of −gravity.
FROM_BELOW = np.pi / 4


@dataclass(frozen=True)
class PusherContact:
    """A pusher's contact at a pose: ``kind`` ``"point"``, ``"line"``, ``"patch"`` or
    ``"plane"``; ``frame`` (m, unit quaternion): the contact frame C in the object frame (see the
    module's doc); ``footprint`` (k, 2) [m]: the contact points in C's x-y plane; ``friction``."""
    name: str
    kind: str
    frame: np.ndarray
    footprint: np.ndarray
    friction: float


def pusher_contact(scene, name: str, pose) -> PusherContact:
    """Pusher ``name`` of ``scene`` against the object at ``pose`` (planar ``[x, z, theta]`` (m, m,
    rad) or 3-D ``[x, y, z, qw, qx, qy, qz]`` (m, quaternion); a plane's points depend on it)."""
    if scene.dimension == 2:
        p = scene.pusher(name)
        pts = np.column_stack([p.points[:, 0], np.zeros(len(p.points)), p.points[:, 1]])
        n, mu, plane = np.array([p.normal[0], 0.0, p.normal[1]]), float(p.friction), False
    else:
        pts, n, mu = scene.pusher_spec(name, pose)
        plane = scene.is_plane(name)
    n = n / np.linalg.norm(n)
    o = pts.mean(axis=0)
    if len(pts) == 2:
        x = pts[1] - pts[0]
        x /= np.linalg.norm(x)
        z = n - (n @ x) * x
        z /= np.linalg.norm(z)
    else:
        z, x = n, P.tangents(n)[0]
    frame = P.from_frame(np.column_stack([x, np.cross(z, x), z]), o)
    local = (pts - o) @ np.column_stack([x, np.cross(z, x)])
    kind = "plane" if plane else {1: "point", 2: "line"}.get(len(pts), "patch")
    return PusherContact(name, kind, frame, local, mu)


@dataclass(frozen=True)
class Assignment:
    """Push ``index`` of a plan: pusher ``pusher`` moves the object from ``path[first]`` to
    ``path[last]``; it is rendered by the workcell contact ``feature`` (a :class:`Contact`'s
    name) whose contact frame in the world is ``frame`` (m, unit quaternion; the contact's frame
    turned about its x within its cone, then about its z, as chosen); ``tilt`` [rad]: the angle between the scene's gravity and the
    world's −z at the push's start; ``contact``: the pusher's contact at ``path[first]``."""
    index: int
    pusher: str
    first: int
    last: int
    feature: str
    frame: np.ndarray
    tilt: float
    contact: PusherContact


def pushes(pushers: list) -> list[tuple[str, int, int]]:
    """The pushes of a plan's ``pushers`` (``pushers[0]`` None): ``(pusher, first, last)`` per run
    of steps with one pusher, ``first``/``last`` the path indices where it starts and ends."""
    out: list = []
    for i in range(1, len(pushers)):
        if out and out[-1][0] == pushers[i] and out[-1][2] == i - 1:
            out[-1] = (pushers[i], out[-1][1], i)
        else:
            out.append((pushers[i], i - 1, i))
    return out


def gravity_in_gripper(scene) -> np.ndarray:
    """The unit direction of the scene's gravity in the gripper frame (3-D; a planar scene's
    gripper X-Z plane is the 3-D x-z plane)."""
    if scene.dimension == 2:
        d, _ = scene.gravity
        g = np.array([d[0], 0.0, d[1]])
    else:
        g = scene.gravity
    ng = np.linalg.norm(g)
    return g / ng if ng > 0 else np.array([0.0, 0.0, -1.0])


def _turns(c: Contact, pusher_frame, gravity: np.ndarray) -> list[tuple[float, float]]:
    """The candidate ``(beta, phi)`` [rad] of contact ``c``'s frame, turned by ``beta`` about its x
    (within its cone) then by ``phi`` about its z, for a pusher whose contact frame in the gripper
    frame is ``pusher_frame`` (m, quaternion): those that best align the gripper-frame ``gravity``
    with the world's −z first, then the plain ones (an edge's half turns, a face's quarter
    turns)."""
    # G = F Rx(beta) Rz(phi) Pc⁻¹: maximize a · Rx(beta) Rz(phi) b, a = −e_z in the contact
    # frame, b = gravity in Pc
    a = P.quat_matrix(c.frame[3:]).T @ np.array([0.0, 0.0, -1.0])
    b = P.quat_matrix(pusher_frame[3:]).T @ gravity
    if c.kind == "edge":
        out = []
        for phi in (0.0, np.pi):
            v = np.array([np.cos(phi) * b[0] - np.sin(phi) * b[1], np.sin(phi) * b[0] + np.cos(phi) * b[1], b[2]])
            best = float(np.arctan2(a[2] * v[1] - a[1] * v[2], a[1] * v[1] + a[2] * v[2]))
            out += [(float(np.clip(best, -c.cone, c.cone)), phi), (-c.cone, phi), (c.cone, phi), (0.0, phi)]
        return out
    phi = float(np.arctan2(a[1] * b[0] - a[0] * b[1], a[0] * b[0] + a[1] * b[1]))
    return [(0.0, phi)] + [(0.0, k * np.pi / 2) for k in range(4)]


def serves(c: Contact, pc: PusherContact, phi: float = 0.0, from_below: bool = False) -> str | None:
    """Why contact ``c`` turned by ``phi`` [rad] about its +z cannot render pusher contact ``pc``
    (None when it can); ``from_below``: whether a line pusher pushes from below."""
    if c.friction < pc.friction:
        return f"its friction {c.friction:g} is below the pusher's {pc.friction:g}"
    if pc.kind == "point":
        return None if c.kind == "corner" else f"a point pusher needs a corner, not a {c.kind}"
    if c.kind == "corner":
        return f"a corner renders only a point pusher, not a {pc.kind}"
    if c.kind == "edge":
        if pc.kind != "line":
            return f"an edge renders only a line pusher, not a {pc.kind}"
        need = float(np.ptp(pc.footprint[:, 0]))
        return None if need <= c.length + FIT_TOL else f"the edge ({c.length:g} m) is shorter than the pusher ({need:g} m)"
    if pc.kind == "line" and not from_below:
        return "a face renders a line pusher only from below (the object resting on it)"
    cph, sph = np.cos(phi), np.sin(phi)
    xy = pc.footprint @ np.array([[cph, sph], [-sph, cph]])  # the footprint turned by phi
    if np.all(np.abs(xy) <= c.extent + FIT_TOL):
        return None
    return f"the face ({2 * c.extent[0]:g} x {2 * c.extent[1]:g} m) does not hold the pusher's points"


def candidates(scene, poses, pushers: list, workcell: Workcell, max_tilt: float = MAX_TILT,
               contacts: list | None = None) -> list[list[Assignment]]:
    """For each push of a plan (arguments as :func:`assign`: ``poses`` planar (m, m, rad) or 3-D
    (m, quaternion)), every contact of ``workcell`` that
    serves it, best first: :func:`assign`'s choice, then the others by tilt (then, for a patch,
    by face size), each with its own best turn (``contacts``: ``workcell.contacts()``, when
    already made). ExecutionError (field ``plan.path[i].pusher``)
    when none serves a push."""
    if isinstance(max_tilt, bool) or not isinstance(max_tilt, (int, float)) or not 0 <= max_tilt <= np.pi:
        raise ArgumentError(f"invalid `max_tilt`: an angle in [0, pi] rad (got {max_tilt!r:.40})", "max_tilt")
    g = gravity_in_gripper(scene)
    contacts = workcell.contacts() if contacts is None else contacts
    out = []
    for k, (name, first, last) in enumerate(pushes(list(pushers))):
        pc = pusher_contact(scene, name, poses[first])
        O = _object_pose(scene, poses[first])
        Pc = P.compose(O, pc.frame)
        below = float(P.quat_rotate(Pc[3:], [0.0, 0, 1]) @ -g) >= np.cos(FROM_BELOW) - 1e-12
        best, each, reasons = None, [], {}
        for c in contacts:
            mine = None
            for beta, phi in _turns(c, Pc, g):
                why = serves(c, pc, phi, below)
                if why is not None:
                    reasons.setdefault(c.kind, (c.name, why))
                    continue
                F = P.compose(c.frame, P.x_turn(beta), P.z_turn(phi))
                G = P.compose(F, P.inverse(Pc))
                tilt = float(np.arccos(np.clip(P.quat_rotate(G[3:], g) @ [0, 0, -1.0], -1, 1)))
                if tilt > max_tilt + 1e-12:
                    reasons.setdefault("tilt", (c.name, f"the plan's gravity would be {np.degrees(tilt):.1f}° off the "
                                                        f"world's, more than max_tilt {np.degrees(max_tilt):.1f}°"))
                    continue
                area = float(np.prod(c.extent)) if pc.kind == "patch" else 0.0
                cand = (tilt, c, F, area, c.friction > pc.friction + 1e-9)
                if best is None or _better(cand, best):
                    best = cand
                if mine is None or _better(cand, mine):
                    mine = cand
            if mine is not None:
                each.append(mine)
        if best is None:
            why = "; ".join(f"{n}: {r}" for n, r in reasons.values()) or "the workcell offers no contact"
            err = ExecutionError(
                f"push {k} (pusher `{name}`, plan path[{first}] to path[{last}]): no feature of workcell "
                f"`{workcell.name}` serves this {pc.kind} pusher, which needs "
                f"{NEEDS[pc.kind]} with friction at least {pc.friction:g} ({why})", f"plan.path[{first + 1}].pusher")
            err.pusher = name  # the pusher no feature serves (pick_place re-plans without it)
            raise err
        rest = sorted((e for e in each if e[1] is not best[1]), key=lambda e: (e[4], e[0], e[3]))
        out.append([Assignment(k, name, first, last, e[1].name, e[2], e[0], pc) for e in [best] + rest])
    return out


def _better(a, b) -> bool:
    """Whether candidate ``a`` (tilt, contact, frame, area, friction above the pusher's) beats
    ``b``: a contact at the pusher's own friction first, then the smaller tilt, then the smaller
    face."""
    if a[4] != b[4]:
        return not a[4]
    return a[0] < b[0] - 1e-9 or (a[0] < b[0] + 1e-9 and a[3] < b[3])


def assign(scene, poses, pushers: list, workcell: Workcell, max_tilt: float = MAX_TILT) -> list[Assignment]:
    """The feature of ``workcell`` for each push of a plan (``poses``: the plan's path poses,
    planar (n, 3) (m, m, rad) or 3-D (n, 7) (m, quaternion); ``pushers``: its pusher names,
    ``pushers[0]`` None), by the rules of the module's doc; a contact that would turn the scene's
    gravity more than ``max_tilt`` [rad] from the world's −z does not serve (default
    :data:`MAX_TILT`; π: any).
    ExecutionError (field ``plan.path[i].pusher``) when no feature serves a push."""
    return [c[0] for c in candidates(scene, poses, pushers, workcell, max_tilt)]


def _object_pose(scene, q) -> np.ndarray:
    """The object's pose in the gripper frame as a 3-D pose (m, unit quaternion)."""
    return np.asarray(P.planar_to_spatial(q) if scene.dimension == 2 else q, float)
