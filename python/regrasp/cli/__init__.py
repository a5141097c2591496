"""Command line: ``regrasp plan | cone | approx-error | validate | simulate | control | push | bench | demo | examples``.

Exit status: 0 success, 1 the task cannot be done (reason printed; also an internal error, and a
missing optional dependency: the extra to install is named), 2 invalid input, 130 interrupted (Ctrl-C), 141 standard output closed early (e.g. piped into ``head``).

One module per command group: ``cones`` (cone, approx-error), ``planning`` (plan), ``dynamics``
(validate, simulate, push), ``control`` (control), ``tools`` (bench, demo), ``examples`` (examples). Each has
``add_parsers(sub)``; this module assembles them (only the chosen command's group is imported:
:data:`GROUPS`) and holds what they share. How a command stops on Ctrl-C and SIGTERM:
:mod:`regrasp.cli.stopping`.
"""

from __future__ import annotations

import argparse
import inspect
import os
import re
import sys
from pathlib import Path

import numpy as np

from .. import errors, progress
from ..errors import ArgumentError, MissingExtraError, RegraspError, SceneError
from ..extras import need
from ..files import check_writable, refuse_overwrite_input
from ..planning.plan import Plan, planner_defaults
from ..scene import load_scene
from ..scene.planar import Scene
from ..scene.settings import core_build, limit_surface_default, mpc_defaults
from .stopping import Terminated, install, restore, stopped as _stopped


#: exit statuses (docs/cli.md): 130 = 128 + SIGINT, 141 = 128 + SIGPIPE (the shell's convention)
OK, CANNOT, INVALID, INTERRUPTED, BROKEN_PIPE, TERMINATED = 0, 1, 2, 130, 141, 143


#: upper bounds of the count options (docs/cli.md): larger values are invalid input, not hours of work
MAX_PUSHES = 100_000
MAX_SAMPLES = 10_000_000
MAX_CONES = 10_000_000
MAX_WORKERS = 1024
MAX_HORIZON = 1000
#: most time steps of one simulated push (`--duration` / `--dt`) and its longest duration [s]
MAX_STEPS = 1_000_000
MAX_DURATION = 100_000.0
#: largest --scale-* factor and largest grip force of `approx-error --forces` [N]
MAX_SCALE = 1000.0
MAX_FORCE = 10_000.0
#: suffixes of --plot (matplotlib), of animations (Pillow) and of --video (Pillow, or ffmpeg for MP4)
FIGURE_SUFFIXES = (".png", ".pdf", ".svg", ".jpg", ".jpeg", ".eps", ".ps", ".tif", ".tiff", ".webp")
ANIMATION_SUFFIXES = (".gif", ".webp", ".png", ".tif", ".tiff")
VIDEO_SUFFIXES = ANIMATION_SUFFIXES + (".mp4",)
#: the suffix sets of outputs drawn with matplotlib (the `plot` extra)
DRAWN = (FIGURE_SUFFIXES, ANIMATION_SUFFIXES, VIDEO_SUFFIXES)


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


def check_count(a, name: str, lo: int, hi: int) -> None:
    """Whole-number option ``name`` (attribute), when given, within [lo, hi]."""
    v = getattr(a, name, None)
    opt = option(name)
    if v is not None and not lo <= v <= hi:
        raise ArgumentError(f"invalid `{opt}`: a whole number in [{lo}, {hi}] (got {v})", opt)


def check_number(a, name: str, lo: float, hi: float = float("inf"), what: str = "number",
                 lo_open: bool = False, finite: bool = True) -> None:
    """Number option ``name`` (attribute), when given: not NaN, finite (unless ``finite`` is
    False: then +inf is allowed), within [lo, hi] (lo excluded with ``lo_open``)."""
    v = getattr(a, name, None)
    if v is None:
        return
    opt = option(name)
    ok = v == v and (np.isfinite(v) or (not finite and v > 0)) and (v > lo if lo_open else v >= lo) and v <= hi
    if not ok:
        lo_text = f"> {lo:g}" if lo_open else f">= {lo:g}"
        hi_text = "" if hi == float("inf") else f" and <= {hi:g}"
        raise ArgumentError(f"invalid `{opt}`: must be a finite {what} {lo_text}{hi_text}{'' if finite else ', or inf'} "
                            f"(got {v})", opt)


