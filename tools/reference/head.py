# SPDX-License-Identifier: Apache-2.0
"""InertialNet rotation head (docs/model_spec.md, "InertialNet head").

flow [B, 2, H, W] (pixels, times flow_scale) -> conv1 kxk + ReLU -> max-pool -> conv2 kxk + ReLU
-> max-pool -> conv3 (1x1) + ReLU -> flatten (C, H, W order) -> dropout (training only) -> fc1 +
ReLU -> fc2 -> (wx, wy, wz) in rad/s. Convolutions use padding (k-1)/2 (k odd) so only the pools
change the size; pools use floor mode. State-dict names: head.conv1.weight ... head.fc2.bias.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass, fields

import torch
import torch.nn as nn
import torch.nn.functional as F


@dataclass
class HeadConfig:
    input_height: int = 480
    input_width: int = 752
    in_channels: int = 2
    conv1_channels: int = 16
    conv1_kernel: int = 3
    conv2_channels: int = 32
    conv2_kernel: int = 3
    conv3_channels: int = 8
    conv3_kernel: int = 1
    pool: int = 2
    fc1_units: int = 128
    outputs: int = 3
    dropout: float = 0.3
    flow_scale: float = 1.0

    def validate(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            if f.name in ("dropout", "flow_scale"):
                continue
            if not isinstance(v, int) or v <= 0:
                raise ValueError(f"head hyper-parameter {f.name} must be a positive integer, got {v!r}")
        for k in (self.conv1_kernel, self.conv2_kernel, self.conv3_kernel):
            if k % 2 == 0:
                raise ValueError(f"head convolution kernels must be odd (size-preserving), got {k}")
        if not 0.0 <= self.dropout < 1.0:
            raise ValueError(f"head dropout must be in [0, 1), got {self.dropout}")
        if self.pooled_height() < 1 or self.pooled_width() < 1:
            raise ValueError(f"head input {self.input_width}x{self.input_height} (WxH) is too small "
                             f"for two {self.pool}x{self.pool} poolings")

    def pooled_height(self) -> int:
        return (self.input_height // self.pool) // self.pool

    def pooled_width(self) -> int:
        return (self.input_width // self.pool) // self.pool

    def fc1_inputs(self) -> int:
        return self.conv3_channels * self.pooled_height() * self.pooled_width()

    def to_json(self) -> str:
        return json.dumps(asdict(self), sort_keys=True, separators=(",", ":"))

    @staticmethod
    def from_dict(d: dict) -> "HeadConfig":
        known = {f.name for f in fields(HeadConfig)}
        unknown = sorted(set(d) - known)
        if unknown:
            raise ValueError(f"unknown head hyper-parameters {unknown}; known: {sorted(known)}")
        cfg = HeadConfig(**d)
        cfg.validate()
        return cfg


class _HeadLayers(nn.Module):
    def __init__(self, cfg: HeadConfig):
        super().__init__()
        self.conv1 = nn.Conv2d(cfg.in_channels, cfg.conv1_channels, cfg.conv1_kernel, 1,
                               (cfg.conv1_kernel - 1) // 2)
        self.conv2 = nn.Conv2d(cfg.conv1_channels, cfg.conv2_channels, cfg.conv2_kernel, 1,
                               (cfg.conv2_kernel - 1) // 2)
        self.conv3 = nn.Conv2d(cfg.conv2_channels, cfg.conv3_channels, cfg.conv3_kernel, 1,
                               (cfg.conv3_kernel - 1) // 2)
        self.fc1 = nn.Linear(cfg.fc1_inputs(), cfg.fc1_units)
        self.fc2 = nn.Linear(cfg.fc1_units, cfg.outputs)


class InertialNetHead(nn.Module):
    def __init__(self, cfg: HeadConfig | None = None):
        super().__init__()
        self.cfg = cfg or HeadConfig()
        self.cfg.validate()
        self.head = _HeadLayers(self.cfg)

    def forward(self, flow: torch.Tensor) -> torch.Tensor:
        cfg, h = self.cfg, self.head
        if tuple(flow.shape[1:]) != (cfg.in_channels, cfg.input_height, cfg.input_width):
            raise ValueError(f"head expects [B, {cfg.in_channels}, {cfg.input_height}, "
                             f"{cfg.input_width}], got {list(flow.shape)}")
        x = flow * cfg.flow_scale if cfg.flow_scale != 1.0 else flow
        x = F.relu(F.conv2d(x, h.conv1.weight, h.conv1.bias, 1, h.conv1.padding))
        x = F.max_pool2d(x, cfg.pool, cfg.pool)
        x = F.relu(F.conv2d(x, h.conv2.weight, h.conv2.bias, 1, h.conv2.padding))
        x = F.max_pool2d(x, cfg.pool, cfg.pool)
        x = F.relu(F.conv2d(x, h.conv3.weight, h.conv3.bias, 1, h.conv3.padding))
        x = torch.flatten(x, 1)
        x = F.dropout(x, cfg.dropout, self.training)
        x = F.relu(F.linear(x, h.fc1.weight, h.fc1.bias))
        return F.linear(x, h.fc2.weight, h.fc2.bias)


def expected_shapes(cfg: HeadConfig) -> dict:
    with torch.device("meta"):
        model = InertialNetHead(cfg)
    return {k: tuple(v.shape) for k, v in model.state_dict().items()}
