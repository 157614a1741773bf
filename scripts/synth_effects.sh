#!/usr/bin/env bash
# Does `hapticjam diagnose` find each effect of the registry on data that has
# it, and none on data that has none (issue 5)? For every case below:
#   1. synth: the chosen sessions of demo-baseline replayed with the true
#      model (demo-baseline's true M, k, kappa_jam + the case's effects), seen by the
#      simulated camera (1 mm noise, 1 mm rounding, 1 % dropped, seed 1);
#   2. compare: the synthetic data against the baseline model, i.e. how far
#      the effect moves the frames (the noise alone leaves 1.04 mm);
#   3. diagnose, timed (CPU), one at a time, niced;
# then scripts/synth_effects_table.py writes the table (markdown) from the
# truth.json, summary.json and diagnosis.json files.
#
# usage: scripts/synth_effects.sh [--build DIR] [--work DIR] [--sessions a,b,c]
#                                 [--cases name,name] [--threads N] [--table FILE]
#                                 [--diagnose-args "..."] [--no-diagnose]
# Defaults: build ./build, work /tmp/hj-synth-effects, sessions
# unjammed-sweep,mixed-1,paper-sequence, every case, 2 threads, the
# table on stdout. --no-diagnose: only synth and compare. A case whose diagnosis.json exists is not run again
# (delete its folder to redo it), so the matrix can be run in pieces.
set -euo pipefail

repo="$(cd "$(dirname "$0")/.." && pwd)"
build="$repo/build"
work=/tmp/hj-synth-effects
# mixed-2 and mixed-3 step an unjammed surface to 3.1-3.3 kPa, where the
# static solver finds no equilibrium with bending on (issue 2), so synth
# cannot make the bending datasets from them.
sessions=unjammed-sweep,mixed-1,paper-sequence
only=""
threads=2
table=""
diagnose_args=""
run_diagnose=1
while [[ $# -gt 0 ]]; do
  case "$1" in
    --build) build="$2"; shift 2 ;;
    --work) work="$2"; shift 2 ;;
    --sessions) sessions="$2"; shift 2 ;;
    --cases) only="$2"; shift 2 ;;
    --threads) threads="$2"; shift 2 ;;
    --table) table="$2"; shift 2 ;;
    --diagnose-args) diagnose_args="$2"; shift 2 ;;
    --no-diagnose) run_diagnose=0; shift ;;
    *) echo "synth_effects.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
hj="$build/hapticjam"
[[ -x "$hj" ]] || { echo "synth_effects.sh: no $hj (build first)" >&2; exit 2; }
source_dataset="$repo/../shared/data/sessions/demo-baseline"