def option(name: str) -> str:
    """The option of attribute ``name``: ``time_limit`` -> ``--time-limit`` (one letter: ``-n``)."""
    return ("-" if len(name) == 1 else "--") + name.replace("_", "-")


def check_outputs(a, outputs: dict, inputs=(), create_folder: bool = True) -> None:
    """The output options ``{attribute: suffixes or None}`` given: writable (before the work),
    not an input file, not one another, with a suffix of ``suffixes``, and what draws them
    installed (:func:`check_drawing`)."""
    paths = {option(k): getattr(a, k, None) for k in outputs}
    refuse_overwrite_input(paths, inputs)
    for k, suffixes in outputs.items():
        v = getattr(a, k, None)
        if v is None:
            continue
        if suffixes and Path(v).suffix.lower() not in suffixes:
            raise ArgumentError(f"invalid `{option(k)}`: cannot write {v}: the name must end in one of "
                                f"{', '.join(suffixes)}", option(k))
        check_drawing(v, suffixes, option(k))
        check_writable(v, option(k), create_folder=create_folder)


def check_drawing(path, suffixes, opt: str) -> None:
    """Figures, animations and videos (``suffixes`` one of :data:`DRAWN`) need matplotlib (a
    MissingExtraError naming ``regrasp[plot]``), an MP4 also ffmpeg: checked before any work."""
    if suffixes not in DRAWN:
        return
    need("matplotlib", "plot")
    if Path(path).suffix.lower() == ".mp4":
        import matplotlib.animation

        if not matplotlib.animation.writers.is_available("ffmpeg"):
            raise ArgumentError(f"invalid `{opt}`: MP4 needs ffmpeg, which is not installed; use a .gif", opt)


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
    return f"default: {d2}" if d3 is None or d3 == d2 else f"default: {d2} planar, {d3} 3-D"


def api_default(fn, name: str):
    """The default of parameter ``name`` of API function ``fn``: a command-line option's default
    is read from the function it calls (stated once, there)."""
    return inspect.signature(fn).parameters[name].default


def mpc_default(key: str) -> str:
    """The MPC's default of setting ``key`` for a help text (the Rust core's)."""
    return f"default: {mpc_defaults()[key]}"


def given(a, *names: str) -> dict:
    """The options among ``names`` given on the command line (not None), by name: the callee's
    own defaults apply to the others."""
    return {n: getattr(a, n) for n in names if getattr(a, n, None) is not None}


SCALES = ("scale_friction", "scale_grip", "scale_mass")


def add_scale_options(p, what: str = "") -> None:
    """--scale-friction/--scale-grip/--scale-mass (factors on the world's physics)."""
    p.add_argument("--scale-friction", type=float, help=f"{what}factor on every friction coefficient of the world (default: 1)")
    p.add_argument("--scale-grip", type=float, help=f"{what}factor on the world's grip force (default: 1)")
    p.add_argument("--scale-mass", type=float, help=f"{what}factor on the object's mass in the world (default: 1)")


def scales(a) -> tuple[float, float, float]:
    """The --scale-* factors (friction, grip force, mass), checked positive; 1 where not given."""
    out = []
    for name in SCALES:
        v = getattr(a, name)
        if v is not None and not (np.isfinite(v) and 0 < v <= MAX_SCALE):
            raise ArgumentError(f"invalid `--{name.replace('_', '-')}`: must be a positive factor, at most {MAX_SCALE:g} "
                                f"(got {v})", option(name))
        out.append(1.0 if v is None else float(v))
    return tuple(out)


def every_friction(s: tuple) -> tuple[float, float, float, float]:
    """The factors of :func:`scales` as a :class:`~regrasp.Perturbation`'s: --scale-friction on
    the fingers' and the features' friction alike."""
    f, g, m = s
    return f, g, m, f


def check_positive(a, name: str, what: str) -> None:
    """Option ``name``, when given, must be a positive finite number."""
    v = getattr(a, name)
    if v is not None and not (np.isfinite(v) and v > 0):
        raise ArgumentError(f"invalid `--{name.replace('_', '-')}`: must be a positive {what}", f"--{name.replace('_', '-')}")


