"""The fuzz suite's harness: profiles, the per-case runner and the recorder of outcomes.

Profiles (``REGRASP_FUZZ``): ``short`` (default; derandomized, bounded, part of ``make test``)
and ``long`` (random, many cases; ``scripts/fuzz-long.sh``). In the short profile the first bad
outcome fails the test (hypothesis shrinks it to a minimal case); in the long one every outcome
is recorded and the session ends with a summary in ``REGRASP_FUZZ_REPORT`` (JSON), then fails
if anything bad was seen.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

from .harness import RECORDER

def pytest_sessionfinish(session, exitstatus):
    """Writes the recorder's summary (long profile, or whenever REGRASP_FUZZ_REPORT is set)."""
    out = os.environ.get("REGRASP_FUZZ_REPORT")
    if out and RECORDER.cases:
        Path(out).write_text(json.dumps(RECORDER.summary(), indent=1))


def pytest_collection_modifyitems(config, items):
    """Every test of this folder carries the `fuzz` marker (`-m "not fuzz"` skips the suite)."""
    import pytest

    here = Path(__file__).parent
    for item in items:
        if here in Path(str(item.fspath)).parents:
            item.add_marker(pytest.mark.fuzz)
