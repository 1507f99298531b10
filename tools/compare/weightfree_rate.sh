#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The weight-free path's rate at EuRoC's 752×480 (issue 24): `inertialnet predict SEQ --stats`
# on a synthetic sequence (`synth --motion general --frames 60 --seed 3`, 59 pairs), each flow
# method in turn, ROUNDS times interleaved (A, B, A, B: load that drifts hits both alike). Per run
# it prints the 1-minute load average before it, pairs/s, the flow and geometric-head stages'
# seconds per pair (from --stats) and the process's CPU time (user + sys) per pair.
#
#   tools/compare/weightfree_rate.sh [BUILD_DIR] [ROUNDS] [METHODS...]
#   tools/compare/weightfree_rate.sh build 3 default dis lk
#
# METHODS: flow methods for --flow (dis, lk), or `default` (no --flow: what predict picks without
# weights). The sequence is written once into $WORK (default: a temporary folder, removed at the
# end). Run it on a quiet machine for absolute figures; under load compare the ratios only.
set -euo pipefail
build=${1:-build}
rounds=${2:-3}
shift $(( $# > 2 ? 2 : $# )) || true
methods=("$@")
[[ ${#methods[@]} -gt 0 ]] || methods=(default dis lk)
cli="$build/inertialnet"
[[ -x $cli ]] || { echo "inertialnet: $cli not found; build the inertialnet_cli target first" >&2; exit 2; }
work=${WORK:-$(mktemp -d)}
[[ -n ${WORK:-} ]] || trap 'rm -rf "$work"' EXIT
seq="$work/general752"
[[ -d $seq/mav0 ]] || "$cli" synth -q "$seq" --motion general --frames 60 --seed 3 --size 752x480 >/dev/null

printf '%-8s %5s %6s %9s %12s %12s %14s\n' method round load pairs/s flow_s/pair head_s/pair cpu_s/pair
for ((r = 1; r <= rounds; ++r)); do
  for m in "${methods[@]}"; do
    flow=()
    [[ $m == default ]] || flow=(--flow "$m")
    load=$(cut -d' ' -f1 /proc/loadavg)
    out="$work/stats.txt"
    # bash's `times` would include the synth; read the child's CPU time from /usr/bin/time's format.
    /usr/bin/time -f '%U %S' -o "$work/cpu.txt" "$cli" predict -q "$seq" "${flow[@]}" --stats -o "$work/rates.$m.$r.csv" >"$out" 2>&1
    pairs=$(awk '/^pairs:/ {print $2}' "$out")
    rate=$(awk '/^pairs:/ {print $(NF-1)}' "$out")
    flow_s=$(awk '/^flow:/ {print $(NF-3)}' "$out")
    head_s=$(awk '/^geometric_head:/ {print $(NF-3)}' "$out")
    cpu=$(awk -v n="$pairs" '{printf "%.4f", ($1 + $2) / n}' "$work/cpu.txt")
    printf '%-8s %5d %6s %9.2f %12s %12s %14s\n' "$m" "$r" "$load" "$rate" "$flow_s" "$head_s" "$cpu"
  done
done