def refuse_flags(a, flags, when: str, why: str) -> None:
    """Invalid input when any of ``flags`` (attribute names; options that default to None or
    False) is given ``when`` (e.g. "with --engine quasistatic", "for a 3-D scene"): ``why`` says
    what they need; the error names the first offending option."""
    bad = [option(f) for f in flags if getattr(a, f, None) is not None and getattr(a, f) is not False]
    if bad:
        raise ArgumentError(f"invalid `{bad[0]}`: {', '.join(bad)} {'has' if len(bad) == 1 else 'have'} no effect "
                            f"{when}: {why}", bad[0])


# --- scenes and plans --------------------------------------------------------------------------

def load(path, a=None, arg: str = "scene"):
    """The scene file ``path`` (planar or 3-D) of the command-line argument ``arg``; with
    ``--verbose`` its notes (e.g. pusher points snapped onto the outline) are printed on stderr.
    A file that cannot be read is invalid input naming ``arg`` (see :func:`unreadable`)."""
    try:
        scene = load_scene(path)
    except ArgumentError as e:
        if e.field != "path":
            raise
        raise unreadable(path, e, arg) from e
    model = getattr(a, "limit_surface", None)
    if model is not None:
        if scene.dimension == 3:
            raise ArgumentError("invalid `--limit-surface`: it selects a planar scene's limit surface; "
                                f"{path} is a 3-D scene", "--limit-surface")
        scene = scene.with_limit_surface(model)
    if getattr(a, "verbose", False):
        for note in getattr(scene, "notes", None) or []:
            progress.note(f"regrasp: {path}: {note}")
    return scene


def add_limit_surface(p) -> None:
    """``--limit-surface``: the limit surface of a planar scene's motion cones."""
    p.add_argument("--limit-surface", choices=["true", "ellipsoid"],
                   help="the motion cones' limit surface: the exact one of the pad's or footprint's pressure, or "
                   "the ellipsoid of eq 3.7 (default: the scene's `limit_surface`, else "
                   f"{limit_surface_default()})")


def unreadable(path, e: ArgumentError, arg: str = "scene") -> ArgumentError:
    """The error of a scene file that cannot be read, naming the argument ``arg``; a missing file
    named like a bundled example gets a hint how to write it here, any other missing one how to
    list them."""
    from .. import examples

    reason = str(e).split(": ", 1)[-1]
    if not Path(path).exists():
        stem = Path(path).name.removesuffix(".toml")
        if stem in examples.names():
            reason += f"; {stem} is a bundled example: `regrasp examples {stem} --copy .` writes it here"
        else:
            reason += "; `regrasp examples` lists the bundled scenes"
    return ArgumentError(f"invalid `{arg}`: {reason}", arg)


def load_planar(path, cmd: str, a=None, arg: str = "scene") -> Scene:
    """A planar scene for commands that have no 3-D counterpart (a clear error for a 3-D one)."""
    scene = load(path, a, arg)
    if scene.dimension == 3:
        raise ArgumentError(f"invalid `{arg}`: `regrasp {cmd}` works on planar scenes; {path} is a 3-D scene "
                            "(3-D scenes: plan, simulate, push, control)", arg)
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


def rounded(v, digits: int = 5) -> list:
    """Numbers ``v`` rounded for printing, ``-0.0`` shown as ``0.0``."""
    return (np.round(np.asarray(v, float), digits) + 0.0).tolist()


def plural(n: int, word: str, words: str | None = None) -> str:
    """``1 step``, ``2 steps`` (``words``: the plural where it is not ``word + "s"``)."""
    return f"{n} {word if n == 1 else words or word + 's'}"


def error3d(err) -> str:
    """A 3-D goal error ``[dx, dy, dz, angle]`` for people: position [m], angle [rad]."""
    return f"position {rounded(err[:3])} m, angle {rounded(err[3:])[0]} rad"


