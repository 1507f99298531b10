#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Seconds per frame pair, ours against PyTorch, interleaved in one run on one machine.

For each round and each model, runs `inertialnet bench --json` (our OpenCL network, its "flow"
stage: the same work as the PyTorch forward pass) and then torch_bench.py (the repository's PyTorch
reference in float32, correlation as one batched matrix product) with the same thread count, the
same frames, the same size and the same synthetic weights; prints the per-round figures, the
medians and the ratio ours / PyTorch. Needs no torch itself: torch runs in the reference's virtual
environment (see README.md here for how to create it).

    tools/compare/compare.py [--venv DIR] [--inertialnet build/inertialnet] \
        [--models FlowNet2,FlowNet2-C] [--size 512x384] [--threads 2] [--pairs 3] [--rounds 2] [--json] \
        [--device gpu --torch-device cuda [--tf32]] [--plan packed,winograd]

With several `--plan`s, each round runs ours once per plan before PyTorch, and each plan gets its
own row and ratio. Every round line carries the 1-minute load average read before it, and a
warning where a run's figures cannot be its plan's (no layer of its profile on that plan, or the
same figures as another plan's run of the round).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))


def run_json(command: list[str], env: dict) -> dict:
    done = subprocess.run(command, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if done.returncode != 0:
        sys.stderr.write(done.stderr)
        raise SystemExit(f"compare: {' '.join(command)} failed with exit code {done.returncode}")
    return json.loads(done.stdout)


def plan_check(plan: str, ours: dict, others: list) -> str:
    """A note for the round line when a run's figures cannot be that plan's: a plan named with
    --plan that no layer of the profiled pair ran on, or figures equal to another plan's run of
    the same round to the microsecond (two runs of different plans never give those)."""
    notes = []
    if plan and plan != "auto":
        backends = sorted({b for kind in ours.get("profile", {}).get("kinds", []) for b in kind.get("backends", []) if b})
        if backends and plan not in backends:
            notes.append(f"no layer ran on plan {plan} (the profile shows {', '.join(backends)})")
    figures = (ours["stages"]["flow"], ours["seconds_per_pair"])
    for other_plan, other in others:
        if (other["stages"]["flow"], other["seconds_per_pair"]) == figures:
            notes.append(f"figures identical to --plan {other_plan or 'default'}'s run: suspect")
    return "; ".join(notes)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--venv", default=os.environ.get("INERTIALNET_REFERENCE_VENV", os.path.join(ROOT, ".venv-reference")),
                        help="the reference's virtual environment (env INERTIALNET_REFERENCE_VENV; default .venv-reference)")
    parser.add_argument("--inertialnet", default=os.path.join(ROOT, "build", "inertialnet"), help="the CLI binary")
    parser.add_argument("--models", default="FlowNet2,FlowNet2-C")
    parser.add_argument("--size", default="512x384", help="WIDTHxHEIGHT")
    parser.add_argument("--threads", type=int, default=os.cpu_count(), help="threads for both (default: all cores)")
    parser.add_argument("--pairs", type=int, default=3, help="timed pairs per run")
    parser.add_argument("--rounds", type=int, default=2, help="alternations ours/PyTorch per model")
    parser.add_argument("--device", default="", help="--device for inertialnet (default: its default)")
    parser.add_argument("--torch-device", default="cpu",
                        help="PyTorch's device (cpu, cuda): compare an OpenCL GPU run with PyTorch on the same GPU")
    parser.add_argument("--tf32", action="store_true",
                        help="PyTorch's float32 convolutions on TF32 tensor cores (its GPU default); without it, float32 "
                             "on both sides")
    parser.add_argument("--correlation", choices=("bmm", "shift"), default="bmm", help="PyTorch's correlation")
    parser.add_argument("--plan", default="",
                        help="inertialnet's GEMM plan(s), comma-separated, each timed in every round (default: its default)")
    parser.add_argument("--json", action="store_true", help="print the results as JSON")
    args = parser.parse_args()
    plans = [p for p in args.plan.split(",") if p] or [""]

    python = os.path.join(args.venv, "bin", "python")
    if not os.access(python, os.X_OK):
        raise SystemExit(f"compare: no Python in {args.venv}; create the environment as tools/compare/README.md says")
    if not os.access(args.inertialnet, os.X_OK):
        raise SystemExit(f"compare: {args.inertialnet} is not built (cmake --build build --target inertialnet_cli)")

    # The same thread count on both sides: PoCL's pthread device and PyTorch's intra-op pool.
    env = dict(os.environ, POCL_MAX_PTHREAD_COUNT=str(args.threads), POCL_CPU_MAX_CU_NUM=str(args.threads),
               OMP_NUM_THREADS=str(args.threads))
    ours_command = [args.inertialnet, "bench", "--size", args.size, "--pairs", str(args.pairs), "--json"]
    if args.device:
        ours_command += ["--device", args.device]
    torch_command = [python, os.path.join(HERE, "torch_bench.py"), "--size", args.size, "--threads", str(args.threads),
                     "--pairs", str(args.pairs), "--correlation", args.correlation,
                     "--torch-device", args.torch_device] + (["--tf32"] if args.tf32 else [])

    models = [m for m in args.models.split(",") if m]
    runs = {(m, p): {"ours": [], "ours_total": [], "torch": [], "load": []} for m in models for p in plans}
    device = torch_version = torch_device = ""
    for round_index in range(args.rounds):
        for model in models:
            ours_runs = []
            for plan in plans:
                load = os.getloadavg()[0]
                ours = run_json(ours_command + ["--model", model] + (["--plan", plan] if plan else []), env)["results"][0]
                ours_runs.append((plan, load, ours, plan_check(plan, ours, [(p, o) for p, _, o, _ in ours_runs])))
            load = os.getloadavg()[0]
            torch_run = run_json(torch_command + ["--model", model], env)
            torch_version, torch_device = torch_run["torch"], torch_run["torch_device"]
            for plan, ours_load, ours, note in ours_runs:
                device = ours["device"]
                run = runs[(model, plan)]
                run["ours"].append(ours["stages"]["flow"])
                run["ours_total"].append(ours["seconds_per_pair"])
                run["torch"].append(torch_run["seconds_per_pair"])
                run["load"].append([ours_load, load])
                run.setdefault("notes", []).append(note)
                print(f"round {round_index + 1} {model}{' --plan ' + plan if plan else ''}: ours {ours['stages']['flow']:.3f} s/pair "
                      f"(with upload, head, download {ours['seconds_per_pair']:.3f}, load {ours_load:.1f}), "
                      f"PyTorch {torch_run['seconds_per_pair']:.3f} s/pair (load {load:.1f})"
                      + (f" WARNING: {note}" if note else ""), file=sys.stderr)

    summary = []
    for (model, plan), run in runs.items():
        ours = statistics.median(run["ours"])
        theirs = statistics.median(run["torch"])
        summary.append({"model": model, "plan": plan or "default", "size": args.size, "threads": args.threads,
                        "ours_seconds_per_pair": ours, "ours_total_seconds_per_pair": statistics.median(run["ours_total"]),
                        "torch_seconds_per_pair": theirs, "ratio": ours / theirs, "runs": run})
    if args.json:
        print(json.dumps({"device": device, "torch": torch_version, "torch_device": torch_device,
                          "correlation": args.correlation, "torch_tf32": args.tf32,
                          "results": summary}, indent=2))
        return 0
    precision = "float32 (PyTorch: TF32 allowed)" if args.tf32 else "float32"
    print(f"{args.size}, {args.threads} threads, {precision}; ours on {device}, PyTorch {torch_version} "
          f"on {torch_device} (correlation: {args.correlation}); medians of {args.rounds} interleaved rounds of {args.pairs} pairs")
    print(f"{'model':<14} {'plan':<9} {'ours s/pair':>12} {'PyTorch s/pair':>15} {'ours/PyTorch':>13}")
    for s in summary:
        print(f"{s['model']:<14} {s['plan']:<9} {s['ours_seconds_per_pair']:>12.3f} {s['torch_seconds_per_pair']:>15.3f} {s['ratio']:>13.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
