"""Runs one fuzz case and judges its outcome: no panic, no hang, no NaN/inf in any output, only
the closed exception set (SceneError/ArgumentError naming a field, GraspError)."""

from __future__ import annotations

import contextlib
import dataclasses
import faulthandler
import math
import os
import resource
import signal
import time
import traceback
from collections import Counter, defaultdict

import numpy as np
from hypothesis import HealthCheck, settings

import regrasp
from regrasp.errors import ArgumentError, GraspError, RegraspError, SceneError
from regrasp.scene.planar import MotionConeBatch

#: the long profile (REGRASP_FUZZ=long): record every outcome instead of failing on the first
LONG = os.environ.get("REGRASP_FUZZ", "short") == "long"
#: seconds one case may take before it counts as a hang
TIMEOUT = float(os.environ.get("REGRASP_FUZZ_TIMEOUT", "10"))
#: outcome kinds that are failures
BAD = ("panic", "hang", "nan", "out_of_set", "no_field", "accepted", "wrong_field", "traceback", "exit_status",
       "internal", "clobbered", "temp_left", "memory")


#: bytes of data a case may add to the process (RLIMIT_DATA; a subprocess gets this much in all):
#: an unbounded read fails the case ("memory") instead of the machine
MEMORY = int(float(os.environ.get("REGRASP_FUZZ_MEMORY_GB", "8")) * 2**30)
#: peak resident memory [bytes] over which the long profile counts a "memory" outcome
PEAK = int(float(os.environ.get("REGRASP_FUZZ_PEAK_GB", "2")) * 2**30)


def _data_bytes() -> int:
    """The process's data segment now (VmData) [bytes]."""
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmData:"):
                return int(line.split()[1]) * 1024
    return 0


@contextlib.contextmanager
def memory_limit(extra: int | None = None):
    """At most ``extra`` (default :data:`MEMORY`) more bytes of data while the block runs."""
    soft, hard = resource.getrlimit(resource.RLIMIT_DATA)
    limit = _data_bytes() + (MEMORY if extra is None else extra)
    if hard != resource.RLIM_INFINITY:
        limit = min(limit, hard)
    resource.setrlimit(resource.RLIMIT_DATA, (limit, hard))
    try:
        yield
    finally:
        resource.setrlimit(resource.RLIMIT_DATA, (soft, hard))


def limit_child() -> None:
    """A subprocess's ``preexec_fn``: at most :data:`MEMORY` bytes of data in all."""
    resource.setrlimit(resource.RLIMIT_DATA, (MEMORY, resource.getrlimit(resource.RLIMIT_DATA)[1]))


def peak_bytes() -> dict:
    """Peak resident memory [bytes] of this process and of its largest finished child."""
    return {"self": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024,
            "children": resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss * 1024}


settings.register_profile(
    "fuzz-short", derandomize=True, database=None, deadline=None, print_blob=False,
    suppress_health_check=list(HealthCheck),
)
settings.register_profile(
    "fuzz-long", derandomize=False, database=None, deadline=None, print_blob=True,
    suppress_health_check=list(HealthCheck),
)


def n_examples(short: int, long: int) -> int:
    """Examples per test in the active profile (REGRASP_FUZZ_SCALE scales the long one)."""
    return max(1, int(long * float(os.environ.get("REGRASP_FUZZ_SCALE", "1")))) if LONG else short


def fuzz_settings(short: int, long: int) -> settings:
    """The active profile's settings with ``short``/``long`` examples."""
    return settings(settings.get_profile("fuzz-long" if LONG else "fuzz-short"), max_examples=n_examples(short, long))


class Hang(BaseException):
    """Raised in the main thread by the alarm when a case runs past TIMEOUT."""


class Recorder:
    """Counts cases per family and bad outcomes per kind, with the first few reproductions."""

    def __init__(self):
        self.cases = Counter()
        self.bad = Counter()
        self.examples = defaultdict(list)

    def case(self, family: str) -> None:
        self.cases[family] += 1

    def fail(self, kind: str, family: str, what: str, detail: str) -> None:
        self.bad[kind] += 1
        if len(self.examples[kind]) < int(os.environ.get("REGRASP_FUZZ_EXAMPLES", "25")):
            self.examples[kind].append({"family": family, "case": what, "detail": detail[-2000:]})
        if not LONG:
            raise AssertionError(f"[{kind}] {family}: {what}\n{detail}")

    def summary(self) -> dict:
        peak = peak_bytes()
        if max(peak.values()) > PEAK and not self.bad.get("memory"):
            self.bad["memory"] += 1
            self.examples["memory"].append({"family": "session", "case": "peak resident memory",
                                            "detail": f"{peak} bytes, over {PEAK}"})
        return {"profile": "long" if LONG else "short", "cases": dict(self.cases),
                "bad": {k: self.bad.get(k, 0) for k in BAD}, "examples": dict(self.examples), "peak_bytes": peak}


RECORDER = Recorder()


def _alarm(signum, frame):
    raise Hang()