def runs(pushers) -> list[list]:
    """Consecutive steps with one pusher: ``[[name, steps], ...]`` (``pushers[0]``, the start's, is
    no step)."""
    out = []
    for name in pushers[1:]:
        if out and out[-1][0] == name:
            out[-1][1] += 1
        else:
            out.append([name, 1])
    return out


def pusher_runs(pushers) -> str:
    """The pushes of a plan: consecutive steps with one pusher, ``left x3 -> bottom x2``."""
    return " -> ".join(f"{n} x{c}" for n, c in runs(pushers)) or "no pushes"


def execute3d(scene, plan: Plan, a, loop: str = "open", **options) -> dict:
    """A 3-D plan executed (:func:`~regrasp.execution.execute`) in the planner's-view world of
    --engine, the quasi-static replay or MuJoCo with the --scale-* factors, ``loop`` open or
    closed (re-planning); ``options``: settings both engines take (``dt``, ``seed``)."""
    from ..execution.execute import World, execute
    from ..scene.perturbation import Perturbation

    world = World(scene, engine=a.engine, options=options)
    with progress.elapsed(None, f"quasi-static replay of {scene.name}", show=a.engine == "quasistatic"):
        run = execute(world, plan, loop=loop, perturbation=Perturbation(*every_friction(scales(a))))
    return {"engine": a.engine, "final_pose": run.final_pose.tolist(), "goal_error": run.goal_error.tolist(),
            "success": run.success, "replans": run.replans, "plan_end_error": run.plan_end_error.tolist()}


# --- the command -------------------------------------------------------------------------------

def add_verbose(p) -> None:
    """-v/--verbose of a command that loads scenes (a subcommand's default does not override the
    global option's)."""
    p.add_argument("-v", "--verbose", action="store_true", default=argparse.SUPPRESS,
                   help="print the scene's notes (e.g. pusher points snapped onto the outline) on stderr")


class Help(argparse.RawDescriptionHelpFormatter):
    """Help texts that end with the option's default: ``(default: X)`` where the option has one and
    its text does not already say it; ``(default: none)`` for an optional value without one;
    ``(required)`` for a required option."""

    def _get_help_string(self, action) -> str:
        text = action.help or ""
        if action.required and action.option_strings:
            return f"{text} (required)"
        if "default" in text or action.default is argparse.SUPPRESS or action.required:
            return text
        if action.option_strings and action.nargs == 0:  # a flag: off unless given
            return text
        if action.default is None:
            return f"{text} (default: none)" if action.option_strings else text
        return f"{text} (default: %(default)s)"


class Parser(argparse.ArgumentParser):
    """The parsers of `regrasp` and of its commands: help with defaults and verbatim epilogs."""

    def __init__(self, *args, **kw) -> None:
        kw.setdefault("formatter_class", Help)
        super().__init__(*args, **kw)


def add_command(sub, name: str, summary: str, example: str, fn) -> Parser:
    """A command ``name``: ``summary`` (one line) in `regrasp --help` and its own help, an example
    (a command line, several on their own lines) as its epilog (see :func:`example_epilog`)."""
    p = sub.add_parser(name, help=summary, description=summary[0].upper() + summary[1:] + ".",
                       epilog=example_epilog(example))
    p.set_defaults(fn=fn)
    return p


def example_epilog(example: str) -> str:
    """``example:`` and the command lines of ``example``; where they read a bundled example's
    scene file (``t-shape.toml``), a line saying how to get it (any folder, after pip install)."""
    from .. import examples

    lines = [f"  {line}" for line in example.splitlines()]
    used = [n for n in examples.names() if re.search(rf"(?<![\w/.-]){re.escape(n)}\.toml\b", example)]
    if used and "--copy" not in example:
        name = used[0] if len(used) == 1 else "NAME"
        lines.append(f"  ({', '.join(f'{n}.toml' for n in used)}: bundled example{'s' * (len(used) > 1)}; "
                     f"`regrasp examples {name} --copy .` writes {name}.toml here)")
    return "example:\n" + "\n".join(lines)


def version() -> str:
    """``regrasp VERSION (core NAME, ABI, PYTHON)``: the package and its compiled core."""
    from .. import __version__

    core, name = core_build()
    abi = "abi3" if ".abi3." in name else name.split(".")[1] if name.count(".") > 1 else "unknown ABI"
    py = f"{sys.implementation.name} {sys.version_info.major}.{sys.version_info.minor}"
    return f"regrasp {__version__} (core {core}: {name}, {abi}; {py})"


