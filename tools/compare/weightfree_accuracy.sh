#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The weight-free path's accuracy under the synthetic conditions of docs/real_cameras.md ("DIS or
# Lucas–Kanade"): per condition, `inertialnet synth` (40 frames), `inertialnet predict` with each
# flow method in turn and `inertialnet eval`; prints the per-axis RMSE against gyro − bias
# (deg/s) and the mean error. Rates do not depend on the machine's load, so this can run anywhere.
#
#   tools/compare/weightfree_accuracy.sh [BUILD_DIR] [METHODS...]
#   tools/compare/weightfree_accuracy.sh build default dis lk
#
# METHODS: dis, lk, or `default` (no --flow). Sequences are kept in $WORK (default: a temporary
# folder, removed at the end); CONDITIONS (space-separated names from the list below) picks some.
# c752rsnr_*: the same rolling-shutter sequences as c752rs_*, predicted WITHOUT --readout-time (a
# phone recording as users make it: the readout is not known), issue 24.
set -euo pipefail
build=${1:-build}
shift || true
methods=("$@")
[[ ${#methods[@]} -gt 0 ]] || methods=(default dis lk)
cli="$build/inertialnet"
[[ -x $cli ]] || { echo "inertialnet: $cli not found; build the inertialnet_cli target first" >&2; exit 2; }
work=${WORK:-$(mktemp -d)}
[[ -n ${WORK:-} ]] || trap 'rm -rf "$work"' EXIT

# name | synth options | predict options
conditions=(
  "c752rs_s3|--motion close --readout-time 0.03 --exposure-time 0.01 --seed 3|--readout-time 0.03"
  "c752rs_s4|--motion close --readout-time 0.03 --exposure-time 0.01 --seed 4|--readout-time 0.03"
  "c752rs_s5|--motion close --readout-time 0.03 --exposure-time 0.01 --seed 5|--readout-time 0.03"
  "c752rsnr_s3|--motion close --readout-time 0.03 --exposure-time 0.01 --seed 3|"
  "c752rsnr_s4|--motion close --readout-time 0.03 --exposure-time 0.01 --seed 4|"
  "c752rsnr_s5|--motion close --readout-time 0.03 --exposure-time 0.01 --seed 5|"
  "rot376|--size 376x240 --seed 3|"
  "gen376|--size 376x240 --motion general --seed 3|"
  "cblur376|--size 376x240 --motion close --exposure-time 0.01 --seed 3|"
  "crs376|--size 376x240 --motion close --readout-time 0.03 --exposure-time 0.01 --seed 3|--readout-time 0.03"
  "expo376|--size 376x240 --motion general --exposure-variation 0.3 --seed 3|"
  "lowtex376|--size 376x240 --motion general --texture-contrast 0.1 --seed 3|"
  "cblur752|--motion close --exposure-time 0.01 --seed 3|"
  "gen752|--motion general --seed 3|"
)
wanted=${CONDITIONS:-}

printf '%-10s %-8s %-20s %-22s\n' condition method "RMSE x y z" "mean error x y z"
for c in "${conditions[@]}"; do
  IFS='|' read -r name synth predict <<<"$c"
  [[ -z $wanted || " $wanted " == *" $name "* ]] || continue
  seq="$work/$name"
  # shellcheck disable=SC2086
  [[ -d $seq/mav0 ]] || "$cli" synth -q "$seq" --frames 40 $synth >/dev/null
  for m in "${methods[@]}"; do
    flow=()
    [[ $m == default ]] || flow=(--flow "$m")
    rates="$work/$name.$m.csv"
    rm -f "$rates" "$rates.json"
    # shellcheck disable=SC2086
    "$cli" predict -q "$seq" "${flow[@]}" $predict -o "$rates" >/dev/null
    report=$("$cli" eval -q "$rates" "$seq" 2>/dev/null)
    rmse=$(awk '/gyro - bias$/ {printf "%s %s %s", $(NF-5), $(NF-4), $(NF-3)}' <<<"$report")
    mean=$(sed -n 's/^mean error (\([^)]*\)) deg\/s.*/\1/p' <<<"$report" | tr -d ',')
    printf '%-10s %-8s %-20s %-22s\n' "$name" "$m" "$rmse" "$mean"
  done
done
