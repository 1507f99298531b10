# SPDX-License-Identifier: Apache-2.0
"""Seconds per frame pair of the repository's PyTorch reference (tools/reference/flownet2.py), in
float32 with a given thread count, on the frames `inertialnet bench` uses, with the deterministic
synthetic weights. Correlation: `bmm` (correlation_bmm.py, default) or `shift` (the reference's).
Run by compare.py inside the reference's virtual environment; prints one JSON object.

    python torch_bench.py --model FlowNet2 --size 512x384 --threads 2 --pairs 3 [--torch-device cuda]
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(HERE), "reference"))

import numpy as np  # noqa: E402
import torch  # noqa: E402

import flownet2  # noqa: E402
import synthetic  # noqa: E402
from correlation_bmm import correlation_bmm  # noqa: E402


def frame_pixels(width: int, height: int, shift: int) -> np.ndarray:
    """tools/cli/command_bench.cpp's frames: a hash of 4x4 blocks per channel, 0..255."""
    c = np.arange(3, dtype=np.int64).reshape(3, 1, 1)
    y = np.arange(height, dtype=np.int64).reshape(1, height, 1)
    x = np.arange(width, dtype=np.int64).reshape(1, 1, width)
    h = ((x + shift) // 4 * 73856093) ^ (y // 4 * 19349663) ^ (c * 83492791)
    return ((h & 0xFFFFFFFF) % 256).astype(np.float32)


def check_correlation() -> float:
    """Largest |bmm - shift| on random features at FlowNetC's configuration (float64)."""
    g = torch.Generator().manual_seed(0)
    f1 = torch.randn(2, 16, 12, 20, generator=g, dtype=torch.float64)
    f2 = torch.randn(2, 16, 12, 20, generator=g, dtype=torch.float64)
    return float((correlation_bmm(f1, f2) - flownet2.correlation(f1, f2)).abs().max())


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", default="FlowNet2")
    parser.add_argument("--size", default="512x384", help="WIDTHxHEIGHT")
    parser.add_argument("--threads", type=int, default=os.cpu_count())
    parser.add_argument("--pairs", type=int, default=3)
    parser.add_argument("--correlation", choices=("bmm", "shift"), default="bmm")
    parser.add_argument("--torch-device", default="cpu", help="PyTorch's device: cpu, cuda, cuda:1 ...")
    parser.add_argument("--tf32", action="store_true",
                        help="let cuDNN and cuBLAS run float32 work on TF32 tensor cores (PyTorch's default for "
                             "convolutions; 10-bit mantissa). Without it both sides compute in float32.")
    args = parser.parse_args()
    width, height = (int(v) for v in args.size.lower().split("x"))

    torch.set_num_threads(args.threads)
    # PyTorch runs float32 convolutions on TF32 tensor cores by default on GPUs that have them;
    # ours are float32 throughout, so the comparison is float32 unless asked otherwise.
    torch.backends.cudnn.allow_tf32 = args.tf32
    torch.backends.cuda.matmul.allow_tf32 = args.tf32
    error = check_correlation()
    if error > 1e-12:
        print(f"correlation_bmm differs from the reference's correlation by {error}", file=sys.stderr)
        return 1
    if args.correlation == "bmm":
        flownet2.correlation = correlation_bmm  # FlowNetC looks the function up at call time

    model = flownet2.build(args.model)
    synthetic.fill_synthetic(model, 1)
    device = torch.device(args.torch_device)
    model = model.float().to(device)
    f1 = torch.from_numpy(frame_pixels(width, height, 0)).unsqueeze(0).to(device)
    f2 = torch.from_numpy(frame_pixels(width, height, 3)).unsqueeze(0).to(device)

    def finish() -> None:
        # CUDA runs asynchronously: a pair is done when its kernels are, not when the call returns.
        if device.type == "cuda":
            torch.cuda.synchronize(device)

    with torch.inference_mode():
        start = time.perf_counter()
        flownet2.run_any_size(model, f1, f2)  # warm-up: allocator, oneDNN primitives / cuDNN plans
        finish()
        warmup = time.perf_counter() - start
        times = []
        for _ in range(args.pairs):
            start = time.perf_counter()
            flownet2.run_any_size(model, f1, f2)
            finish()
            times.append(time.perf_counter() - start)
    print(json.dumps({
        "model": args.model, "width": width, "height": height, "threads": torch.get_num_threads(),
        "torch_device": str(device) + (f" ({torch.cuda.get_device_name(device)})" if device.type == "cuda" else ""),
        "correlation": args.correlation, "torch": torch.__version__, "pairs": args.pairs, "tf32": args.tf32,
        "warmup_seconds": warmup, "seconds": times, "seconds_per_pair": sum(times) / len(times),
    }))
    return 0


if __name__ == "__main__":
    sys.exit(main())