def add_quiet(p, default=False) -> None:
    """-q/--quiet: no progress bars (before the command, or as an option of any command)."""
    p.add_argument("-q", "--quiet", action="store_true", default=default,
                   help="no progress bars on stderr (bars are shown only when stderr is a terminal)")


#: each command and its group, the module ``cli/<group>.py`` that adds its parser, in the order of
#: `regrasp --help`; only the chosen command's group is imported (the CLI starts in about the time of
#: `import regrasp`: the groups' help reads the defaults of the modules that do the work)
GROUPS = {"plan": "planning", "cone": "cones", "approx-error": "cones", "validate": "dynamics",
          "simulate": "dynamics", "push": "dynamics", "control": "control", "execute": "execution",
          "pick-place": "pick_place", "grasp-graph": "dexterity", "regrasp-sequence": "dexterity",
          "bench": "tools", "demo": "tools", "examples": "examples"}
#: the options of `regrasp` itself (before COMMAND): none takes a value
GLOBAL_FLAGS = ("-v", "--verbose", "-q", "--quiet", "--version")


def chosen(argv: list) -> str | None:
    """The command that ``argv`` names (its first word that is not a global flag); "" when it has
    global flags only (``--version``, or no command); None for an unknown command or `regrasp`'s
    own help asked for before it (then every group's parser is built)."""
    for token in argv:
        if token not in GLOBAL_FLAGS:
            return token if token in GROUPS else None
    return ""


def build_parser(cmd: str | None = None) -> argparse.ArgumentParser:
    """`regrasp`'s parser: with the parsers of ``cmd``'s group only when ``cmd`` is a command (the
    other groups are not imported), none when it is "" (see :func:`chosen`), else every command's."""
    import importlib

    ap = Parser(prog="regrasp", description="In-hand regrasps by prehensile pushing: motion cones, planning, "
                "simulation and control (`regrasp COMMAND --help` for each command).",
                epilog=example_epilog("regrasp demo --out out/demo\nregrasp examples t-shape --copy .\n"
                                      "regrasp plan t-shape.toml --plot plan.png"))
    ap.add_argument("--version", action="version", version=version(), help="print the version and exit")
    ap.add_argument("-v", "--verbose", action="store_true", help="print the scenes' notes on stderr")
    add_quiet(ap)
    sub = ap.add_subparsers(dest="cmd", metavar="COMMAND", parser_class=Parser)
    groups = [GROUPS[cmd]] if cmd in GROUPS else [] if cmd == "" else list(dict.fromkeys(GROUPS.values()))
    for group in groups:
        importlib.import_module(f"{__name__}.{group}").add_parsers(sub)
    ap.description += f"\nCOMMAND: one of {{{','.join(GROUPS)}}}."
    for p in sub.choices.values():
        add_quiet(p, argparse.SUPPRESS)
    return ap


def _internal(e: BaseException) -> str:
    return f"internal error (please report): {type(e).__name__}: {e}"


def _run(args) -> tuple[int, str | None]:
    """Runs the command: (exit status, message for stderr or None)."""
    internal = getattr(errors, "InternalError", ())
    try:
        return args.fn(args), None
    except (SceneError, ArgumentError) as e:
        return INVALID, str(e)
    except internal as e:  # a caught panic of the Rust core
        return CANNOT, _internal(e)
    except MissingExtraError as e:  # an optional dependency not installed: which extra brings it
        return CANNOT, f"`regrasp {args.cmd}` needs {e.what}: pip install 'regrasp[{e.extra}]'"
    except RegraspError as e:  # GraspError and the rest: the task cannot be done
        return CANNOT, str(e)
    except (KeyboardInterrupt, BrokenPipeError):
        raise
    except OSError as e:  # a file that cannot be read or written
        if e.filename is None:
            return _unexpected(e)
        return INVALID, f"cannot write or read {e.filename}: {e.strerror or e}"
    except Exception as e:
        return _unexpected(e)


