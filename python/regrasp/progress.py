"""Progress bars on stderr (tqdm), for work that can take more than a few seconds.

A bar is shown only when stderr is a terminal and output is not quieted (``regrasp -q``, or
:func:`set_quiet`); otherwise the bars do nothing. Standard output is never written to. Messages
on stderr during a bar go through :func:`note` (on their own line, not glued onto the bar).
"""

from __future__ import annotations

import contextlib
import os
import sys
import threading
import time

_quiet = False

#: a bar of a task that ends sooner than this [s] is never drawn (environment: REGRASP_PROGRESS_DELAY)
DELAY_S = 1.0


def _delay() -> float:
    try:
        return max(float(os.environ.get("REGRASP_PROGRESS_DELAY", DELAY_S)), 0.0)
    except ValueError:
        return DELAY_S


def set_quiet(quiet: bool) -> None:
    """Turns every bar off (``True``) or back on where stderr is a terminal (``False``)."""
    global _quiet
    _quiet = bool(quiet)


def enabled() -> bool:
    """Whether bars are drawn: not quieted and stderr a terminal."""
    if _quiet:
        return False
    try:
        return sys.stderr.isatty()
    except (AttributeError, ValueError):  # stderr closed or replaced
        return False


def _columns() -> int:
    """The width of the terminal on stderr (0 when it reports none)."""
    try:
        return os.get_terminal_size(sys.stderr.fileno()).columns
    except (OSError, ValueError, AttributeError):
        return 0


def note(text: str) -> None:
    """Prints ``text`` on its own line of stderr: above a progress bar being drawn (the bar is
    cleared and redrawn below it), plainly when no bar can be shown. Every message printed on
    stderr while a bar may be shown goes through here."""
    if enabled():
        from tqdm import tqdm

        tqdm.write(text, file=sys.stderr)
    else:
        print(text, file=sys.stderr)


class _Null:
    """A bar that draws nothing."""

    def update(self, n: float = 1) -> None:
        pass

    def set_postfix_str(self, s: str = "", refresh: bool = True) -> None:
        pass

    def close(self) -> None:
        pass


@contextlib.contextmanager
def bar(total: float | None, desc: str, unit: str = "it", show: bool = True, bar_format: str | None = None):
    """A progress bar of ``total`` units (``update(n)`` advances it), closed on exit (also on an
    exception, so that a message follows a finished line); a bar that does nothing when bars are
    off or ``show`` is False."""
    if not (show and enabled()):
        yield _Null()
        return
    from tqdm import tqdm

    # a terminal that reports no size (a fresh pseudo-terminal) gets 80 columns, not an empty bar
    sized = _columns() > 0
    b = tqdm(total=total, desc=desc, unit=unit, file=sys.stderr, delay=_delay(), leave=False, dynamic_ncols=sized,
             ncols=None if sized else 80, nrows=None if sized else 24, bar_format=bar_format)
    try:
        yield b
    finally:
        b.close()


def iterate(items, desc: str, unit: str = "it", total: int | None = None, show: bool = True):
    """``items``, advancing a bar (see :func:`bar`) for each."""
    if total is None:
        try:
            total = len(items)
        except TypeError:
            total = None
    with bar(total, desc, unit, show) as b:
        for x in items:
            yield x
            b.update(1)


@contextlib.contextmanager
def elapsed(limit_s: float | None, desc: str, show: bool = True, period_s: float = 0.2):
    """A bar of the time elapsed [s] against ``limit_s`` (None or inf: no limit), advanced by a
    background thread while the body runs (e.g. the planner, which releases the GIL); drawn only
    once the body has run for :data:`DELAY_S`."""
    if not (show and enabled()):
        yield
        return
    total = limit_s if limit_s is not None and 0 < limit_s < float("inf") else None
    stop = threading.Event()
    fmt = ("{desc}: {percentage:3.0f}%|{bar}| {n:.1f}/{total:.1f} s" if total else "{desc}: {n:.1f} s")
    with bar(total, desc, "s", show, fmt) as b:
        def tick() -> None:
            t0 = last = time.monotonic()
            while not stop.wait(period_s):
                now = time.monotonic()
                step = now - last if total is None else min(now - last, max(total - (last - t0), 0.0))
                b.update(step)
                last = now

        thread = threading.Thread(target=tick, name="regrasp-progress", daemon=True)
        thread.start()
        try:
            yield
        finally:
            stop.set()
            thread.join()
