#!/usr/bin/env bash
# How far a real sequence's ATE moves under changes that should not matter, so a change is judged against that
# spread (issue #33): the four benchmark configurations, each from the first frame and from two later starts, and
# with the ORB feature count 10 % lower and higher. Deterministic mode; one run per cell.
#   [FEATURES=1000] [RESUME=1] bench/kitchen_spread.sh [DATASET=../shared/realdata/7scenes_redkitchen] [OUT=/tmp/varslam_kitchen_spread]
#     [-- extra run options]
# RESUME=1 keeps the cells of OUT that have a metrics.json (a sweep that was cut off goes on where it stopped).
# Writes OUT/spread.md (a table: ATE per configuration and variant, and each configuration's spread) and prints it.
set -euo pipefail
cd "$(dirname "$0")/.."
data=${1:-../shared/realdata/7scenes_redkitchen}; out=${2:-/tmp/varslam_kitchen_spread}
shift $(( $# < 2 ? $# : 2 )); [ "${1:-}" = "--" ] && shift
bin=build/bin/varslam
[ -x "$bin" ] || { echo "kitchen_spread: $bin not built (scripts/build.sh varslam_cli)" >&2; exit 2; }
[ -d "$data" ] || { echo "kitchen_spread: no dataset folder '$data'" >&2; exit 2; }
mkdir -p "$out"

# The configurations as `varslam bench` defines them (src/report/bench_matrix.cpp).
declare -A config=(
  [huber]="--set tracking.kernel=huber --set mapping.kernel=huber --set semantic.detector=none"
  [semantic]="--set tracking.kernel=huber --set mapping.kernel=huber --set semantic.detector=yolo"
  [kernel]="--set tracking.kernel=barron-fixed --set mapping.kernel=barron-adaptive --set semantic.detector=none"
  [full]="--set tracking.kernel=barron-fixed --set mapping.kernel=barron-adaptive --set semantic.detector=yolo")
features=${FEATURES:-1000}  # the sequence's ORB feature count (the kitchen's settings.yaml: 1000)
declare -A variant=(
  [base]=""
  [first+5]="--first 5"
  [first+10]="--first 10"
  [features-10%]="--set orb.n_features=$(( features * 9 / 10 ))"
  [features+10%]="--set orb.n_features=$(( features * 11 / 10 ))")
configs=(huber semantic kernel full)
variants=(base first+5 first+10 features-10% features+10%)

ate_cm() { python3 -c "import json,sys; m=json.load(open(sys.argv[1])); print('%.2f' % (100 * m['ate']['rmse']))" "$1"; }

total=$(( ${#configs[@]} * ${#variants[@]} )); n=0
for c in "${configs[@]}"; do
  for v in "${variants[@]}"; do
    n=$((n + 1)); dir="$out/$c/$v"; mkdir -p "$out/$c"
    if [ -n "${RESUME:-}" ] && [ -f "$dir/metrics.json" ]; then echo "[$n/$total] $c $v: done before" >&2; continue; fi
    echo "[$n/$total] $c $v" >&2
    # shellcheck disable=SC2086  # the option strings are word lists
    "$bin" run -d "$data" --out "$dir" -q ${config[$c]} ${variant[$v]} "$@" > "$dir.log" 2>&1 ||
      { echo "kitchen_spread: run $c $v failed, see $dir.log" >&2; exit 1; }
  done
done

{
  printf '| configuration |'; for v in "${variants[@]}"; do printf ' %s |' "$v"; done; printf ' spread (max - min) |\n'
  printf '|---|'; for _ in "${variants[@]}"; do printf -- '--:|'; done; printf -- '--:|\n'
  for c in "${configs[@]}"; do
    vals=(); for v in "${variants[@]}"; do vals+=("$(ate_cm "$out/$c/$v/metrics.json")"); done
    spread=$(printf '%s\n' "${vals[@]}" | sort -n | awk 'NR == 1 {lo = $1} {hi = $1} END {printf "%.2f", hi - lo}')
    printf '| %s |' "$c"; for x in "${vals[@]}"; do printf ' %s |' "$x"; done; printf ' %s |\n' "$spread"
  done
  echo
  echo "ATE rmse in cm, $data, deterministic, $(git describe --always --dirty 2>/dev/null || echo unknown)"
} | tee "$out/spread.md"