def _unexpected(e: Exception) -> tuple[int, str]:
    """Any other exception: a one-line internal error (exit 1); REGRASP_TRACEBACK=1 re-raises it.
    After Ctrl-C or SIGTERM: the stop (:func:`_stopped`)."""
    stop = _stopped()
    if stop is not None:
        raise stop from e
    if os.environ.get("REGRASP_TRACEBACK"):
        raise e
    return CANNOT, _internal(e)


def _quiet_stdout() -> None:
    """Standard output was closed (``| head``): point it at /dev/null so that the interpreter's
    last flush does not fail again."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError, AttributeError):
        pass


def _open_closed_streams() -> None:
    """A standard stream the command was started without (``>&-``: Python sets it to None)
    becomes /dev/null, so that nothing written to it fails."""
    for name in ("stdout", "stderr"):
        if getattr(sys, name) is None:
            setattr(sys, name, open(os.devnull, "w", encoding="utf-8"))  # noqa: SIM115 (lives as long as the process)


def _say(message: str) -> None:
    try:
        progress.note(f"regrasp: {message}")
    except (OSError, ValueError):  # stderr closed too
        pass


def pusher_help(cmd: str) -> str:
    """The help of --pusher of command ``cmd`` when no scene is given before --help."""
    return f"a pusher of the scene, by name (`regrasp {cmd} SCENE --help` lists the scene's pushers)"


def check_pusher(scene, name: str) -> None:
    """``--pusher`` names a pusher of ``scene``, else invalid input listing the scene's pushers."""
    names = list(scene.pusher_names)
    if name not in names:
        raise ArgumentError(f"invalid `--pusher`: no pusher {name!r} in scene {scene.name!r}; its pushers: "
                            f"{', '.join(names)}", "--pusher")


def _scene_help(ap: argparse.ArgumentParser, argv: list) -> None:
    """``regrasp COMMAND SCENE --help``: the --pusher help of COMMAND lists the pushers of SCENE
    (the first readable scene among the arguments, loaded quietly)."""
    if not ({"-h", "--help"} & set(argv)):
        return
    sub = next(a for a in ap._actions if isinstance(a, argparse._SubParsersAction))
    cmd = next((t for t in argv if t in sub.choices), None)
    action = cmd and next((a for a in sub.choices[cmd]._actions if "--pusher" in a.option_strings), None)
    if action is None:
        return
    for token in argv[argv.index(cmd) + 1:]:
        if token.startswith("-") or not Path(token).is_file():
            continue
        try:
            scene = load_scene(token)
        except Exception:  # not a scene: the help stays general
            continue
        action.help = f"a pusher of the scene, by name; pushers of {token}: {', '.join(scene.pusher_names)}"
        return


def main(argv=None) -> int:
    """The `regrasp` command; returns its exit status (docs/cli.md). Ctrl-C: 130, after
    "regrasp: interrupted" (outputs are written atomically: nothing half-done is left); a closed
    standard output (``| head``): 141, quietly; SIGTERM: 143, after "regrasp: terminated", as Ctrl-C. Started with standard output or error closed
    (``>&-``), what would go there is discarded; the command runs and its status stands."""
    _open_closed_streams()
    saved = install()
    try:
        argv = sys.argv[1:] if argv is None else list(argv)
        ap = build_parser(chosen(argv))
        _scene_help(ap, argv)
        args = ap.parse_args(argv)
        if args.cmd is None:
            ap.error(f"a COMMAND is required: one of {', '.join(GROUPS)} (`regrasp --help` says what each does)")
        progress.set_quiet(args.quiet)
        status, message = _run(args)
        stop = _stopped()  # a stop turned into an error by the code it interrupted is still the stop
        if stop is not None and status != OK:
            raise stop
        if message is not None:
            _say(message)
        sys.stdout.flush()
        return status
    except Terminated:
        _say("terminated")
        return TERMINATED
    except KeyboardInterrupt:
        _say("interrupted")
        return INTERRUPTED
    except BrokenPipeError:
        _quiet_stdout()
        return BROKEN_PIPE
    finally:
        restore(saved)


if __name__ == "__main__":
    sys.exit(main())
