"""Plain numpy implementations of the motion cone, written from the thesis equations
independently of the Rust core. They are the baselines of ``regrasp bench`` and an independent
check in the tests. Circular pads with uniform pressure only (k = 0.6 r).

* :func:`generators_numpy`: one cone per call, the way one would write it from the equations.
* :func:`generators_numpy_batch` / :func:`classify_numpy_batch`: vectorized over poses.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..scene.planar import Scene


@dataclass(frozen=True)
class RefParams:
    """The parameters of a grasp and a line pusher as the numpy reference takes them: mass [kg],
    COM [m], g [m/s²] and its direction, the pads' friction capacity and the pusher's contact."""
    mass: float
    com: np.ndarray
    g: float
    gdir: np.ndarray
    s: float  # mu_s * 2N
    k: float
    L: float
    points: np.ndarray
    normal: np.ndarray
    mu_p: float

    @classmethod
    def from_scene(cls, scene: Scene, pusher: str) -> "RefParams":
        """The parameters of ``pusher`` in a grasp ``scene`` with circular pads on the
        ellipsoidal limit surface, the model this reference implements (ValueError otherwise)."""
        if scene.kind != "grasp" or scene.pad is None or scene.pad[0] != "circle":
            raise ValueError("the numpy reference handles grasps with circular pads only")
        if scene.limit_surface != "ellipsoid":
            raise ValueError("the numpy reference is the ellipsoidal limit surface's (eq 3.7): take "
                             "scene.with_limit_surface('ellipsoid')")
        p = scene.pusher(pusher)
        gdir, g = scene.gravity
        mu_s = scene.pad_friction
        return cls(
            mass=scene.mass,
            com=scene.com,
            g=g,
            gdir=gdir,
            s=2 * scene.grip_force * mu_s,
            k=0.6 * scene.pad[1],
            L=scene.length,
            points=p.points,
            normal=p.normal / np.linalg.norm(p.normal),
            mu_p=p.friction,
        )

    def edges(self) -> np.ndarray:
        """Edge wrenches of the pusher's generalized friction cone (eq 3.6), (2m, 3)."""
        n = self.normal
        t = np.array([-n[1], n[0]])
        out = []
        for r in self.points:
            for f in (n + self.mu_p * t, n - self.mu_p * t):
                out.append([f[0], f[1], r[0] * f[1] - r[1] * f[0]])
        return np.array(out)


def _metric_norm(p: RefParams, v: np.ndarray) -> np.ndarray:
    """Norm of twists in the metric [velocity of the COM, L omega]."""
    w = v[..., 2]
    return np.sqrt((v[..., 0] - w * p.com[1]) ** 2 + (v[..., 1] + w * p.com[0]) ** 2 + (p.L * w) ** 2)


def generators_numpy(p: RefParams, pose) -> np.ndarray:
    """Polyhedral motion-cone generators at one ``pose`` ``[x, z, theta]`` (m, m, rad): unit twists
    in the COM metric (m/s, m/s, m/s)."""
    x, z, th = pose
    c, s = np.cos(th), np.sin(th)
    R = np.array([[c, -s], [s, c]])
    pad = R.T @ -np.array([x, z])
    Js = np.eye(3)
    Js[:2, :2] = R
    Js = Js @ np.array([[1.0, 0.0, -pad[1]], [0.0, 1.0, pad[0]], [0.0, 0.0, 1.0]])
    A = np.diag([1.0, 1.0, 1.0 / p.k**2]) / p.s**2
    fg = R.T @ p.gdir * (p.mass * p.g)
    wg = np.array([fg[0], fg[1], p.com[0] * fg[1] - p.com[1] * fg[0]])
    Jinv = np.linalg.inv(Js)
    ug = Jinv.T @ wg
    cq = ug @ A @ ug - 1.0
    if cq >= 0:
        raise RuntimeError("grasp cannot hold the object against gravity")
    out = []
    for e in p.edges():
        u = Jinv.T @ e
        a = u @ A @ u
        b = 2 * u @ A @ ug
        lam = (-b + np.sqrt(b * b - 4 * a * cq)) / (2 * a)
        v = Jinv @ A @ (lam * u + ug)
        out.append(v / _metric_norm(p, v))
    return np.array(out)


