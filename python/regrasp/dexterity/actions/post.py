"""The regrasp action with a contact against the workcell's post (thesis §1.1.1 and ch. 3–4,
``resource = "contact"``): ``post-push`` (:class:`PostPush`: a prehensile push deeper into the
hand against the post, planned by motion cones) and the scene of that push
(:func:`post_scene`)."""

from __future__ import annotations

import weakref
from pathlib import Path

import numpy as np

from ... import pose as P
from ...errors import ArgumentError, SceneError
from ..world import POST_FRICTION, POST_HALF, POST_X, POST_Y, WORK_POINT, HandPath, hand_pose, ramps
from .base import DEFAULTS, RAMP, Action, ObjectModel, Setup, _params
from .geometry import _intended, _offset_step, lowest


POST_HOLDS = (1.5, 2.0, 3.0, 4.0)  # post-push: the grips tried (2 μ N / m g), the least the planner finds a push at
PLAN_TIME_CAP = 60.0  # s, post-push: a safety cap on the planner's time (its iterations limit it first)
POST_ROOM = 0.006  # m, post-push: the post's side at least this far from each pad (the IK keeps the gripper 5 mm off it)


class PostPush(Action):
    """A prehensile push against the workcell's post (thesis ch. 3–4): the hand level, its fingers
    towards the post (:data:`~regrasp.dexterity.world.POST_X`), which passes between them. The
    motion-cone planner (:meth:`regrasp.Scene3D.plan`, inverse dynamics over the pads' limit surface) plans the push
    one offset step deeper into the hand with the post's face as a plane pusher of the post's
    friction and gravity across the push, at the least grip of :data:`POST_HOLDS` at which it
    finds one — the post's friction, pressed by the pads' sliding friction, must carry the weight
    (μ_post · 2μN ≥ m g). The hand renders the plan with the object held still by the post
    (sticking): at knot k the TCP is O ∘ X_k⁻¹, O the object's world pose at contact and X_k its
    planned pose in the hand; the hand comes in at ``speed`` and follows the plan at ``push_speed``."""

    ALPHA = np.pi / 2  # rad, the hand level, its fingers along the world's +x (at the post)

    def __init__(self):
        super().__init__("post-push", "contact", "push it deeper against a post, the motion planned by motion cones")

    def _plan(self, obj, grasp, iterations: int):
        """(grip ratio, the plan) or why there is none (cached per grasp)."""
        cache = _PLANS.setdefault(obj.taxonomy, {})
        key = (grasp.name, iterations)
        if key in cache:
            return cache[key]
        step = _offset_step(obj, grasp, +1)
        if step is None:
            out = "no grasp further towards the palm"
        elif grasp.width / 2 - POST_HALF[1] < POST_ROOM:
            out = f"the post ({2e3 * POST_HALF[1]:.0f} mm) does not pass between pads {grasp.width * 1e3:.1f} mm apart"
        else:
            goal = P.compose(np.array([0.0, 0.0, step, 1.0, 0.0, 0.0, 0.0]), grasp.pose)
            out = f"the motion-cone planner finds no push at a grip up to {POST_HOLDS[-1]} times the holding force"
            for ratio in POST_HOLDS:
                try:
                    plan = post_scene(obj, grasp.pose, goal, obj.holding(ratio)).plan(
                        seed=0, max_iterations=iterations, time_limit=PLAN_TIME_CAP)
                except (ArgumentError, SceneError) as e:  # no scene file, or the pads do not touch it at the start or the goal
                    out = f"no push to plan: {e}"
                    break
                if plan.found and plan.valid:
                    out = (ratio, plan)
                    break
        cache[key] = out
        return out

    def applies(self, obj, grasp):
        plan = self._plan(obj, grasp, int(DEFAULTS["plan_iterations"]))
        return plan if isinstance(plan, str) else None

    def setup(self, obj, grasp, params=None):
        p = _params(params)
        plan = self._plan(obj, grasp, int(p["plan_iterations"]))
        if isinstance(plan, str):
            raise ArgumentError(f"invalid `grasp`: post-push does not apply to {grasp.name}: {plan}", "grasp")
        ratio, plan = plan
        X = np.asarray(plan.poses, float)
        reach = -lowest(grasp, obj.taxonomy.vertices)[2]
        press = 0.0005  # m, the object pressed this far into the post at contact (soft contact)
        contact = hand_pose(self.ALPHA, (POST_X - reach + press, POST_Y, WORK_POINT[2]))
        start = hand_pose(self.ALPHA, (POST_X - reach - p["approach"], POST_Y, WORK_POINT[2]))
        O = P.compose(contact, X[0])  # the object's world pose, held by the post
        knots = [P.compose(O, P.inverse(x)) for x in X]
        path = HandPath.line(start, contact, 1.5 * p["approach"] / p["speed"])
        t0 = path.times[-1]
        for a, b in zip(knots, knots[1:]):
            path = path.then(HandPath.line(a, b, max(float(np.linalg.norm(b[:3] - a[:3])) / p["push_speed"], 0.05),
                                           profile=lambda s: s))
        t1 = path.times[-1]
        path = path.then(HandPath.line(knots[-1], P.compose(knots[-1], np.array([0.0, 0.0, p["approach"], 1.0, 0.0, 0.0, 0.0])), 1.0))
        low = obj.holding(ratio)
        grip = ramps((0.0, obj.grip), (t0 - RAMP, obj.grip), (t0, low), (t1, low), (t1 + RAMP, obj.grip))
        pose = X[-1]
        return Setup(start, path, grip, 0.3, pose, _intended(obj, pose),
                     {"grip": low, "hold": ratio, "knots": len(X), "push": float(X[-1][2] - X[0][2])})


