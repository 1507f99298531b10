#!/usr/bin/env bash
# Soak test: PAIRS frame pairs at 128×96 through `inertialnet predict`, its resident memory
# (VmRSS) sampled every second, and the verdict: flat when every sample after the warm-up (the
# first WARMUP_PERCENT of the samples, default 20) lies within ±5 % of their median.
#   bash tools/soak.sh [dis|flownet2|both] [PAIRS]        (defaults: both, 2000)
# Not in CI: FlowNet2 at 128×96 takes about a second per pair on a 2-core PoCL machine.
# Samples go to <SOAK_DIR>/rss_<run>.csv (seconds,kB); SOAK_DIR defaults to build/soak.
set -euo pipefail
cd "$(dirname "$0")/.."
which="${1:-both}"
pairs="${2:-2000}"
cli="${INERTIALNET_CLI:-$PWD/build/inertialnet}"
work="${SOAK_DIR:-$PWD/build/soak}"
warmup="${WARMUP_PERCENT:-20}"
mkdir -p "$work"
seq="$work/seq-$pairs"
[ -d "$seq" ] || "$cli" synth "$seq" --frames $((pairs + 1)) --size 128x96 --seed 11 >/dev/null

soak() {
  local name="$1"
  shift
  local samples="$work/rss_$name.csv"
  : >"$samples"
  "$cli" predict "$seq" -o "$work/rates_$name.csv" "$@" 2>"$work/predict_$name.log" &
  local pid=$! start=$SECONDS
  while kill -0 "$pid" 2>/dev/null; do
    local rss
    rss=$(awk '/^VmRSS:/ {print $2}' "/proc/$pid/status" 2>/dev/null || true)
    [ -n "$rss" ] && echo "$((SECONDS - start)),$rss" >>"$samples"
    sleep 1
  done
  wait "$pid"
  local total first peak
  total=$(wc -l <"$samples")
  first=$((total * warmup / 100 + 1))
  peak=$(cut -d, -f2 "$samples" | sort -n | tail -1)
  tail -n +"$first" "$samples" | cut -d, -f2 | sort -n | awk -v name="$name" -v warmup="$warmup" \
    -v seconds=$((SECONDS - start)) -v total="$total" -v peak="$peak" '
    { v[NR] = $1 }
    END {
      median = v[int((NR + 1) / 2)]
      low = (v[1] - median) / median * 100
      high = (v[NR] - median) / median * 100
      printf "%-9s %d s, %d samples; after the first %d %%: median %.1f MB, min %+.1f %%, max %+.1f %%; peak %.1f MB: %s\n",
             name, seconds, total, warmup, median / 1024, low, high, peak / 1024,
             (low >= -5 && high <= 5) ? "flat (within 5 %)" : "NOT flat"
    }'
}

if [ "$which" = dis ] || [ "$which" = both ]; then
  soak dis --flow dis --head geometric
fi
if [ "$which" = flownet2 ] || [ "$which" = both ]; then
  [ -f "$work/flownet2.safetensors" ] || "$cli" weights --synthetic FlowNet2 -o "$work/flownet2.safetensors" >/dev/null
  [ -f "$work/head.safetensors" ] ||
    "$cli" weights --synthetic InertialNetHead --size 128x96 -o "$work/head.safetensors" >/dev/null
  soak flownet2 -w "$work/flownet2.safetensors" -w "$work/head.safetensors"
fi
