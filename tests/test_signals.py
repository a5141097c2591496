"""Ctrl-C: the core's long loops (T-RRT* search, quasi-static stepping, batches, path checks)
poll Python's signal handlers, so SIGINT stops them within a fraction of a second with
KeyboardInterrupt, whatever the remaining budget. Each case runs in a subprocess that would take
far longer than the test waits; SIGINT comes once the subprocess says it started the call.
"""

import os
import signal
import subprocess
import sys
import time

import pytest

from .conftest import EXAMPLES, ROOT

pytestmark = pytest.mark.skipif(os.name != "posix", reason="SIGINT to a subprocess")

PRELUDE = f"""
import sys, numpy as np, regrasp
from regrasp import _core
from pathlib import Path
E = Path({str(EXAMPLES)!r})
planar = _core.Scene.from_toml((E / "block-low-friction.toml").read_text())
s3 = _core.Scene3D.from_toml((E / "pivot-3d.toml").read_text(), str(E))
print("started", flush=True)
"""

# each call would run for minutes (a goal that cannot be reached, a tiny step, no node limit)
LONG = {
    "planar plan": "planar.plan(None, None, {'time_limit': 600, 'max_nodes': 10**8, 'max_iterations': 10**12, 'cost_threshold': -1.0, 'refine': float('inf')})",
    "python plan": "regrasp.plan(regrasp.load_scene(E / 'block-low-friction.toml'), time_limit=600, max_nodes=10**8,"
                   " max_iterations=10**12, cost_threshold=-1.0, refine=float('inf'))",
    "3-d plan": "s3.plan(None, None, {'time_limit': 600, 'max_nodes': 10**8, 'max_iterations': 10**12, 'cost_threshold': -1.0, 'refine': float('inf')})",
    "planar simulate_push": "planar.simulate_push([0, 0, 0], 'left', [1e-9, 0, 0], 1e5, 0.1)",
    "push_outcomes": "planar.push_outcomes(np.zeros((10**6, 3)), 'left', np.tile([0.01, 0, 0], (10**6, 1)))",
    # single solves on the incline's footprint, many points (about 1 s each before the block-arrow
    # Newton step, 0.5 ms now): stopped inside a solve or between two
    "slow push_outcomes": "incline = _core.Scene.from_toml((E / 'block-on-incline.toml').read_text()); "
                          "incline.push_outcomes(np.zeros((10**6, 3)), 'finger', np.tile([0.004, 0.006, -0.1], (10**6, 1)))",
    "validate_path": "planar.validate_path([[0, 0, 0], [1e-6, 0, 0]] * 20000, [None] + ['left'] * 39999, 10000)",
}


def interrupted(call: str, wait: float = 1.0):
    """Runs `call` in a subprocess, sends SIGINT `wait` s after it starts: (seconds from SIGINT
    to the KeyboardInterrupt reaching Python, seconds from SIGINT to exit, return code, stdout,
    stderr). The first is the stop; the second adds the interpreter's teardown, which a loaded
    machine (cargo test beside pytest on 2 cores) can stretch past a second."""
    body = "\n".join("    " + line for line in call.split("; "))
    code = (PRELUDE + "import time\ntry:\n" + body + "\nexcept KeyboardInterrupt:\n"
            "    print('caught', time.monotonic(), file=sys.stderr, flush=True)\n    raise\n"
            "print('finished', flush=True)\n")
    p = subprocess.Popen([sys.executable, "-c", code], cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert p.stdout.readline().strip() == "started", p.stderr.read()
        time.sleep(wait)
        assert p.poll() is None, f"the call ended before the signal: {p.communicate()}"
        p.send_signal(signal.SIGINT)
        t0 = time.monotonic()
        out, err = p.communicate(timeout=30)
        t_exit = time.monotonic()
        caught = [float(line.split()[1]) for line in err.splitlines() if line.startswith("caught ")]
        t_stop = caught[0] if caught else float("inf")
        return t_stop - t0, t_exit - t0, p.returncode, out, err
    finally:
        if p.poll() is None:
            p.kill()
            p.wait()


@pytest.mark.parametrize("name", list(LONG))
def test_ctrl_c_stops_a_long_call_within_a_second(name):
    dt, dt_exit, rc, out, err = interrupted(LONG[name])
    assert "KeyboardInterrupt" in err, (name, err[-2000:])
    assert "finished" not in out
    assert rc != 0
    assert dt < 1.0, f"{name}: {dt:.2f} s from SIGINT to the KeyboardInterrupt"
    assert dt_exit < 10.0, f"{name}: {dt_exit:.2f} s from SIGINT to exit"
    assert "PanicException" not in err and "panicked" not in err