_PLANS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()  # taxonomy -> {(grasp name, iterations): _plan}


def post_scene(obj: ObjectModel, start, goal, force: float, friction: float = POST_FRICTION):
    """The :class:`regrasp.Scene3D` of a push against the post with the hand level: ``obj``'s object
    file's ``[object]`` (an ArgumentError naming ``scene`` when the scene has no readable file),
    its pads at ``force`` [N] each, gravity along the hand's −x, the post's face a plane pusher
    (``friction``, by default the post's) pushing towards the palm (+z), the task from in-hand
    pose ``start`` to ``goal`` (1 mm, 1°)."""
    from ...files import parse_toml, read_text
    from ...scene.spatial import Scene3D
    from ...workcell.file import toml_value

    path = getattr(obj.scene, "path", None)
    if path is None:
        raise ArgumentError("invalid `scene`: a post push needs the object's scene file (load it from a file)", "scene")
    why = lambda e: ArgumentError(f"invalid `scene`: cannot read the object's scene file {str(path)!r}: {e}", "scene")  # noqa: E731
    try:
        text = read_text(path, "scene")
    except ArgumentError as e:
        raise why(e) from None
    data = parse_toml(text, "scene", why)
    lines = ["dimension = 3", 'name = "post-push"']
    for table, values in (("object", data.get("object", {})), ("grasp", dict(data.get("grasp", {}), force=float(force)))):
        lines += ["", f"[{table}]"]
        for k, v in values.items():
            try:
                lines.append(f"{k} = {toml_value(v)}")
            except ValueError as e:
                raise SceneError(f"scene field `{table}.{k}`: {e}", f"{table}.{k}") from None
    lines += ["", "[gravity]", "direction = [-1.0, 0.0, 0.0]", f"g = {obj.g!r}"]
    lines += ["", "[[pushers]]", 'name = "post"', f"friction = {float(friction)!r}", "plane = true", "normal = [0.0, 0.0, 1.0]"]
    lines += ["", "[task]", f"start = {toml_value(np.asarray(start, float))}", f"goal = {toml_value(np.asarray(goal, float))}",
              "tolerance = [0.001, 0.001, 0.001, 0.0175]"]
    return Scene3D.from_toml("\n".join(lines) + "\n", Path(path).parent)
