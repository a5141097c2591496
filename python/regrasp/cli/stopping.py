"""How `regrasp` stops on Ctrl-C (SIGINT) and SIGTERM: the signal raises where the command is
(KeyboardInterrupt, or :class:`Terminated`), so that outputs stay uncommitted, temporary files are
removed and worker processes stopped; `regrasp` then exits 130 or 143 (docs/cli.md).

A signal that arrives while a module is being imported, or inside a section that must not be cut
(:func:`regrasp.interrupts.deferred`: starting a local Ray cluster), waits for its end (it is sent
again every :data:`RESEND` seconds until then). An exception raised inside an import can pass
through an extension module's own run of Python code (``PyRun_*``, e.g. while MuJoCo's bindings
load), which CPython marks as an unhandled Ctrl-C for good; the interpreter would then end by
killing itself with SIGINT whatever status the command returned.
"""

from __future__ import annotations

import os
import signal
import threading

from ..interrupts import deferring

#: seconds after which a signal deferred by an import is sent again
RESEND = 0.05

#: the signals that asked the command to stop (SIGINT or SIGTERM), in order
STOPPED: list = []
#: whether a command is running with these handlers (a deferred signal is sent again only then)
_ACTIVE = threading.Event()


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised where the command is, so that it stops as on Ctrl-C."""


def _importing(frame) -> bool:
    """Whether ``frame`` runs inside an import (importlib's frames on its stack)."""
    while frame is not None:
        if frame.f_code.co_filename.startswith("<frozen importlib"):
            return True
        frame = frame.f_back
    return False


def _send_again(signum: int) -> None:
    if _ACTIVE.is_set():
        os.kill(os.getpid(), signum)


def on_signal(signum, frame):
    """The handler of SIGINT and SIGTERM while a command runs."""
    STOPPED.append(signum)
    if _importing(frame) or deferring():
        timer = threading.Timer(RESEND, _send_again, (signum,))
        timer.daemon = True
        timer.start()
        return
    raise Terminated() if signum == signal.SIGTERM else KeyboardInterrupt()


def stopped() -> KeyboardInterrupt | None:
    """The interrupt to raise when a signal asked the command to stop: an exception raised inside
    a compiled solver by the signal may come back as another one (a QP solver's "Buffer dtype
    mismatch"); it is the stop, not an internal error."""
    if not STOPPED:
        return None
    return Terminated() if STOPPED[-1] == signal.SIGTERM else KeyboardInterrupt()


def install() -> tuple:
    """Handlers for a command (main thread only; SIGINT only where Python's default handler is
    in place): what :func:`restore` needs."""
    STOPPED.clear()
    if threading.current_thread() is not threading.main_thread():
        return ()
    _ACTIVE.set()
    old_term = signal.signal(signal.SIGTERM, on_signal)
    old_int = signal.signal(signal.SIGINT, on_signal) if signal.getsignal(signal.SIGINT) is signal.default_int_handler else None
    return (old_term, old_int)


def restore(saved: tuple) -> None:
    """The handlers before :func:`install`."""
    if not saved:
        return
    _ACTIVE.clear()
    old_term, old_int = saved
    signal.signal(signal.SIGTERM, signal.SIG_DFL if old_term is None else old_term)
    if old_int is not None:
        signal.signal(signal.SIGINT, old_int)
