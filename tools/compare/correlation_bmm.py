# SPDX-License-Identifier: Apache-2.0
"""FlowNetC's correlation as one batched matrix product, PyTorch at its best.

The reference (tools/reference/flownet2.py) writes the correlation as 441 shifted elementwise
products, which is clear but memory-bound. Here every displacement row dy is a window of the padded
second feature map, and for each (dy, y) one product f1[y]^T (W x C) @ f2p[y + dy] (C x W+2p)
gives the dot products of every x with every x' of that row; the 21 horizontal displacements are
diagonals of it (x' = x + j*stride2), read without a copy through as_strided. The product does
(W+2p)/D times the multiply-adds the correlation needs (about 5x at FlowNetC's 64-pixel-wide
features), but at GEMM speed, which is far faster than the memory-bound form.
"""

from __future__ import annotations

import torch
import torch.nn.functional as F


def correlation_bmm(f1: torch.Tensor, f2: torch.Tensor, max_displacement: int = 20,
                    stride2: int = 2) -> torch.Tensor:
    """Same contract and channel order as flownet2.correlation: channel dy_idx * D + dx_idx."""
    b, c, h, w = f1.shape
    r = max_displacement // stride2
    d = 2 * r + 1
    p = max_displacement
    wp = w + 2 * p
    f2p = F.pad(f2, (p, p, p, p))                                   # [B, C, H+2p, W+2p]
    rows = f2p.unfold(2, h, stride2)                                # [B, C, D, W+2p, H]: row windows per dy
    rows = rows.permute(0, 2, 4, 1, 3)                              # [B, D, H, C, W+2p]
    a = f1.permute(0, 2, 3, 1).unsqueeze(1)                         # [B, 1, H, W, C]
    prod = torch.matmul(a, rows).contiguous()                       # [B, D, H, W, W+2p]
    # out[b, dy, y, x, j] = prod[b, dy, y, x, x + j*stride2]: a diagonal walk through the last two axes.
    s = prod.stride()
    diag = prod.as_strided((b, d, h, w, d), (s[0], s[1], s[2], s[3] + s[4], stride2 * s[4]))
    return diag.permute(0, 1, 4, 2, 3).reshape(b, d * d, h, w) / c
