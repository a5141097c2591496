#!/usr/bin/env bash
# A/B of the core's criterion benches: a base revision against the working tree, on the same
# machine, interleaved (base first, then this tree first), medians and ratios.
#   scripts/bench-ab.sh BASE_REV [ROUNDS]      e.g. scripts/bench-ab.sh c91a425 3
set -euo pipefail
base_rev=${1:?usage: scripts/bench-ab.sh BASE_REV [ROUNDS]}
rounds=${2:-3}
top=$(git rev-parse --show-toplevel)
work=$(mktemp -d)
trap 'git -C "$top" worktree remove --force "$work/base" >/dev/null 2>&1 || true' EXIT
git -C "$top" worktree add --detach "$work/base" "$base_rev" >/dev/null
# the benches' crate: regrasp-bench, or regrasp-core in a revision before they had their own
crate() { if [ -d "$1/crates/regrasp-bench" ]; then echo regrasp-bench; else echo regrasp-core; fi; }
(cd "$work/base" && CARGO_TARGET_DIR="$work/base-target" cargo bench -p "$(crate "$work/base")" --no-run -q)
(cd "$top" && cargo bench -p "$(crate "$top")" --no-run -q)
bin() { ls "$1"/release/deps/"$2"-* | grep -v '\.d$' | head -1; }
run() {  # run NAME TARGET_DIR SRC_DIR ROUND LABEL
  (cd "$3/crates/$(crate "$3")" && CRITERION_HOME="$work/criterion-$5" "$(bin "$2" "$1")" --bench --warm-up-time 1 \
    --measurement-time 2 --noplot > "$work/$1-$5-$4.txt" 2>&1)
}
for b in cones mncp mpc; do
  for r in $(seq "$rounds"); do
    if [ $((r % 2)) = 1 ]; then run $b "$work/base-target" "$work/base" $r base; run $b "$top/target" "$top" $r new
    else run $b "$top/target" "$top" $r new; run $b "$work/base-target" "$work/base" $r base; fi
  done
done
python3 - "$work" <<'PY'
import collections, glob, re, statistics, sys
units = {"ns": 1e-9, "µs": 1e-6, "us": 1e-6, "ms": 1e-3, "s": 1.0}
res = collections.defaultdict(lambda: {"base": [], "new": []})
for f in glob.glob(sys.argv[1] + "/*-*-*.txt"):
    b, ver, _ = f.rsplit("/", 1)[1][:-4].split("-")
    lines = open(f).read().split("\n")
    for i, l in enumerate(lines):
        m = re.search(r"time:\s+\[\S+ \S+ (\S+) (\S+) \S+ \S+\]", l)
        if m:
            name = l.split("time:")[0].strip() or lines[i - 1].strip()
            res[name][ver].append(float(m.group(1)) * units[m.group(2)])
fmt = lambda x: f"{x * 1e6:.3g} µs" if x < 1e-3 else f"{x * 1e3:.3g} ms"
print("| bench | base (median) | this tree | ratio |\n|---|---|---|---|")
for k, v in sorted(res.items()):
    if v["base"] and v["new"]:
        a, c = statistics.median(v["base"]), statistics.median(v["new"])
        print(f"| {k} | {fmt(a)} | {fmt(c)} | {c / a:.2f} |")
PY
