#!/usr/bin/env bash
# The gain of `--align` (docs/planners.md) on the 11 shared goals at 3 x 4
# and 6 x 8, with algorithm2 and algorithm2-levelled: one `sweep --align`
# per planner, then mean, best and worst gain and the time cost per planner
# and size. Usage: scripts/align_gain.sh [OUT_DIR] (default /tmp/align-gain);
# HJ_BIN (default build/hapticjam), JOBS (sweep threads, default 2),
# PLANNERS (default "algorithm2 algorithm2-levelled"), PICK=random for the
# control: as many windows picked at random instead of by valley cost
# (sweep --align-pick).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin=${HJ_BIN:-$root/build/hapticjam}
shared=$root/../shared/data
out=${1:-/tmp/align-gain}
goals=("$shared"/dem/*.csv "$shared"/dem/*.tif "$shared"/mesh/*.stl "$shared"/mesh/*.obj)
for planner in ${PLANNERS:-algorithm2 algorithm2-levelled}; do
  nice -n 10 "$bin" sweep "${goals[@]}" --sizes 3x4,6x8 --planner "$planner" --align-pick "${PICK:-cost}" --jobs "${JOBS:-2}" \
    --out "$out/$planner" >"$out.$planner.log"
done
python3 - "$out" <<'PY'
import csv, sys, pathlib
out = pathlib.Path(sys.argv[1])
print(f"{'planner':20} {'size':5} {'n':>3} {'mean gain':>9} {'best':>7} {'worst':>7} {'moved':>5} {'time x':>6}")
for planner in ("algorithm2", "algorithm2-levelled"):
    if not (out / planner / "sweep.csv").exists():
        continue
    rows = list(csv.DictReader(open(out / planner / "sweep.csv")))
    for size in ("3x4", "6x8"):
        sel = [r for r in rows if f"{r['rows']}x{r['cols']}" == size and r["align_gain"] != ""]
        gains = [float(r["align_gain"]) for r in sel]
        moved = sum(1 for r in sel if (r["align_shift_x_cells"], r["align_shift_y_cells"], r["align_scale"]) != ("0", "0", "1"))
        ratio = sum(float(r["seconds"]) for r in sel) / max(1e-9, sum(float(r["unaligned_seconds"]) for r in sel))
        if gains:
            print(f"{planner:20} {size:5} {len(gains):3d} {sum(gains)/len(gains):9.4f} {max(gains):7.4f} {min(gains):7.4f} "
                  f"{moved:5d} {ratio:6.2f}")
    for r in rows:
        print(f"  {r['goal']:28} {r['rows']}x{r['cols']} unaligned {r['unaligned_correlation']:>9} aligned {r['correlation']:>9} "
              f"gain {r['align_gain']:>9} shift {r['align_shift_x_cells']:>6},{r['align_shift_y_cells']:>6} scale {r['align_scale']:>5} "
              f"planned {r['align_planned']} {float(r['seconds']):6.1f} s ({float(r['unaligned_seconds'] or 0):5.1f} s unaligned) {r['status']}")
PY
