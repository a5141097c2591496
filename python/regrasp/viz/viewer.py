"""The browser view of a scene or a plan: one self-contained HTML page (inline script, no
network, no libraries) drawn on a canvas that fills the window (or a notebook's frame) and
follows its size, at the screen's pixel density. In the gripper frame (the planner's view): the
ground under the object (perpendicular to gravity, or the scene's support), both jaws of the
parallel gripper (fingers, pads, palm) at the grasp's width, the object at the plan's poses
(slerp between knots; play/pause, step slider, speed), the pushers as small bodies on the object
(the one in contact red, its contact points marked), the gripper's axes (x red, y green, z blue),
gravity (g) and the goal (dashed). Drag to orbit, wheel to zoom. Planar scenes are shown as
their outline extruded across the jaw direction (see :mod:`regrasp.viz.view_data`).

The world view (:func:`workcell_html`, :func:`motion_html`; ``world_viewer.js``) draws a workcell
in the world frame (table, features, the robot's base, world axes) and a world motion along its
times: the gripper holding the object, its path coloured by label, the feature of each push
highlighted while it pushes (see :mod:`regrasp.viz.world_data`)."""

from __future__ import annotations

import html
import json
from pathlib import Path

import numpy as np

from ..errors import ArgumentError
from ..files import write_text
from .view_data import planar_description, spatial_description

SCRIPT = Path(__file__).with_name("viewer.js")
#: The vector and quaternion helpers both scripts share (prepended to each page's script).
MATH_SCRIPT = Path(__file__).with_name("view_math.js")
#: The world view's script (a workcell, a world motion).
WORLD_SCRIPT = Path(__file__).with_name("world_viewer.js")

#: The pages' shared style sheet (head: the page and its bar; tail: the canvas, legend, info).
STYLE_HEAD = """html,body{height:100%;margin:0}
body{font-family:system-ui,sans-serif;background:#fff;display:flex;flex-direction:column;overflow:hidden}
#bar{padding:6px 8px;display:flex;gap:10px;align-items:center;flex-wrap:wrap;background:#f4f4f4;border-bottom:1px solid #ddd}
"""
STYLE_TAIL = """#info{font-size:13px;color:#333}
#wrap{position:relative;flex:1;min-height:200px}
#c{position:absolute;left:0;top:0;width:100%;height:100%;display:block;cursor:grab}
#legend{position:absolute;right:8px;top:8px;font-size:12px;background:rgba(255,255,255,0.85);padding:4px 8px;
 border:1px solid #ddd;line-height:1.5;pointer-events:none}
#legend i{display:inline-block;width:12px;height:10px;margin-right:5px;vertical-align:middle}
#selftest{display:none}
"""

PAGE = r"""<!doctype html>
<html><head><meta charset="utf-8"><meta name="viewport" content="width=device-width, initial-scale=1">
<title>regrasp: __TITLE__</title>
<style>
__STYLE_HEAD__#t{flex:1;min-width:120px}
__STYLE_TAIL__</style></head><body>
<div id="bar"><button id="play">play</button>
<input id="t" type="range" min="0" max="1000" value="0" step="any" list="knots" title="along the plan"><datalist id="knots">__KNOTS__</datalist>
<label>speed <select id="speed"><option>0.25</option><option>0.5</option><option selected>1</option><option>2</option><option>4</option></select></label>
<span id="info"></span></div>
<div id="wrap"><canvas id="c" width="900" height="620"></canvas>
<div id="legend"><b>gripper frame</b> (drag: orbit, wheel: zoom)<br>
<i style="background:#9ebff0"></i>object<br><i style="border:1px dashed #148c3c"></i>goal<br>
<span class="jaws"><i style="background:#6e6e78"></i>jaws, <i style="background:#323232"></i>pads<br></span>
<i style="background:#e62828"></i>pusher in contact<br><i style="background:#cdbbe6"></i>other pushers<br>
<i style="background:#cdb996"></i>__GROUND__<br>
<span style="color:#d62728">x</span> <span style="color:#2ca02c">y</span> <span style="color:#1f5fd6">z</span> axes,
<span style="color:#7b2fbf">g</span> gravity</div></div>
<script id="data" type="application/json">__DATA__</script>
<script>
__SCRIPT__</script></body></html>
"""


def marks(scene) -> np.ndarray:
    """Which of the object's triangles are painted (1) — a sphere's alternate octants, so its
    turning shows (the thesis' paint marks on the ball, Fig 4-8); none for other objects."""
    v, t = scene.mesh()
    if not scene.sphere:
        return np.zeros(len(t), int)
    c = np.asarray(v, float)[np.asarray(t, int)].mean(axis=1)
    return (np.prod(np.sign(c + 1e-12), axis=1) > 0).astype(int)


