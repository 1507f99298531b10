# SPDX-License-Identifier: Apache-2.0
"""Writes tests/data/fixtures/head_gradients_14x10.safetensors: a small InertialNet head's
training step computed by torch autograd in float64, to check the library's backward ops
(include/inertialnet/models/head_backprop.hpp) against an independent implementation.

The head is the one of docs/model_spec.md with small widths (conv 4, 5, 3 channels, fc1 7 units)
on a 14×10 flow, batch 2, flow_scale 0.5 and dropout 0.3 with the library's counter-based mask
(include/inertialnet/ops/dropout.hpp), so every layer kind and its gradient is exercised. The
parameters, flow and target are random float32 values (numpy, fixed seed); the file holds them,
the loss and the gradient of every parameter ("grad." + its name), rounded to float32.

Usage: python tools/reference/make_head_gradient_fixture.py [--out DIR]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys

import numpy as np
import torch
import torch.nn.functional as F

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import synthetic as sy  # noqa: E402
from make_fixtures import write_safetensors  # noqa: E402  (byte-reproducible files)

REPO = os.path.dirname(os.path.dirname(HERE))
DEFAULT_OUT = os.path.join(REPO, "tests", "data", "fixtures")
NAME = "head_gradients_14x10.safetensors"

CONFIG = {
    "conv1_channels": 4, "conv1_kernel": 3, "conv2_channels": 5, "conv2_kernel": 3,
    "conv3_channels": 3, "conv3_kernel": 1, "dropout": 0.3, "flow_scale": 0.5, "fc1_units": 7,
    "in_channels": 2, "input_height": 10, "input_width": 14, "outputs": 3, "pool": 2,
}
BATCH = 2
DROPOUT_SEED = 7


def dropout_mask(seed: int, p: float, count: int) -> np.ndarray:
    """keep = (splitmix64(splitmix64(seed) + i) >> 40) >= ceil(p · 2^24), p as float32."""
    key = int(sy.splitmix64_array(seed, 1)[0])
    bits = sy.splitmix64_array(key, count) >> np.uint64(40)
    threshold = math.ceil(float(np.float32(p)) * 16777216.0)
    return bits >= np.uint64(threshold)


def shapes(c: dict) -> dict:
    h2 = (c["input_height"] // c["pool"]) // c["pool"]
    w2 = (c["input_width"] // c["pool"]) // c["pool"]
    k1, k2, k3 = c["conv1_kernel"], c["conv2_kernel"], c["conv3_kernel"]
    return {
        "head.conv1.weight": (c["conv1_channels"], c["in_channels"], k1, k1),
        "head.conv1.bias": (c["conv1_channels"],),
        "head.conv2.weight": (c["conv2_channels"], c["conv1_channels"], k2, k2),
        "head.conv2.bias": (c["conv2_channels"],),
        "head.conv3.weight": (c["conv3_channels"], c["conv2_channels"], k3, k3),
        "head.conv3.bias": (c["conv3_channels"],),
        "head.fc1.weight": (c["fc1_units"], c["conv3_channels"] * h2 * w2),
        "head.fc1.bias": (c["fc1_units"],),
        "head.fc2.weight": (c["outputs"], c["fc1_units"]),
        "head.fc2.bias": (c["outputs"],),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=DEFAULT_OUT)
    args = parser.parse_args()
    c = CONFIG
    rng = np.random.default_rng(20261123)
    tensors = {name: rng.uniform(-0.5, 0.5, shape).astype(np.float32) for name, shape in shapes(c).items()}
    flow = rng.uniform(-3.0, 3.0, (BATCH, c["in_channels"], c["input_height"], c["input_width"])).astype(np.float32)
    target = rng.uniform(-1.0, 1.0, (BATCH, c["outputs"])).astype(np.float32)

    params = {k: torch.tensor(v, dtype=torch.float64, requires_grad=True) for k, v in tensors.items()}
    x = torch.tensor(flow, dtype=torch.float64) * c["flow_scale"]
    pad = lambda k: (k - 1) // 2  # noqa: E731
    x = F.relu(F.conv2d(x, params["head.conv1.weight"], params["head.conv1.bias"], padding=pad(c["conv1_kernel"])))
    x = F.max_pool2d(x, c["pool"], c["pool"])
    x = F.relu(F.conv2d(x, params["head.conv2.weight"], params["head.conv2.bias"], padding=pad(c["conv2_kernel"])))
    x = F.max_pool2d(x, c["pool"], c["pool"])
    x = F.relu(F.conv2d(x, params["head.conv3.weight"], params["head.conv3.bias"], padding=pad(c["conv3_kernel"])))
    x = torch.flatten(x, 1)
    keep = torch.tensor(dropout_mask(DROPOUT_SEED, c["dropout"], x.numel()).reshape(x.shape))
    scale = float(np.float32(1.0 / (1.0 - float(np.float32(c["dropout"])))))
    x = torch.where(keep, x * scale, torch.zeros_like(x))
    x = F.relu(F.linear(x, params["head.fc1.weight"], params["head.fc1.bias"]))
    omega = F.linear(x, params["head.fc2.weight"], params["head.fc2.bias"])
    loss = F.mse_loss(omega, torch.tensor(target, dtype=torch.float64))
    loss.backward()

    out = dict(tensors)
    out["flow"] = flow
    out["target"] = target
    out["loss"] = np.array([loss.item()], dtype=np.float32)
    for name, p in params.items():
        out["grad." + name] = p.grad.numpy().astype(np.float32)
    metadata = {"inertialnet.model": "InertialNetHead",
                "inertialnet.head": json.dumps(c, sort_keys=True, separators=(",", ":")),
                "fixture.dropout_seed": str(DROPOUT_SEED), "fixture.torch": torch.__version__.split("+")[0],
                "fixture.computed_in": "float64", "fixture.generator": "tools/reference/make_head_gradient_fixture.py"}
    os.makedirs(args.out, exist_ok=True)
    path = os.path.join(args.out, NAME)
    write_safetensors(path, {k: np.ascontiguousarray(v, dtype=np.float32) for k, v in out.items()}, metadata)
    print(f"wrote {path} ({os.path.getsize(path)} bytes), loss {loss.item():.6g}")


if __name__ == "__main__":
    main()
