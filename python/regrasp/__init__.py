"""regrasp: in-hand regrasps with a parallel-jaw gripper by prehensile pushing.

Quick use::

    import regrasp
    scene = regrasp.Scene.load(regrasp.examples.path("block-low-friction"))
    cone = scene.motion_cone([0, 0, 0], "bottom")
    cone.generators, cone.contains([0, 0.01, 0]), cone.project([0.01, 0.0, 0.0])

    scene = regrasp.load_scene(regrasp.examples.path("pivot-3d"))  # a Scene or a Scene3D, by the file
    plan = regrasp.plan(scene, seed=0)                      # a Plan, for either
    plan.found, plan.poses, plan.pushers, plan.to_json()
"""

from ._core import __version__
from .errors import ArgumentError, ExecutionError, GraspError, InternalError, MissingExtraError, RegraspError, SceneError
from .planning.plan import Plan, plan, planner_defaults
from .scene import load_scene
from .scene.perturbation import Perturbation
from .scene.planar import Classification, GravityFreeCone, MotionCone, MotionConeBatch, Pusher, Scene, Task
from .scene.spatial import Scene3D
from . import _moved, examples

_moved.install()

__all__ = [
    "__version__",
    "examples",
    "ArgumentError",
    "ExecutionError",
    "GraspError",
    "InternalError",
    "MissingExtraError",
    "RegraspError",
    "SceneError",
    "Classification",
    "GravityFreeCone",
    "MotionCone",
    "MotionConeBatch",
    "Pusher",
    "Scene",
    "Scene3D",
    "Plan",
    "load_scene",
    "plan",
    "planner_defaults",
    "Task",
    "Perturbation",
]