# name | effects | --set values: plausible for a real array, each moving the
# frames by clearly more than the 1 mm camera noise (see the table's
# "RMSE vs baseline").
cases=(
  "none||"
  # Every effect at three magnitudes: small, middle, near the largest that
  # synthesises on these sessions (the bound itself has no equilibrium for
  # some, e.g. area_pressure 0.5).
  "bending_small|bending|bending.kappa_bend=0.0005"
  "bending|bending|bending.kappa_bend=0.002"
  "bending_large|bending|bending.kappa_bend=0.01"
  "stiffening_small|stiffening|stiffening.beta=0.5"
  "stiffening|stiffening|stiffening.beta=50"
  "stiffening_large|stiffening|stiffening.beta=600"
  "jam_contraction_small|jam_contraction|jam_contraction.contraction=0.02"
  "jam_contraction|jam_contraction|jam_contraction.contraction=0.05"
  "jam_contraction_large|jam_contraction|jam_contraction.contraction=0.2"
  "jam_creep|jam_creep|jam_creep.creep_per_settle=0.5"
  # At its bound: on these sessions 0.5 barely moves the frames; with
  # --sessions jammed-sweep,... this one does (0.65 mm on jammed-sweep).
  "jam_creep_fast|jam_creep|jam_creep.creep_per_settle=1"
  "cell_stiffness_small|cell_stiffness|cell_stiffness.grad_x=0.05,cell_stiffness.bulge=-0.05"
  "cell_stiffness|cell_stiffness|cell_stiffness.grad_x=0.15,cell_stiffness.bulge=-0.15"
  "cell_stiffness_large|cell_stiffness|cell_stiffness.grad_x=0.28,cell_stiffness.bulge=-0.28"
  "area_pressure_small|area_pressure|area_pressure.weight=0.03"
  "area_pressure|area_pressure|area_pressure.weight=0.1"
  "area_pressure_large|area_pressure|area_pressure.weight=0.3"
  "boundary_compliance_small|boundary_compliance|boundary_compliance.k_edge=2000"
  "boundary_compliance|boundary_compliance|boundary_compliance.k_edge=200"
  "boundary_compliance_large|boundary_compliance|boundary_compliance.k_edge=30"
  "sensor_tilt_small|sensor_tilt|sensor_tilt.tilt_x_mrad=5,sensor_tilt.tilt_y_mrad=-3,sensor_tilt.offset_mm=0.5"
  "sensor_tilt|sensor_tilt|sensor_tilt.tilt_x_mrad=15,sensor_tilt.tilt_y_mrad=-10,sensor_tilt.offset_mm=1.5"
  "sensor_tilt_large|sensor_tilt|sensor_tilt.tilt_x_mrad=45,sensor_tilt.tilt_y_mrad=-40,sensor_tilt.offset_mm=15"
  "pressure_offset_small|pressure_offset|pressure_offset.gain=1.02,pressure_offset.offset_pa=10"
  "pressure_offset|pressure_offset|pressure_offset.gain=1.05,pressure_offset.offset_pa=40"
  "pressure_offset_large|pressure_offset|pressure_offset.gain=1.4,pressure_offset.offset_pa=400"
  # One cell softer than the rest, at two magnitudes in two cells.
  "cell_defect_1_1_soft|cell_defect|cell_defect.factor=0.6,cell_defect.row=1,cell_defect.col=1"
  "cell_defect_1_1_softer|cell_defect|cell_defect.factor=0.3,cell_defect.row=1,cell_defect.col=1"
  "cell_defect_2_3_soft|cell_defect|cell_defect.factor=0.6,cell_defect.row=2,cell_defect.col=3"
  "cell_defect_2_3_stiff|cell_defect|cell_defect.factor=3,cell_defect.row=2,cell_defect.col=3"
  # One physical effect and one of the camera.
  "bending+sensor_tilt|bending,sensor_tilt|bending.kappa_bend=0.002,sensor_tilt.tilt_x_mrad=15,sensor_tilt.tilt_y_mrad=-10,sensor_tilt.offset_mm=1.5"
  "jam_contraction+pressure_offset|jam_contraction,pressure_offset|jam_contraction.contraction=0.05,pressure_offset.gain=1.05,pressure_offset.offset_pa=40"
  "stiffening_large+sensor_tilt|stiffening,sensor_tilt|stiffening.beta=600,sensor_tilt.tilt_x_mrad=15,sensor_tilt.tilt_y_mrad=-10,sensor_tilt.offset_mm=1.5"
  "cell_defect+pressure_offset|cell_defect,pressure_offset|cell_defect.factor=0.5,cell_defect.row=1,cell_defect.col=2,pressure_offset.gain=1.05,pressure_offset.offset_pa=40"
  "stiffening+cell_stiffness|stiffening,cell_stiffness|stiffening.beta=0.5,cell_stiffness.grad_x=0.15,cell_stiffness.bulge=-0.15"
  # Effects written only for the test (tests/tools/offform_effects.cc, made
  # by build/synth_offform): the form differs from the nearest candidate's,
  # which diagnose should choose; the camera bump is like no candidate, so
  # the data should stay unexplained with the residual over cell [1, 2].
  "offform_power_stiffening|test_power_stiffening|test_power_stiffening.beta=5000"
  "offform_interior_contraction|test_interior_contraction|test_interior_contraction.contraction=0.1"
  "offform_soft_interior|test_soft_interior|test_soft_interior.factor=0.3,test_soft_interior.row=1,test_soft_interior.col=2"
  "unknown_camera_bump|test_camera_bump|test_camera_bump.height_mm=5,test_camera_bump.row=1,test_camera_bump.col=2"
)