def description(scene, plan=None) -> dict:
    """What the page draws (see :mod:`regrasp.viz.view_data`), for ``scene`` (a planar
    :class:`~regrasp.Scene` or a :class:`~regrasp.Scene3D`) and ``plan`` (a :class:`~regrasp.Plan`
    for that scene; None: the scene alone, at its start, with its goal)."""
    if getattr(scene, "dimension", None) not in (2, 3) or not hasattr(scene, "pusher_names"):
        raise ArgumentError(f"invalid `scene`: a regrasp Scene or Scene3D (got {type(scene).__name__})", "scene")
    if plan is not None and not hasattr(plan, "check_for"):
        raise ArgumentError(f"invalid `plan`: a regrasp Plan (got {type(plan).__name__}; a plan dict: "
                            "Plan.from_json)", "plan")
    if plan is not None:
        plan.check_for(scene, "plan")
    poses, pushers = (None, None) if plan is None else (plan.poses, plan.pushers)
    if scene.dimension == 2:
        d = planar_description(scene, poses, pushers)
    else:
        d = spatial_description(scene, poses, pushers, marks(scene))
    d["name"] = scene.name
    return d


def page(scene, plan=None) -> str:
    """The HTML page (a str) of ``plan`` for ``scene``, or of the scene alone (``plan=None``)."""
    d = description(scene, plan)
    n = len(d["poses"]) - 1
    knots = "".join(f'<option value="{1000 * k / n:.3f}"></option>' for k in range(n + 1)) if n > 0 else ""
    ground = "ground" if d["ground"]["support"] is None else f"support ({html.escape(d['ground']['support'])})"
    text = json.dumps(d, allow_nan=False).replace("</", "<\\/")
    return (PAGE.replace("__STYLE_HEAD__", STYLE_HEAD).replace("__STYLE_TAIL__", STYLE_TAIL)
            .replace("__TITLE__", html.escape(scene.name)).replace("__KNOTS__", knots)
            .replace("__GROUND__", ground).replace("__SCRIPT__", MATH_SCRIPT.read_text() + SCRIPT.read_text()).replace("__DATA__", text))


def write_html(scene, plan, path) -> Path:
    """Writes :func:`page` of ``scene`` and ``plan`` (None: the scene alone) to ``path``
    (atomically; its folder created, once the page is made); returns the path."""
    p, text = Path(path), page(scene, plan)
    p.parent.mkdir(parents=True, exist_ok=True)  # atomic_write does not create folders
    return write_text(p, text)


def iframe(text: str, height: int = 480) -> str:
    """The page ``text`` in an ``<iframe srcdoc>`` of ``height`` [px] filling the cell's width
    (its script runs in the frame): what ``_repr_html_`` shows in Jupyter."""
    return (f'<iframe srcdoc="{html.escape(text, quote=True)}" style="width:100%;height:{int(height)}px;'
            f'border:1px solid #ddd" sandbox="allow-scripts"></iframe>')


def notebook_html(scene, plan=None, height: int = 480) -> str:
    """The page in an ``<iframe srcdoc>`` of ``height`` [px] filling the cell's width: what
    ``_repr_html_`` of scenes and plans shows in Jupyter (its script runs in the frame)."""
    return iframe(page(scene, plan), height)


def plan_html(plan, scene=None) -> str:
    """A plan's display in Jupyter: its browser view with ``scene``, else its summary table."""
    if scene is not None:
        return notebook_html(scene, plan)
    rows = [("scene", plan.scene), ("found", plan.found), ("stop reason", plan.stop_reason),
            ("steps", len(plan.poses) - 1), ("switch-overs", plan.switch_overs),
            ("planning time [s]", None if plan.planning_time_s is None else f"{plan.planning_time_s:.3g}"),
            ("valid", plan.valid)]
    body = "".join(f"<tr><th style='text-align:left'>{k}</th><td>{html.escape(str(v))}</td></tr>"
                   for k, v in rows if v is not None)
    return f"<table><caption>regrasp plan ({plan.dimension}-D)</caption>{body}</table>"


WORLD_PAGE = r"""<!doctype html>
<html><head><meta charset="utf-8"><meta name="viewport" content="width=device-width, initial-scale=1">
<title>regrasp: __TITLE__</title>
<style>
__STYLE_HEAD__#tbox{flex:1;min-width:120px;display:flex;flex-direction:column}
#t{width:100%;margin:0}
#strip{height:5px;width:100%}
__STYLE_TAIL__</style></head><body>
<div id="bar"><button id="play">play</button>
<div id="tbox"><input id="t" type="range" min="0" max="__DURATION__" value="0" step="any" title="time [s]"><div id="strip"></div></div>
<label>speed <select id="speed"><option>0.25</option><option>0.5</option><option selected>1</option><option>2</option><option>4</option></select></label>
<label><input id="follow" type="checkbox"> follow the gripper</label>
<span id="info"></span></div>
<div id="wrap"><canvas id="c" width="900" height="620"></canvas>
<div id="legend"><b>world frame</b> (drag: orbit, wheel: zoom)<br>
<i style="background:#c8aa82"></i>table, <i style="background:#a0a5b4"></i>features<br>
<i style="background:#e62828"></i>feature pushing<br>
<i style="background:#ffb43c"></i>robot base<span class="arm">, <i style="background:#5f78a5"></i>arm</span><br>
<span class="held"><i style="background:#9ebff0"></i>object, <i style="background:#6e6e78"></i>jaws<br></span>
<span class="moving">gripper path: <span style="color:#888">transfer</span>, <span style="color:#1f77b4">approach</span>,
<span style="color:#d62728">push</span>, <span style="color:#2ca02c">retreat</span><br></span>
<span style="color:#d62728">x</span> <span style="color:#2ca02c">y</span> <span style="color:#1f5fd6">z</span> world axes</div></div>
<script id="data" type="application/json">__DATA__</script>
<script>
__SCRIPT__</script></body></html>
"""


