"""Execution in the world: which workcell feature renders each push of a plan
(:mod:`~regrasp.execution.assignment`) and the gripper's timed world-frame trajectory that
executes the plan (:mod:`~regrasp.execution.world_motion`)::

    from regrasp.execution import world_motion
    motion = world_motion(scene, plan)          # default_workcell(scene); or workcell=Workcell.load(...)
    motion.times, motion.gripper, motion.labels, motion.assignments
    motion.to_trajectory().save("plan.trajectory.json")   # docs/trajectory-file.md
    result = execute_free_gripper(scene, plan, motion)   # MuJoCo, a free-flying gripper (extra `mujoco`)

One entry point runs a plan in any rig (:mod:`~regrasp.execution.execute`)::

    run = execute(World(scene, rig="arm"), plan, loop="open", perturbation=Perturbation(0.9, 1.1, 1.0, 1.0))
    run.success, run.goal_error, run.plan_end_error
"""

from .execute import Execution, World, execute
from .assignment import Assignment, PusherContact, assign, pusher_contact
from .free_gripper import FreeGripperResult, execute_free_gripper
from .layout import default_workcell
from .trajectory import PushRecord, Trajectory
from .world_motion import Timing, WorldMotion, world_motion

__all__ = ["Execution", "World", "execute", "Assignment", "FreeGripperResult", "PusherContact", "PushRecord", "Timing", "Trajectory", "WorldMotion",
           "assign", "default_workcell", "execute_free_gripper", "pusher_contact", "world_motion"]