def non_finite(x, path: str = "", seen=None) -> str | None:
    """Path of the first NaN/inf in an output (numbers, numpy arrays, lists, tuples, dicts,
    dataclasses, Plans), or None."""
    if isinstance(x, (bool, np.bool_, str, bytes)) or x is None:
        return None
    if isinstance(x, (float, np.floating, complex)):
        return None if np.isfinite(x) else path or "<value>"
    if isinstance(x, (int, np.integer)):
        return None
    if isinstance(x, np.ndarray):
        if x.dtype.kind in "fc" and not np.all(np.isfinite(x)):
            return f"{path}[{np.argwhere(~np.isfinite(x))[0].tolist()}]"
        if x.dtype.kind == "O":
            return non_finite(x.tolist(), path)
        return None
    if isinstance(x, dict):
        for k, v in x.items():
            r = non_finite(v, f"{path}.{k}")
            if r:
                return r
        return None
    if isinstance(x, (list, tuple)):
        for i, v in enumerate(x):
            r = non_finite(v, f"{path}[{i}]")
            if r:
                return r
        return None
    if isinstance(x, regrasp.Plan):
        return non_finite(x.to_json(), path)
    if dataclasses.is_dataclass(x) and not isinstance(x, type):
        # a batch keeps the poses it was given, bad rows included: its `status` marks those (the
        # outputs, `generators`, are checked)
        echo = {"poses"} if isinstance(x, MotionConeBatch) else set()
        return non_finite({f.name: getattr(x, f.name) for f in dataclasses.fields(x) if f.name not in echo
                           and not isinstance(getattr(x, f.name), (regrasp.Scene, regrasp.Scene3D))}, path)
    return None


def is_panic(e: BaseException) -> bool:
    """A Rust panic that crossed into Python (pyo3's PanicException) or the bindings' InternalError."""
    names = {c.__name__ for c in type(e).__mro__}
    return "PanicException" in names or "InternalError" in names


def judge_exception(e: BaseException, family: str, what: str) -> None:
    """Records an exception outside the closed set, a panic, or an error without its field."""
    tb = "".join(traceback.format_exception(type(e), e, e.__traceback__))
    if isinstance(e, Hang):
        RECORDER.fail("hang", family, what, f"ran past {TIMEOUT} s\n{tb}")
    elif is_panic(e):
        RECORDER.fail("panic", family, what, tb)
    elif isinstance(e, (SceneError, ArgumentError)):
        if not (isinstance(e.field, str) and e.field.strip()):
            RECORDER.fail("no_field", family, what, f"{type(e).__name__} without a field: {e}")
    elif isinstance(e, (GraspError, RegraspError)):
        pass
    elif isinstance(e, KeyboardInterrupt):
        raise e
    elif isinstance(e, MemoryError):
        RECORDER.fail("memory", family, what, f"ran out of its {MEMORY} bytes: an unbounded read?\n{tb}")
    else:
        RECORDER.fail("out_of_set", family, what, tb)


def _top(field: str) -> str:
    return field.split(".")[0].split("[")[0].strip("`-")


def _check_rejected(e: BaseException, family: str, what: str, reject: list) -> None:
    """A rejection of input that had to be rejected names one of the fields ``reject`` (their
    top-level key at least: ``pushers[2].points`` for ``pushers``)."""
    # a key with no name ("" at the top) can only be named by where it is: any field will do
    if isinstance(e, (SceneError, ArgumentError)) and e.field and not any(_top(f) in ("", _top(e.field)) for f in reject):
        RECORDER.fail("wrong_field", family, what, f"expected a field of {reject}, got {e.field!r}: {e}")


def run(family: str, what: str, fn, timeout: float | None = None, reject: list | None = None):
    """Runs ``fn()`` as one case of ``family``; returns its result (None on an error of the
    closed set). ``what`` reproduces the case in a report. ``reject``: fields of which the input
    certainly has an invalid one: ``fn`` must raise SceneError/ArgumentError naming one."""
    RECORDER.case(family)
    limit = TIMEOUT if timeout is None else timeout
    old = signal.signal(signal.SIGALRM, _alarm)
    signal.setitimer(signal.ITIMER_REAL, limit)
    # a loop that never checks signals is not interrupted by the alarm: its stack goes to stderr
    faulthandler.dump_traceback_later(3 * limit + 5, exit=False)
    t0 = time.monotonic()
    try:
        with memory_limit():
            out = fn()
    except BaseException as e:  # noqa: BLE001 - judging every outcome is the point
        signal.setitimer(signal.ITIMER_REAL, 0)
        judge_exception(e, family, what)
        if reject:
            _check_rejected(e, family, what, reject)
        return None
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        faulthandler.cancel_dump_traceback_later()
        signal.signal(signal.SIGALRM, old)
    took = time.monotonic() - t0
    if took > limit:  # the alarm could not interrupt it (a loop that does not check signals)
        RECORDER.fail("hang", family, what, f"took {took:.1f} s (limit {limit} s); signals not checked")
    if reject:
        RECORDER.fail("accepted", family, what, f"invalid input accepted (expected an error naming one of {reject})")
    bad = non_finite(out)
    if bad:
        RECORDER.fail("nan", family, what, f"non-finite output at {bad}")
    return out