def world_page(d: dict, title: str) -> str:
    """The self-contained HTML page (a str) of world-view data ``d``
    (:mod:`regrasp.viz.world_data`) titled ``title``."""
    text = json.dumps(d, allow_nan=False).replace("</", "<\\/")
    duration = max(float(d["samples"]["times"][-1]), 0.0)
    return (WORLD_PAGE.replace("__STYLE_HEAD__", STYLE_HEAD).replace("__STYLE_TAIL__", STYLE_TAIL)
            .replace("__TITLE__", html.escape(title)).replace("__DURATION__", f"{duration!r}")
            .replace("__SCRIPT__", MATH_SCRIPT.read_text() + WORLD_SCRIPT.read_text()).replace("__DATA__", text))


def _check_workcell(workcell):
    if not all(hasattr(workcell, k) for k in ("table", "features", "robot", "contact_owners", "clearance")):
        raise ArgumentError(f"invalid `workcell`: a Workcell (got {type(workcell).__name__})", "workcell")


def workcell_description_of(workcell, scene=None) -> dict:
    """The world view's data of ``workcell`` (see :mod:`regrasp.viz.world_data`); with ``scene``
    (a :class:`~regrasp.Scene` or :class:`~regrasp.Scene3D`) its object where the workcell starts
    it: on the table, or held at the scene's start by the gripper above the table's centre at
    the safe height (every feature's top + the workcell's clearance + the object's reach) [m]."""
    from .world_data import still_description, workcell_description

    _check_workcell(workcell)
    if scene is None:
        d = workcell_description(workcell)
        d.update(scene=None, object=None, gripper=None, pushes=[],
                 samples={"times": [0.0], "gripper": [None], "object": [None], "labels": ["start"], "push": [-1]})
        return d
    v = description(scene)
    reach = float(np.linalg.norm(np.asarray(v["vertices"], float), axis=1).max())
    hand = [*workcell.table.center, workcell.top() + workcell.clearance + reach, 1.0, 0.0, 0.0, 0.0]
    return still_description(v, workcell, hand)


def workcell_html(workcell, scene=None) -> str:
    """The browser view (a self-contained HTML page, a str) of ``workcell``: the table, every
    feature, the robot's base and the world axes; with ``scene``, its object where it starts (see
    :func:`workcell_description_of`)."""
    return world_page(workcell_description_of(workcell, scene), workcell.name)


def motion_description_of(scene, motion, arm=None) -> dict:
    """The world view's data of ``motion`` (a :class:`~regrasp.execution.WorldMotion` of
    ``scene``; None: without the object, the gripper as its axes) and the robot's bodies ``arm``
    (:func:`regrasp.robot.shapes.arm_view`; see :func:`regrasp.viz.world_data.motion_description`)."""
    from .world_data import motion_description

    if not all(hasattr(motion, k) for k in ("workcell", "times", "gripper", "object", "assignments", "in_hand")):
        raise ArgumentError(f"invalid `motion`: a WorldMotion (got {type(motion).__name__})", "motion")
    if scene is None:
        return motion_description(None, motion, arm)
    v = description(scene)
    if motion.scene and motion.scene != scene.name:
        raise ArgumentError(f"invalid `scene`: the motion is of scene `{motion.scene}` (got `{scene.name}`)", "scene")
    return motion_description(v, motion, arm)


def motion_html(scene, motion, arm=None) -> str:
    """The browser view (a self-contained HTML page, a str) of world motion ``motion`` of
    ``scene`` (None: without the object, the gripper as its axes): the workcell, the gripper
    holding the object animated along the motion's times [s]
    (time slider, play), the gripper's path coloured by label (transfer, approach, push,
    retreat), the feature of each push highlighted while it pushes, and with ``arm``
    (:func:`regrasp.robot.shapes.arm_view`) the robot's arm and gripper."""
    name = scene.name if scene is not None else motion.scene or "motion"
    return world_page(motion_description_of(scene, motion, arm), f"{name} in {motion.workcell.name}")


def write_motion_html(path, scene, motion, arm=None) -> Path:
    """Writes :func:`motion_html` of ``scene``, ``motion`` and ``arm`` to ``path`` (atomically;
    its folder created, once the page is made); returns the path."""
    p, text = Path(path), motion_html(scene, motion, arm)
    p.parent.mkdir(parents=True, exist_ok=True)  # atomic_write does not create folders
    return write_text(p, text)
