#!/usr/bin/env bash
# Every registered planner on the 11 shared goals (5 DEM files, 6 mesh
# files) at the given sizes: one `sweep` per planner, then per planner how
# many plans finished (status ok), the slowest, and the mean correlation; and
# the portfolio against Algorithm 2 plan by plan (scripts/portfolio_gain.py).
# Usage: scripts/planner_matrix.sh [OUT_DIR] (default /tmp/planner-matrix);
# SIZES (default 9x12; "paper" for the 16 Table 1 sizes), PLANNERS (default:
# every registered one), HJ_BIN (default build/hapticjam), JOBS (sweep
# threads, default 1: the portfolio runs its strategies on every core).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin=${HJ_BIN:-$root/build/hapticjam}
shared=$root/../shared/data
out=${1:-/tmp/planner-matrix}
goals=("$shared"/dem/*.csv "$shared"/dem/*.tif "$shared"/mesh/*.stl "$shared"/mesh/*.obj)
planners=${PLANNERS:-algorithm2 algorithm2-levelled algorithm2-refined from-above portfolio}
mkdir -p "$out"
for planner in $planners; do
  "$bin" sweep "${goals[@]}" --sizes "${SIZES:-9x12}" --planner "$planner" --jobs "${JOBS:-1}" --budget-s 900 \
    --out "$out/$planner" >"$out/$planner.log" 2>&1
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
