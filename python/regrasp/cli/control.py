"""`regrasp control`: a plan executed with feedback (planar: the MPC; 3-D: re-planning)."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np

from ..scene.settings import mpc_defaults
from ..errors import ArgumentError
from ..planning.plan import Plan
from . import (CANNOT, api_default, FIGURE_SUFFIXES, MAX_HORIZON, OK, SCALES, add_command, add_scale_options, add_verbose, check_count,
               check_number, check_outputs, check_positive, execute3d, floats, given, load, mode_scene, mpc_default,
               plural, refuse_flags, rounded, scales, every_friction, seed_arg, error3d)

#: options of the planar MPC, without meaning for 3-D control
PLANAR_ONLY = ("poke", "start_error", "robust", "uncertainty", "fixtureless", "plot", "dt", "horizon", "noise")


def _control3d(scene, plan: Plan, a) -> int:
    """3-D: the plan executed with feedback by re-planning (see
    :func:`regrasp.scene.spatial.run_plan3d`), or open loop with --open-loop."""
    refuse_flags(a, PLANAR_ONLY, "for a 3-D scene", "3-D control re-plans from the measured pose")
    if a.engine == "quasistatic" and any(getattr(a, f) is not None for f in SCALES):
        raise ArgumentError("invalid `--scale-*`: the quasi-static 3-D world is the scene itself (MuJoCo only)", "--engine")
    fb = not a.open_loop
    r = execute3d(scene, plan, a, loop="closed" if fb else "open", seed=a.seed)
    out = {k: r[k] for k in ("engine", "final_pose", "goal_error", "success", "replans")}
    out["policy"] = "replan" if fb else "open_loop"
    if a.json:
        print(json.dumps(out))
    else:
        print(f"{scene.name}: {out['policy']} in {r['engine']}: {'success' if r['success'] else 'failure'}, "
              f"{plural(r['replans'], 're-plan')}; error {error3d(r['goal_error'])}")
    return OK if r["success"] else CANNOT


def _check_mpc_options(a) -> None:
    check_count(a, "horizon", 1, MAX_HORIZON)
    check_positive(a, "dt", "control period [s]")
    check_number(a, "noise", 0.0, what="standard deviation")


def cmd_control(a) -> int:
    from ..control.loop import Poke, control
    from ..execution.execute import World, execute
    from ..scene.perturbation import Perturbation

    scales(a)
    check_outputs(a, {"plot": FIGURE_SUFFIXES}, [a.scene, a.plan])
    scene = load(a.scene, a)
    plan = Plan.load(a.plan, scene)
    if scene.dimension == 3:
        return _control3d(scene, plan, a)
    _check_mpc_options(a)
    if a.open_loop:
        refuse_flags(a, ("robust", "uncertainty", "fixtureless", "horizon", "noise"), "with --open-loop",
                     "they shape the MPC's feedback, which open-loop execution does not use")
    pokes = [Poke.parse(t) for t in a.poke or []]
    start_error = np.zeros(3) if a.start_error is None else floats(a.start_error, 3, "--start-error")
    settings = dict(pokes=pokes, controller_scene=mode_scene(scene, a), seed=a.seed, **given(a, "noise", "dt", "horizon"))
    world = Perturbation(*every_friction(scales(a)))
    if a.open_loop:  # the baseline: the plan's pushes on the controller's clock, pokes and all
        res = control(scene, plan, engine=a.engine, policy="open_loop", start_error=start_error, perturb=world, **settings)
    else:
        dx, dz, dth = map(float, start_error)
        world = replace(world, shift=(dx, 0.0, dz), turn=-dth)  # the start moved as a Perturbation says it
        res = execute(World(scene, engine=a.engine, options=settings), plan, loop="closed", perturbation=world).detail
    if a.plot:
        from ..viz.plotting import plot_control

        plot_control(scene, res, a.plot)
    if a.json:
        print(json.dumps(res.to_json()))
    else:
        print(_summary(scene, res))
    return OK if res.success else CANNOT


def _summary(scene, res) -> str:
    """What `regrasp control` prints for a planar run (the MPC's figures only for the MPC)."""
    mpc = (f", {plural(res.replans, 're-plan')}, median MPC step {1e3 * res.mpc_step_median_s:.3f} ms"
           if res.policy == "mpc" else "")
    return (f"{scene.name}: {res.policy} in {res.engine}: {'success' if res.success else 'failure'} "
            f"after {res.t[-1]:.1f} s{mpc}; final pose {rounded(res.final_pose)}, error {rounded(res.goal_error)} "
            "(m, m, rad)" + (f"; {res.failure}" if res.failure else ""))


def add_parsers(sub) -> None:
    from ..control.loop import control

    k = add_command(sub, "control", "track a plan with the MPC (closed loop) in a simulator "
                    "(3-D scenes: feedback by re-planning from the measured pose)",
                    "regrasp control t-shape.toml --plan plan.json --poke 2,0.002,0,0 --plot control.png",
                    cmd_control)
    k.add_argument("scene", help="the scene file the plan is for")
    k.add_argument("--plan", required=True, metavar="PLAN.json", help="the plan file")
    k.add_argument("--engine", default="quasistatic", choices=["quasistatic", "mujoco"], help="the world")
    k.add_argument("--poke", action="append", metavar="T,dx,dz,dtheta",
                   help="planar: displace the object in the grasp at time T [s] (repeatable)")
    k.add_argument("--start-error", metavar="dx,dz,dtheta", help="planar: the object starts this far from the plan's start")
    add_scale_options(k)
    k.add_argument("--robust", action="store_true",
                   help="planar: constrain the MPC with robust cones (scene's [uncertainty])")
    k.add_argument("--uncertainty", metavar="P,F,N,M", help="planar: spreads for the robust cones (implies --robust)")
    k.add_argument("--fixtureless", action="store_true", help="planar: constrain the MPC with fixtureless-fixturing cones")
    k.add_argument("--open-loop", action="store_true", help="execute the plan open loop instead (for comparison)")
    k.add_argument("--noise", type=float, help="planar: pose measurement noise, standard deviation: x, z [m], theta "
                   f"NOISE/L [rad] with L the object's length (default: {api_default(control, 'noise')})")
    k.add_argument("--dt", type=float, help=f"planar: control period [s] ({mpc_default('dt')})")
    k.add_argument("--horizon", type=int, help=f"planar: MPC horizon in steps ({mpc_default('horizon')})")
    k.add_argument("--seed", type=seed_arg, default=mpc_defaults()["seed"],
                   help="random seed (measurement noise; seeds of re-plans)")
    k.add_argument("--plot", metavar="PNG", help="planar: planned against executed poses, pokes marked")
    k.add_argument("--json", action="store_true", help="print the result as JSON")
    add_verbose(k)
