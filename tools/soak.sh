#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Soak test: PAIRS frame pairs at 128×96 through `inertialnet predict`, its resident memory
# (VmRSS) and the 1-minute load average sampled every second, and the verdict: flat when every
# sample after the warm-up (the first WARMUP_PERCENT of the samples, default 20) and before the
# tear-down (the last TEARDOWN_SECONDS, default 3, when the exiting process frees its buffers)
# lies within ±5 % of their median.
#   bash tools/soak.sh [dis|flownet2|both] [PAIRS]        (defaults: both, 2000)
#   bash tools/soak.sh --analyse SAMPLES.csv NAME PAIRS   (the verdict of samples taken before)
# Before each soak a two-pair run of the same command fills the program and PoCL kernel caches
# (a first run on a machine compiles every kernel: over a minute for FlowNet2), so the soak
# measures the steady state; its time is reported as the warm-up.
# Not in CI: FlowNet2 at 128×96 takes about a second per pair on a 2-core PoCL machine. Under a
# heavy load do not run it at a low priority (nice 19 beside busy builds gets it a few per cent
# of a core).
# Samples go to <SOAK_DIR>/rss_<run>.csv (seconds,kB,load), the verdict to
# <SOAK_DIR>/summary_<run>.txt; SOAK_DIR defaults to build/soak.
set -euo pipefail
cd "$(dirname "$0")/.."
warmup="${WARMUP_PERCENT:-20}"
teardown="${TEARDOWN_SECONDS:-3}"

# The verdict line of a samples file (seconds,kB[,load]) of a run of `pairs` pairs: median RSS
# between warm-up and tear-down, the lowest and highest sample against it, the largest change between two
# consecutive samples (a step), pairs per second over the whole run (start-up included) and the
# load average while it ran.
analyse() {
  local samples="$1" name="$2" pairs="$3"
  local total first last
  total=$(wc -l <"$samples")
  [ "$total" -gt 0 ] || { echo "$name: no samples in $samples" >&2; return 1; }
  first=$((total * warmup / 100 + 1))
  last=$(($(tail -n 1 "$samples" | cut -d, -f1) - teardown))
  awk -F, -v name="$name" -v warmup="$warmup" -v first="$first" -v last="$last" -v teardown="$teardown" \
    -v pairs="$pairs" '
    function sort_numeric(a, n,   i, j, t) {  # insertion sort: a few thousand samples at most
      for (i = 2; i <= n; i++) { t = a[i]; for (j = i - 1; j >= 1 && a[j] > t; j--) a[j + 1] = a[j]; a[j + 1] = t }
    }
    {
      seconds = $1
      if ($2 > peak) peak = $2
      if (NF >= 3 && $3 != "") { load_sum += $3; load_n++; if ($3 > load_max) load_max = $3 }
      if (NR >= first && $1 <= last) {
        v[++n] = $2
        if (n > 1 && (d = $2 - previous) * (d < 0 ? -1 : 1) > step) step = d * (d < 0 ? -1 : 1)
        previous = $2
      }
    }
    END {
      if (n == 0) {
        printf "%s: %d pairs in %d s, %d samples: too short to judge (none between warm-up and tear-down)\n",
               name, pairs, seconds, NR
        exit
      }
      sort_numeric(v, n)
      median = v[int((n + 1) / 2)]
      low = (v[1] - median) / median * 100
      high = (v[n] - median) / median * 100
      format = "%s: %d pairs in %d s (%.2f pairs/s, start-up included), %s; "
      format = format "after the first %d %% of %d samples and before the last %d s: median %.1f MiB, "
      format = format "min %+.1f %%, max %+.1f %%, "
      format = format "largest step %.1f MiB; peak %.1f MiB: %s\n"
      rate = seconds > 0 ? pairs / seconds : 0
      load = load_n ? sprintf("load average %.1f (max %.1f)", load_sum / load_n, load_max) : "load not sampled"
      verdict = (low >= -5 && high <= 5) ? "flat (within 5 %)" : "NOT flat"
      printf format, name, pairs, seconds, rate, load, warmup, NR, teardown, median / 1024, low, high, step / 1024, peak / 1024, verdict
    }' "$samples"
}

if [ "${1:-}" = --analyse ]; then
  analyse "$2" "${3:-run}" "${4:-0}"
  exit
fi

which="${1:-both}"
pairs="${2:-2000}"
cli="${INERTIALNET_CLI:-$PWD/build/inertialnet}"
work="${SOAK_DIR:-$PWD/build/soak}"
mkdir -p "$work"
seq="$work/seq-$pairs"
[ -d "$seq" ] || "$cli" synth "$seq" --frames $((pairs + 1)) --size 128x96 --seed 11 >/dev/null

soak() {
  local name="$1"
  shift
  local samples="$work/rss_$name.csv" start=$SECONDS
  "$cli" predict "$seq" --max-pairs 2 -q -o "$work/warmup_$name.csv" "$@"
  echo "$name: warm-up run (2 pairs, fills the kernel caches): $((SECONDS - start)) s"
  : >"$samples"
  "$cli" predict "$seq" -o "$work/rates_$name.csv" "$@" 2>"$work/predict_$name.log" &
  local pid=$!
  start=$SECONDS
  while kill -0 "$pid" 2>/dev/null; do
    local rss load
    rss=$(awk '/^VmRSS:/ {print $2}' "/proc/$pid/status" 2>/dev/null || true)
    read -r load _ </proc/loadavg
    [ -n "$rss" ] && echo "$((SECONDS - start)),$rss,$load" >>"$samples"
    sleep 1
  done
  wait "$pid"
  analyse "$samples" "$name" "$pairs" | tee "$work/summary_$name.txt"
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