# The true baseline: demo-baseline's (its README), not the paper's defaults,
# which diagnose starts from as a user would.
truth_base="$work/baseline-truth.json"
mkdir -p "$work"
cat >"$truth_base" <<'JSON'
{"format": "hapticjam.params/1", "surface": {"mass_kg": 0.52, "spring_k": 58, "kappa_jam": 4.2}}
JSON

# The base dataset: links to the chosen sessions of demo-baseline.
base="$work/base"
rm -rf "$base" && mkdir -p "$base"
IFS=, read -ra chosen <<<"$sessions"
for s in "${chosen[@]}"; do
  [[ -f "$source_dataset/$s/session.json" ]] || { echo "synth_effects.sh: no session $s in $source_dataset" >&2; exit 2; }
  ln -sfn "$source_dataset/$s" "$base/$s"  # -n: never a link inside the source session
done

# The cases in the order --cases gives them (cheapest first, say), else all.
ordered=()
if [[ -n "$only" ]]; then
  IFS=, read -ra requested <<<"$only"
  for want in "${requested[@]}"; do
    found=0
    for entry in "${cases[@]}"; do
      [[ "${entry%%|*}" == "$want" ]] && { ordered+=("$entry"); found=1; }
    done
    [[ $found == 1 ]] || { echo "synth_effects.sh: unknown case $want" >&2; exit 2; }
  done
else
  ordered=("${cases[@]}")
fi

for entry in "${ordered[@]}"; do
  IFS='|' read -r name effects sets <<<"$entry"
  dir="$work/$name"
  mkdir -p "$dir"
  model=(--params "$truth_base")
  [[ -n "$effects" ]] && model+=(--effects "$effects")
  if [[ -n "$sets" ]]; then
    IFS=, read -ra items <<<"$sets"
    for item in "${items[@]}"; do model+=(--set "$item"); done
  fi
  synth=("$hj" synth "$base" --out "$dir/data" "${model[@]}")
  if [[ "$effects" == test_* ]]; then
    # The test-only effects: their params file written here, as --set would.
    python3 - "$truth_base" "$effects" "$sets" >"$dir/params.json" <<'PY'
import json, sys
doc = json.load(open(sys.argv[1]))
effects = doc.setdefault("effects", {})
for name in sys.argv[2].split(","):
    effects.setdefault(name, {})
for item in filter(None, sys.argv[3].split(",")):
    key, value = item.split("=")
    effect, parameter = key.split(".")
    effects[effect][parameter] = float(value)
print(json.dumps(doc))
PY
    synth=("$build/synth_offform" "$base" --out "$dir/data" --params "$dir/params.json")
  fi
  if [[ ! -f "$dir/data/truth.json" ]]; then
    if ! nice -n 5 "${synth[@]}" --threads "$threads" >"$dir/synth.log" 2>&1; then
      echo "synth $name failed: $(tail -1 "$dir/synth.log")" >&2
      rm -rf "$dir/data"
      continue
    fi
  fi
  if [[ ! -f "$dir/compare/summary.json" ]]; then
    nice -n 5 "$hj" compare "$dir/data" --params "$truth_base" --out "$dir/compare" --threads "$threads" >"$dir/compare.log" 2>&1
  fi
  if [[ $run_diagnose == 1 && ! -f "$dir/diagnose/diagnosis.json" ]]; then
    echo "diagnose $name ($(date -u +%H:%M:%S))" >&2
    # shellcheck disable=SC2086
    nice -n 5 "$hj" diagnose "$dir/data" --out "$dir/diagnose" --threads "$threads" $diagnose_args \
      >"$dir/diagnose.log" 2>"$dir/diagnose.err" || echo "diagnose $name failed: see $dir/diagnose.err" >&2
  fi
done

names=()
for entry in "${ordered[@]}"; do names+=("${entry%%|*}"); done
if [[ -n "$table" ]]; then
  python3 "$repo/scripts/synth_effects_table.py" "$work" "$sessions" "${names[@]}" >"$table"
else
  python3 "$repo/scripts/synth_effects_table.py" "$work" "$sessions" "${names[@]}"
fi
