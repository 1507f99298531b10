# SPDX-License-Identifier: Apache-2.0
"""Deterministic synthetic weights (docs/model_spec.md, "Deterministic synthetic weights").

The C++ library implements the same generator; both must agree bit for bit, which
tests/data/fixtures/synthetic_weights.json checks. The arithmetic is spelled out here in the
order the C++ side must use it:

    key    = fnv1a64(utf8(name)) XOR (seed * 0x9E3779B97F4A7C15 mod 2^64)
    z_i    = splitmix64(key + i mod 2^64)                      for i = 0 .. n-1
    u_i    = (z_i >> 40) / 2^23 - 1                            (exact in double, in [-1, 1))
    weight = float32((u_i * sqrt(6.0 / fan_in)) * gain)       (double, left to right, one rounding)
    bias   = float32(0.01 * u_i)

fan_in = ci*k*k for Conv2d ([co, ci, k, k]) and Linear ([out, in], k = 1); ci*16/4 = 4*ci for the
stride-2, 4x4 ConvTranspose2d ([ci, co, 4, 4]). gain = 0.7 for the flow-predicting layers
(a dotted name component starting with "predict_flow" or "upsampled_flow"), else 1. The first
choice, 0.1, made the whole FlowNet2 output about 0.1 px of flow at 128x96, too little to exercise
warps and image borders; with 0.7 the fixture pair gets a mean |flow| of about 6 px and a maximum
of about 19 px.
"""

from __future__ import annotations

import math

import numpy as np

MASK64 = (1 << 64) - 1
GOLDEN = 0x9E3779B97F4A7C15
FNV_OFFSET = 0xCBF29CE484222325
FNV_PRIME = 0x100000001B3

KINDS = ("conv", "deconv", "linear")
FLOW_GAIN = 0.7


def fnv1a64(name: str) -> int:
    h = FNV_OFFSET
    for byte in name.encode("utf-8"):
        h ^= byte
        h = (h * FNV_PRIME) & MASK64
    return h


def stream_key(name: str, seed: int) -> int:
    return fnv1a64(name) ^ (((seed & MASK64) * GOLDEN) & MASK64)


def splitmix64_array(start: int, n: int) -> np.ndarray:
    """splitmix64(start + i) for i in 0..n-1, as uint64 (numpy arrays wrap modulo 2^64)."""
    z = np.arange(n, dtype=np.uint64)
    z += np.uint64(start & MASK64)
    z += np.uint64(GOLDEN)
    z ^= z >> np.uint64(30)
    z *= np.uint64(0xBF58476D1CE4E5B9)
    z ^= z >> np.uint64(27)
    z *= np.uint64(0x94D049BB133111EB)
    z ^= z >> np.uint64(31)
    return z


def uniform(name: str, n: int, seed: int) -> np.ndarray:
    """The u_i in [-1, 1) of tensor `name`, float64 (exact)."""
    z = splitmix64_array(stream_key(name, seed), n)
    return (z >> np.uint64(40)).astype(np.float64) * (1.0 / 8388608.0) - 1.0


def gain_for(name: str) -> float:
    for part in name.split("."):
        if part.startswith("predict_flow") or part.startswith("upsampled_flow"):
            return FLOW_GAIN
    return 1.0


def fan_in_for(kind: str, weight_shape) -> int:
    shape = tuple(int(s) for s in weight_shape)
    if kind == "conv":
        return shape[1] * shape[2] * shape[3]
    if kind == "linear":
        return shape[1]
    if kind == "deconv":
        # ConvTranspose2d [ci, co, k, k] with stride 2: each output sees ci*k*k/stride^2 inputs.
        return shape[0] * shape[2] * shape[3] // 4
    raise ValueError(f"unknown layer kind {kind!r}; expected one of {KINDS}")


def is_bias(name: str) -> bool:
    return name.endswith(".bias")


def synthetic_tensor(name: str, shape, kind: str, seed: int, weight_shape=None) -> np.ndarray:
    """One tensor as float32. For a bias, `weight_shape` is not needed (the bias ignores fan_in)."""
    shape = tuple(int(s) for s in shape)
    n = int(np.prod(shape, dtype=np.int64)) if shape else 1
    u = uniform(name, n, seed)
    if is_bias(name):
        values = 0.01 * u
    else:
        scale = math.sqrt(6.0 / fan_in_for(kind, shape))
        values = (u * scale) * gain_for(name)
    return values.astype(np.float32).reshape(shape)


def describe(name: str, shape, kind: str, weight_shape=None) -> dict:
    """fan_in / gain as used for `name` (bias entries report the layer's fan_in for information)."""
    ws = shape if not is_bias(name) else weight_shape
    info = {"kind": kind, "param": "bias" if is_bias(name) else "weight"}
    if is_bias(name):
        info["fan_in"] = None if ws is None else fan_in_for(kind, ws)
        info["gain"] = None
        info["formula"] = "float32(0.01*u)"
    else:
        info["fan_in"] = fan_in_for(kind, ws)
        info["gain"] = gain_for(name)
        info["formula"] = "float32((u*sqrt(6/fan_in))*gain)"
    return info


def layer_kind(module) -> str:
    import torch.nn as nn  # local: the generator itself needs only numpy

    if isinstance(module, nn.ConvTranspose2d):
        return "deconv"
    if isinstance(module, nn.Conv2d):
        return "conv"
    if isinstance(module, nn.Linear):
        return "linear"
    raise TypeError(f"no synthetic rule for {type(module).__name__}")


def parameter_kinds(model) -> dict:
    """{state_dict name: (kind, weight shape)} for every parameter of `model`."""
    import torch.nn as nn

    kinds = {}
    for mod_name, module in model.named_modules():
        if not isinstance(module, (nn.Conv2d, nn.ConvTranspose2d, nn.Linear)):
            continue
        kind = layer_kind(module)
        for pname, p in module.named_parameters(recurse=False):
            full = f"{mod_name}.{pname}" if mod_name else pname
            kinds[full] = (kind, tuple(module.weight.shape))
    return kinds


def fill_synthetic(model, seed: int, prefix: str = "") -> None:
    """Overwrites every parameter of `model` with its synthetic value (in the parameter's dtype).
    The generator sees `prefix + name`, e.g. prefix "flownetfusion." gives a standalone
    FlowNetFusion the weights it has inside FlowNet2."""
    import torch

    kinds = parameter_kinds(model)
    params = dict(model.named_parameters())
    missing = sorted(set(params) - set(kinds))
    if missing:
        raise TypeError(f"parameters without a synthetic rule: {missing}")
    with torch.no_grad():
        for name, p in params.items():
            kind, wshape = kinds[name]
            values = synthetic_tensor(prefix + name, p.shape, kind, seed, wshape)
            p.copy_(torch.from_numpy(values).to(p.dtype))
