"""Pictures of grasps and grasp graphs (thesis Fig 1-2): a grasp drawn in the plane of the pads
(the hand frame's x-z, the palm up) — the object's outline (its hull's projection), the pad, the
fingers and the centre of mass — and the graph with a small drawing per grasp and an arrow per
edge labelled with its action and measured success rate (solid: ≥ 50 % of runs reached the
intended grasp; dashed: fewer)."""

from __future__ import annotations

import numpy as np

from .. import pose as P
from ..extras import need

SOLID = 0.5  # an edge drawn solid at this success rate or more


def outline(vertices, pose) -> np.ndarray:
    """The (k, 2) outline (x, z) [m] of the object's hull at in-hand ``pose``, seen along the grasp axis."""
    ConvexHull = need("scipy.spatial", "robot").ConvexHull
    v = P.transform(pose, np.asarray(vertices, float))[:, [0, 2]]
    return v[ConvexHull(v).vertices]


def draw_grasp(ax, vertices, pose, com=(0.0, 0.0, 0.0), title: str | None = None) -> None:
    """Draws the grasp at in-hand ``pose`` ``[x, y, z, qw, qx, qy, qz]`` (m) of the object (hull ``vertices``
    [m], centre of mass ``com`` [m]) on ``ax``, in mm."""
    mpl = need("matplotlib", "plot")  # noqa: F841
    from matplotlib.patches import Polygon, Rectangle

    from ..robot.pads import HALF_WIDTH, LENGTH

    ax.add_patch(Polygon(outline(vertices, pose) * 1e3, closed=True, fc="#5a9bd5", ec="k", lw=0.8))
    ax.add_patch(Rectangle((-HALF_WIDTH * 1e3, -LENGTH / 2 * 1e3), 2 * HALF_WIDTH * 1e3, LENGTH * 1e3,
                           fc="none", ec="#333333", lw=1.2, ls="-"))
    ax.add_patch(Rectangle((-HALF_WIDTH * 1e3, LENGTH / 2 * 1e3), 2 * HALF_WIDTH * 1e3, 25, fc="#999999", ec="none",
                           alpha=0.6))
    c = P.transform(pose, np.asarray(com, float))
    ax.plot(c[0] * 1e3, c[2] * 1e3, "o", ms=3, color="#c00000")
    ax.set_aspect("equal")
    ax.set_xlim(-50, 50)
    ax.set_ylim(-55, 45)
    ax.axis("off")
    if title:
        ax.set_title(title, fontsize=7, pad=1)


def draw_graph(graph, path, taxonomy=None, com=(0.0, 0.0, 0.0)) -> None:
    """Draws the grasp graph (a :class:`~.graph.GraspGraph`) to image ``path``: the grasps that
    some edge touches, each as a small drawing, and the edges (see the module's doc). The
    object's ``taxonomy`` and centre of mass ``com`` [m] (default: read from the graph's object
    file)."""
    need("matplotlib", "plot")
    nx = need("networkx", "robot")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..files import atomic_write
    from .taxonomy import Grasp

    nodes = {n["name"]: Grasp.from_dict(n) for n in graph.nodes}
    if taxonomy is None:
        from .graph import _object

        scene, taxonomy, obj = _object(graph.object["file"])
        com = obj.com
    G = nx.MultiDiGraph()
    for e in graph.edges:
        if e.trials and e.target is not None and e.target != e.source:
            G.add_edge(e.source, e.target, action=e.action, p=e.success_rate)
    if G.number_of_nodes() == 0:
        G.add_nodes_from(list(nodes)[:12])
    pos = nx.kamada_kawai_layout(nx.Graph(G)) if G.number_of_nodes() > 2 else nx.circular_layout(G)
    fig = plt.figure(figsize=(12, 9))
    ax = fig.add_axes([0, 0, 1, 1])
    ax.set_xlim(-1.25, 1.25)
    ax.set_ylim(-1.2, 1.2)
    ax.axis("off")
    seen: dict = {}
    for u, v, d in G.edges(data=True):
        k = seen.setdefault((u, v), 0)
        seen[(u, v)] += 1
        rad = 0.15 + 0.12 * k
        ax.annotate("", xy=pos[v], xytext=pos[u], arrowprops=dict(
            arrowstyle="-|>", lw=1.2, color="#1f4e79" if d["p"] >= SOLID else "#7f7f7f",
            ls="-" if d["p"] >= SOLID else "--", connectionstyle=f"arc3,rad={rad}", shrinkA=38, shrinkB=38))
        mid = (np.asarray(pos[u]) + np.asarray(pos[v])) / 2
        normal = np.array([pos[v][1] - pos[u][1], -(pos[v][0] - pos[u][0])])  # the side arc3 bends to
        ax.text(*(mid + rad * 0.5 * normal), f"{d['action']} {d['p']:.0%}", fontsize=6.5, ha="center", va="center",
                bbox=dict(fc="white", ec="none", alpha=0.8, pad=0.5))
    for n, (x, y) in pos.items():
        sub = fig.add_axes([(x + 1.25) / 2.5 - 0.045, (y + 1.2) / 2.4 - 0.06, 0.09, 0.12])
        draw_grasp(sub, taxonomy.vertices, nodes[n].pose, com, n)
    fig.suptitle(f"grasp graph of {graph.object['name']}: {sum(e.trials for e in graph.edges)} simulated trials",
                 fontsize=10, y=0.995)
    atomic_write(path, lambda tmp: fig.savefig(tmp, dpi=110, format=str(path).rsplit(".", 1)[-1]))
    plt.close(fig)
