#!/usr/bin/env bash
# Every registered planner on the 11 shared goals (5 DEM files, 6 mesh
# files) at the given sizes: goal by goal, one `sweep` per planner (so the
# planners' times of a plan are taken a minute or two apart, not a whole
# sweep apart on a machine whose speed drifts), merged into
# OUT_DIR/PLANNER/sweep.csv; then per planner how many plans finished
# (status ok), the slowest, and the mean correlation; and the portfolio
# against Algorithm 2 plan by plan (scripts/portfolio_gain.py).
# Usage: scripts/planner_matrix.sh [OUT_DIR] (default /tmp/planner-matrix);
# SIZES (default 9x12; "paper" for the 16 Table 1 sizes, or a list such as
# 2x3,9x12), PLANNERS (default: every registered one), HJ_BIN (default
# build/hapticjam), JOBS (sweep threads, default 1: the portfolio runs its
# strategies on every core).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin=${HJ_BIN:-$root/build/hapticjam}
shared=$root/../shared/data
out=${1:-/tmp/planner-matrix}
goals=("$shared"/dem/*.csv "$shared"/dem/*.tif "$shared"/mesh/*.stl "$shared"/mesh/*.obj)
planners=${PLANNERS:-algorithm2 algorithm2-levelled algorithm2-refined from-above portfolio}
mkdir -p "$out"
for planner in $planners; do rm -f "$out/$planner.log"; done
for k in "${!goals[@]}"; do  # by index: the Luxembourg CSV and TIFF share a name
  for planner in $planners; do
    "$bin" sweep "${goals[$k]}" --sizes "${SIZES:-9x12}" --planner "$planner" --jobs "${JOBS:-1}" --budget-s 900 \
      --out "$out/$planner/goal$k" >>"$out/$planner.log" 2>&1
  done
done
for planner in $planners; do  # one sweep.csv per planner, the goals in order
  for k in "${!goals[@]}"; do
    if ((k == 0)); then cat "$out/$planner/goal$k/sweep.csv"; else tail -n +2 "$out/$planner/goal$k/sweep.csv"; fi
  done >"$out/$planner/sweep.csv"
done
python3 - "$out" $planners <<'PY'
import csv, sys
out, planners = sys.argv[1], sys.argv[2:]
print("| planner | plans | finished (ok) | mean correlation | slowest plan s | refused, all plans |")
print("|---|---|---|---|---|---|")
for p in planners:
    rows = list(csv.DictReader(open(f"{out}/{p}/sweep.csv")))
    ok = [r for r in rows if r["status"] == "ok"]
    mean = sum(float(r["correlation"]) for r in ok) / max(len(ok), 1)
    print(f"| {p} | {len(rows)} | {len(ok)} | {mean:.3f} | {max(float(r['seconds']) for r in rows):.1f} | "
          f"{sum(int(r['refused']) for r in rows)} |")
PY
if [[ " $planners " == *" algorithm2 "* && " $planners " == *" portfolio "* ]]; then
  python3 "$root/scripts/portfolio_gain.py" "$out/algorithm2/sweep.csv" "$out/portfolio/sweep.csv"
fi
