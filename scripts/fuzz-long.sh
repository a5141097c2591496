#!/usr/bin/env bash
# The fuzz suite's long profile (tests/fuzz, REGRASP_FUZZ=long): random, >= 10,000 scene
# mutations, >= 5,000 API calls, >= 200 CLI invocations; every outcome is recorded, not only the
# first failure. Prints the cases run per family and the bad outcomes per kind (panics, hangs,
# NaN/inf, exceptions outside the closed set, tracebacks, ...) with the first reproductions, and
# exits 1 when there is any. Usage: scripts/fuzz-long.sh [REPORT.json] [pytest args...]
# (REGRASP_FUZZ_SCALE=0.1 runs a tenth of the long counts; REGRASP_FUZZ_TIMEOUT: seconds a case may take)
set -euo pipefail
cd "$(dirname "$0")/.."
REPORT="${1:-out/fuzz-long.json}"
shift || true
mkdir -p "$(dirname "$REPORT")"
PY="${PYTHON:-.venv/bin/python}"
REGRASP_FUZZ=long REGRASP_FUZZ_REPORT="$REPORT" "$PY" -m pytest -q -p no:cacheprovider tests/fuzz "$@" || true
"$PY" - "$REPORT" <<'PYEOF'
import json, sys
r = json.load(open(sys.argv[1]))
cases = r["cases"]
fam = lambda p: sum(v for k, v in cases.items() if k.startswith(p))
print(f"\nfuzz ({r['profile']} profile): {fam('scene.')} scene cases, {fam('api.')} API calls, {fam('cli.')} CLI invocations")
for k, v in sorted(cases.items()):
    print(f"  {k:40s} {v}")
print("bad outcomes: " + ", ".join(f"{k} {v}" for k, v in r["bad"].items()))
for kind, ex in r["examples"].items():
    for e in ex[:5]:
        print(f"  [{kind}] {e['family']}: {e['case'][:300]}\n      {e['detail'].strip().splitlines()[-1][:300]}")
sys.exit(1 if any(r["bad"].values()) else 0)
PYEOF
