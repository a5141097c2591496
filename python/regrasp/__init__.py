"""regrasp: in-hand regrasps with a parallel-jaw gripper by prehensile pushing.

Quick use::

    import regrasp
    scene = regrasp.Scene.load("examples/block-low-friction.toml")
    cone = scene.motion_cone([0, 0, 0], "bottom")
    cone.generators, cone.contains([0, 0.01, 0]), cone.project([0.01, 0.0, 0.0])
"""

from ._core import __version__
from .errors import ArgumentError, GraspError, RegraspError, SceneError
from .scene.planar import Classification, GravityFreeCone, MotionCone, MotionConeBatch, Pusher, Scene, Task
from .scene.spatial import Scene3D
from .planning.plan import Plan, plan

__all__ = [
    "__version__",
    "ArgumentError",
    "GraspError",
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
    "plan",
    "Task",
]
