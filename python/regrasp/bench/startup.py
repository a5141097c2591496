"""The CLI's start (``regrasp bench``, "CLI start"): the CPU time of `regrasp --version` and of
`regrasp plan t-shape.toml`, each a fresh interpreter, against `python -c "import numpy"` measured
interleaved in the same run; medians. Targets (issue 45): at most 1.5x and 2x numpy's import, i.e.
ratios (numpy / regrasp) of at least 0.67 and 0.5.

Each interpreter may write its bytecode cache (``PYTHONDONTWRITEBYTECODE`` removed; one warm-up
run first), as an installed wheel has it: without the cache every start compiles regrasp's
modules again, which is not the start a user sees.
"""

from __future__ import annotations

import os
import resource
import subprocess
import sys

import numpy as np

from .. import examples as bundled

#: the `regrasp` console script's body, run by the same interpreter
_ENTRY = "import sys; from regrasp.cli import main; sys.exit(main())"
#: what each command's start is compared against
_BASELINE = [sys.executable, "-c", "import numpy"]


def _cpu(cmd: list, env: dict) -> float:
    """CPU time [s] (user + system) of running ``cmd`` to its end."""
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=120, check=False)
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (r1.ru_utime + r1.ru_stime) - (r0.ru_utime + r0.ru_stime)


def run_startup(reps: int = 11) -> dict:
    """Median CPU times [s] of the two commands and of numpy's import, interleaved; ratio =
    numpy / regrasp (>= 1/1.5 and >= 1/2 meet the targets)."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    commands = {
        "cli_start_version": ([sys.executable, "-c", _ENTRY, "--version"], 1.5, "regrasp --version"),
        "cli_start_plan_t_shape": ([sys.executable, "-c", _ENTRY, "-q", "plan", str(bundled.path("t-shape"))],
                                   2.0, "regrasp plan t-shape.toml"),
    }
    for cmd, _, _ in commands.values():  # warm-up: the bytecode cache written, files in the page cache
        _cpu(cmd, env)
    times = {name: [] for name in commands}
    base = []
    for _ in range(reps):
        base.append(_cpu(_BASELINE, env))
        for name, (cmd, _, _) in commands.items():
            times[name].append(_cpu(cmd, env))
    b = float(np.median(base))
    out = {}
    for name, (_, target, what) in commands.items():
        t = float(np.median(times[name]))
        out[name] = {"median_s": t, "baseline_median_s": b, "ratio": b / t,
                     "baseline": f"`import numpy`, CPU time; target: {what} <= {target:g}x it (ratio >= {1 / target:.2f})"}
    return out
