#!/usr/bin/env bash
# The fuzz suite's long profile (tests/fuzz, REGRASP_FUZZ=long): random, >= 10,000 scene
# mutations, >= 5,000 API calls, >= 200 CLI invocations, >= 10,000 world-side cases (workcell,
# plan, graph, trajectory and mesh files; the world commands; valid runs; SIGTERM and closed
# streams); every outcome is recorded, not only the first failure. Prints the cases run per family,
# the bad outcomes per kind (panics, hangs, NaN/inf, exceptions outside the closed set, internal
# errors, tracebacks, accepted nonsense, wrong fields, temporary files left, memory) with the first
# reproductions and the peak resident memory, and exits 1 when there is any.
# Usage: scripts/fuzz-long.sh [REPORT.json] [pytest args: default tests/fuzz]
# (REGRASP_FUZZ_SCALE=0.1 runs a tenth of the long counts; REGRASP_FUZZ_TIMEOUT: seconds a case may take)
set -euo pipefail
cd "$(dirname "$0")/.."
REPORT="${1:-out/fuzz-long.json}"
shift || true
mkdir -p "$(dirname "$REPORT")"
PY="${PYTHON:-.venv/bin/python}"
[ $# -gt 0 ] || set -- tests/fuzz
REGRASP_FUZZ=long REGRASP_FUZZ_REPORT="$REPORT" "$PY" -m pytest -q -p no:cacheprovider "$@" || true
"$PY" - "$REPORT" <<'PYEOF'
import json, sys
r = json.load(open(sys.argv[1]))
cases = r["cases"]
fam = lambda p: sum(v for k, v in cases.items() if k.startswith(p))
world = ("world.", "cli.execute", "cli.pick-place", "cli.grasp-graph", "cli.regrasp-sequence", "cli.valid-", "process.")
n_world = sum(v for k, v in cases.items() if k.startswith(world))
print(f"\nfuzz ({r['profile']} profile): {fam('scene.')} scene cases, {fam('api.')} API calls, {fam('cli.')} CLI "
      f"invocations; {n_world} of all on the world side")
for k, v in sorted(cases.items()):
    print(f"  {k:40s} {v}")
print("bad outcomes: " + ", ".join(f"{k} {v}" for k, v in r["bad"].items()))
peak = r.get("peak_bytes", {})
print("peak resident memory: " + ", ".join(f"{k} {v / 2**30:.2f} GiB" for k, v in peak.items()))
for kind, ex in r["examples"].items():
    for e in ex[:5]:
        print(f"  [{kind}] {e['family']}: {e['case'][:300]}\n      {e['detail'].strip().splitlines()[-1][:300]}")
sys.exit(1 if any(r["bad"].values()) else 0)
PYEOF
