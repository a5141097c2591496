"""Sections a Ctrl-C or SIGTERM must not cut: a signal that arrives inside :func:`deferred` is
acted on when the section ends (`regrasp`'s handlers, :mod:`regrasp.cli.stopping`, send it again
until then). Starting a local Ray cluster is one: cut half-way, its agents outlive the command.
"""

from __future__ import annotations

from contextlib import contextmanager

#: how many deferred sections are open (nested ones count)
_OPEN: list = []


@contextmanager
def deferred():
    """A section during which `regrasp`'s stop waits (the signal is acted on after it)."""
    _OPEN.append(True)
    try:
        yield
    finally:
        _OPEN.pop()


def deferring() -> bool:
    """Whether a deferred section is open."""
    return bool(_OPEN)
