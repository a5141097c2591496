"""Command line: ``regrasp plan | cone | approx-error | validate | simulate | control | push | bench | demo``.

Exit status: 0 success, 1 the task cannot be done (reason printed), 2 invalid input.

One module per command group: ``cones`` (cone, approx-error), ``planning`` (plan), ``dynamics``
(validate, simulate, push), ``control`` (control), ``tools`` (bench, demo). Each has
``add_parsers(sub)``; this module assembles them and holds what they share.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from ..errors import ArgumentError, RegraspError, SceneError
from ..planning.plan import Plan, planner_defaults
from ..scene import load_scene
from ..scene.planar import Scene

EXAMPLES = Path(__file__).resolve().parents[3] / "examples"

#: exit statuses (docs/cli.md)
OK, CANNOT, INVALID = 0, 1, 2


# --- arguments ---------------------------------------------------------------------------------

def seed_arg(text: str) -> int:
    """argparse type of --seed: a whole number >= 0."""
    try:
        v = int(text)
    except ValueError:
        v = -1
    if not 0 <= v < 2**64:
        raise argparse.ArgumentTypeError(f"a whole number >= 0 (got {text!r})")
    return v


def floats(text: str, n: int, name: str) -> np.ndarray:
    """``n`` comma-separated finite numbers, or an ArgumentError naming the option."""
    try:
        v = np.array([float(x) for x in text.split(",")])
    except ValueError:
        raise ArgumentError(f"invalid `{name}`: expected {n} comma-separated numbers, got {text!r}", name)
    if v.shape != (n,) or not np.all(np.isfinite(v)):
        raise ArgumentError(f"invalid `{name}`: expected {n} finite comma-separated numbers, got {text!r}", name)
    return v


def planner_default(key: str) -> str:
    """The planner's default of setting ``key`` for a help text (the Rust core's)."""
    d2, d3 = planner_defaults(2).get(key), planner_defaults(3).get(key)
    return f"default {d2}" if d3 is None or d3 == d2 else f"default {d2} planar, {d3} 3-D"


def given(a, *names: str) -> dict:
    """The options among ``names`` given on the command line (not None), by name: the callee's
    own defaults apply to the others."""
    return {n: getattr(a, n) for n in names if getattr(a, n, None) is not None}


SCALES = ("scale_friction", "scale_grip", "scale_mass")


def add_scale_options(p, what: str = "") -> None:
    """--scale-friction/--scale-grip/--scale-mass (factors on the world's physics)."""
    p.add_argument("--scale-friction", type=float, help=f"{what}factor on every friction coefficient of the world (default 1)")
    p.add_argument("--scale-grip", type=float, help=f"{what}factor on the world's grip force (default 1)")
    p.add_argument("--scale-mass", type=float, help=f"{what}factor on the object's mass in the world (default 1)")


def scales(a) -> tuple[float, float, float]:
    """The --scale-* factors (friction, grip force, mass), checked positive; 1 where not given."""
    out = []
    for name in SCALES:
        v = getattr(a, name)
        if v is not None and not (np.isfinite(v) and v > 0):
            raise ArgumentError(f"invalid `--{name.replace('_', '-')}`: must be a positive factor", name)
        out.append(1.0 if v is None else float(v))
    return tuple(out)


def check_positive(a, name: str, what: str) -> None:
    """Option ``name``, when given, must be a positive finite number."""
    v = getattr(a, name)
    if v is not None and not (np.isfinite(v) and v > 0):
        raise ArgumentError(f"invalid `--{name.replace('_', '-')}`: must be a positive {what}", f"--{name.replace('_', '-')}")


def reject_flags(a, flags, why: str) -> None:
    """Invalid input when any of ``flags`` (attribute names; options that default to None or
    False) is given: ``why`` says what applies."""
    bad = [f for f in flags if getattr(a, f, None) is not None and getattr(a, f) is not False]
    if bad:
        raise ArgumentError(f"invalid flags for a 3-D scene: {why} (no --{', --'.join(f.replace('_', '-') for f in bad)})",
                            "scene")


# --- scenes and plans --------------------------------------------------------------------------

def load_planar(path, cmd: str) -> Scene:
    """A planar scene for commands that have no 3-D counterpart (a clear error for a 3-D one)."""
    scene = load_scene(path)
    if scene.dimension == 3:
        raise ArgumentError(f"invalid `scene`: `regrasp {cmd}` works on planar scenes; {path} is a 3-D scene "
                            "(3-D scenes: plan, simulate, push, control)", "scene")
    return scene


def mode_scene(scene: Scene, a) -> Scene:
    """The scene in the cone mode the flags ask for (--robust, --uncertainty, --fixtureless)."""
    if getattr(a, "robust", False) and getattr(a, "fixtureless", False):
        raise ArgumentError("invalid `--robust`: choose --robust or --fixtureless, not both", "--robust")
    if getattr(a, "robust", False) or getattr(a, "uncertainty", None):
        u = None
        if getattr(a, "uncertainty", None):
            v = floats(a.uncertainty, 4, "--uncertainty")
            u = dict(zip(("pusher_friction", "finger_friction", "grip_force", "mass"), v.tolist()))
        return scene.robust(u)
    if getattr(a, "fixtureless", False):
        return scene.fixtureless()
    return scene


def pusher_runs(pushers) -> str:
    """The pushes of a plan: consecutive steps with one pusher, ``left x3 -> bottom x2``."""
    runs = []
    for name in pushers[1:]:
        if runs and runs[-1][0] == name:
            runs[-1][1] += 1
        else:
            runs.append([name, 1])
    return " -> ".join(f"{n} x{c}" for n, c in runs)


def execute3d(scene, plan: Plan, a, **kw) -> dict:
    """A 3-D plan executed in the world of --engine: the quasi-static replay or MuJoCo with the
    --scale-* factors (``kw``: settings both take, e.g. ``feedback``)."""
    if a.engine == "mujoco":
        from ..mujoco.spatial import execute_plan3d

        return execute_plan3d(scene, plan, *scales(a), **kw)
    return scene.replay(plan, **kw)


# --- the command -------------------------------------------------------------------------------

def build_parser() -> argparse.ArgumentParser:
    from . import cones, control, dynamics, planning, tools

    ap = argparse.ArgumentParser(prog="regrasp", description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    for group in (planning, cones, dynamics, control, tools):
        group.add_parsers(sub)
    return ap


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return args.fn(args)
    except (SceneError, ArgumentError) as e:
        status = INVALID
        message = str(e)
    except RegraspError as e:  # GraspError and the rest: the task cannot be done
        status = CANNOT
        message = str(e)
    except OSError as e:  # a file that cannot be read or written (e.g. --plot into a missing folder)
        if e.filename is None:
            raise
        status = INVALID
        message = f"cannot write or read {e.filename}: {e.strerror or e}"
    print(f"regrasp: {message}", file=sys.stderr)
    return status


if __name__ == "__main__":
    sys.exit(main())