def _batch_frames(p: RefParams, poses: np.ndarray):
    th = poses[:, 2]
    c, s = np.cos(th), np.sin(th)
    # pad centre in the object frame: R^T (-t)
    px = -(c * poses[:, 0] + s * poses[:, 1])
    pz = -(-s * poses[:, 0] + c * poses[:, 1])
    n = len(poses)
    Js = np.zeros((n, 3, 3))
    Js[:, 0, 0], Js[:, 0, 1], Js[:, 1, 0], Js[:, 1, 1], Js[:, 2, 2] = c, -s, s, c, 1.0
    # last column: R @ [-pz, px] (the shift to the pad centre, eq 3.15's J_s)
    Js[:, 0, 2] = -c * pz - s * px
    Js[:, 1, 2] = -s * pz + c * px
    fgx = (c * p.gdir[0] + s * p.gdir[1]) * p.mass * p.g
    fgz = (-s * p.gdir[0] + c * p.gdir[1]) * p.mass * p.g
    wg = np.stack([fgx, fgz, p.com[0] * fgz - p.com[1] * fgx], axis=1)
    Jinv = np.linalg.inv(Js)
    return Js, Jinv, wg


def generators_numpy_batch(p: RefParams, poses: np.ndarray) -> np.ndarray:
    """Vectorized :func:`generators_numpy` over an (n, 3) array of poses (m, m, rad): (n, 2m, 3)."""
    poses = np.asarray(poses, dtype=float)
    _, Jinv, wg = _batch_frames(p, poses)
    Ad = np.array([1.0, 1.0, 1.0 / p.k**2]) / p.s**2
    JinvT = np.transpose(Jinv, (0, 2, 1))
    ug = np.einsum("nij,nj->ni", JinvT, wg)
    cq = np.einsum("ni,i,ni->n", ug, Ad, ug) - 1.0
    u = np.einsum("nij,ej->nei", JinvT, p.edges())
    a = np.einsum("nei,i,nei->ne", u, Ad, u)
    b = 2 * np.einsum("nei,i,ni->ne", u, Ad, ug)
    lam = (-b + np.sqrt(b * b - 4 * a * cq[:, None])) / (2 * a)
    w = lam[..., None] * u + ug[:, None, :]
    v = np.einsum("nij,nej->nei", Jinv, w * Ad)
    return v / _metric_norm(p, v)[..., None]


def classify_numpy_batch(p: RefParams, poses: np.ndarray, twists: np.ndarray) -> np.ndarray:
    """Exact membership (line pushers) of twist i (m/s, m/s, rad/s) at pose i (m, m, rad),
    vectorized: bool (n,)."""
    poses = np.asarray(poses, dtype=float)
    Js, _, wg = _batch_frames(p, poses)
    Ad = np.array([1.0, 1.0, 1.0 / p.k**2]) / p.s**2
    vs = np.einsum("nij,nj->ni", Js, twists)
    w = vs / Ad
    w /= np.sqrt(np.einsum("ni,ni->n", vs, w))[:, None]
    wp = np.einsum("nji,nj->ni", Js, w) - wg
    # facets of the line pusher's cone: inward normals from pairs of edges in the wrench metric
    # [f, moment about the COM / L] (the same facets in any metric; this one sets the margins)
    def scaled(w):
        return np.stack([w[..., 0], w[..., 1], (w[..., 2] - (p.com[0] * w[..., 1] - p.com[1] * w[..., 0])) / p.L], -1)

    E = scaled(p.edges())
    normals = []
    for i in range(len(E)):
        for j in range(i + 1, len(E)):
            nrm = np.cross(E[i], E[j])
            if np.linalg.norm(nrm) < 1e-12:
                continue
            others = [E[k] @ nrm for k in range(len(E)) if k not in (i, j)]
            if all(o >= -1e-12 for o in others):
                normals.append(nrm / np.linalg.norm(nrm))
            elif all(o <= 1e-12 for o in others):
                normals.append(-nrm / np.linalg.norm(nrm))
    N = np.array(normals)
    ws = scaled(wp)
    ws /= np.linalg.norm(ws, axis=1)[:, None]
    return np.all(ws @ N.T >= -1e-9, axis=1)
