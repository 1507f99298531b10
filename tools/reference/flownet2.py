# SPDX-License-Identifier: Apache-2.0
"""Independent PyTorch reference of the FlowNet2 family, written from docs/model_spec.md.

Only torch built-ins are used (F.conv2d, F.conv_transpose2d, F.leaky_relu, F.interpolate, gather,
pad/shift). Parameter names equal flownet2-pytorch's state_dict names so published checkpoints
load one-to-one; every forward pass returns a dict so that intermediates can be inspected.

Frames enter as two [B, 3, H, W] RGB tensors with values in [0, 255]. The networks themselves
need H and W to be multiples of 64; run_any_size() implements the spec's resize rule for others.
The code is dtype-agnostic (the fixtures are computed in float64 and stored as float32).
"""

from __future__ import annotations

import math

import torch
import torch.nn as nn
import torch.nn.functional as F

DIV_FLOW = 20.0
RGB_MAX = 255.0
LEAK = 0.1


# --------------------------------------------------------------------------- layers and ops --

def _conv_layer(ci: int, co: int, k: int = 3, s: int = 1) -> nn.Sequential:
    # A Sequential so the state_dict names read "<layer>.0.weight" as in flownet2-pytorch.
    return nn.Sequential(nn.Conv2d(ci, co, k, s, (k - 1) // 2, bias=True))


def _deconv_layer(ci: int, co: int) -> nn.Sequential:
    return nn.Sequential(nn.ConvTranspose2d(ci, co, 4, 2, 1, bias=True))


def _pred_layer(ci: int) -> nn.Conv2d:
    return nn.Conv2d(ci, 2, 3, 1, 1, bias=True)


def _up_layer(bias: bool) -> nn.ConvTranspose2d:
    return nn.ConvTranspose2d(2, 2, 4, 2, 1, bias=bias)


def conv2d(layer: nn.Module, x: torch.Tensor, act: bool) -> torch.Tensor:
    m = layer[0] if isinstance(layer, nn.Sequential) else layer
    y = F.conv2d(x, m.weight, m.bias, m.stride, m.padding)
    return F.leaky_relu(y, LEAK) if act else y


def deconv2d(layer: nn.Module, x: torch.Tensor, act: bool) -> torch.Tensor:
    m = layer[0] if isinstance(layer, nn.Sequential) else layer
    y = F.conv_transpose2d(x, m.weight, m.bias, m.stride, m.padding)
    return F.leaky_relu(y, LEAK) if act else y


def correlation(f1: torch.Tensor, f2: torch.Tensor, max_displacement: int = 20,
                stride2: int = 2) -> torch.Tensor:
    """Correlation with kernel 1, stride1 1, pad = max_displacement (FlowNetC's configuration).

    Channel (dy_idx * D + dx_idx) holds sum_c f1[c, y, x] * f2[c, y + dy, x + dx] / C with
    dy, dx = (idx - r) * stride2, r = max_displacement // stride2, D = 2r + 1; f2 reads zeros
    outside the image.
    """
    b, c, h, w = f1.shape
    r = max_displacement // stride2
    p = max_displacement
    f2p = F.pad(f2, (p, p, p, p))
    out = []
    for dy_idx in range(2 * r + 1):
        dy = (dy_idx - r) * stride2
        for dx_idx in range(2 * r + 1):
            dx = (dx_idx - r) * stride2
            shifted = f2p[:, :, p + dy:p + dy + h, p + dx:p + dx + w]
            out.append((f1 * shifted).sum(dim=1))
    return torch.stack(out, dim=1) / c


def warp(img: torch.Tensor, flow: torch.Tensor) -> torch.Tensor:
    """Resample2d (kernel 1): bilinear sample of img at (x + u, y + v), border replicated by
    clamping the four corner indices (the weights use the unclamped fractional parts)."""
    b, c, h, w = img.shape
    xs = torch.arange(w, dtype=img.dtype, device=img.device).view(1, 1, w)
    ys = torch.arange(h, dtype=img.dtype, device=img.device).view(1, h, 1)
    xf = xs + flow[:, 0]
    yf = ys + flow[:, 1]
    x0 = torch.floor(xf)
    y0 = torch.floor(yf)
    alpha = (xf - x0).unsqueeze(1)
    beta = (yf - y0).unsqueeze(1)
    xl = x0.clamp(0, w - 1).long()
    xr = (x0 + 1).clamp(0, w - 1).long()
    yt = y0.clamp(0, h - 1).long()
    yb = (y0 + 1).clamp(0, h - 1).long()
    flat = img.reshape(b, c, h * w)

    def tap(yi, xi):
        idx = (yi * w + xi).reshape(b, 1, h * w).expand(b, c, h * w)
        return flat.gather(2, idx).reshape(b, c, h, w)

    return ((1 - alpha) * (1 - beta) * tap(yt, xl) + alpha * (1 - beta) * tap(yt, xr)
            + (1 - alpha) * beta * tap(yb, xl) + alpha * beta * tap(yb, xr))


def channelnorm(x: torch.Tensor) -> torch.Tensor:
    return torch.sqrt((x * x).sum(dim=1, keepdim=True))


def upsample_bilinear(x: torch.Tensor, factor: int = 4) -> torch.Tensor:
    h, w = x.shape[-2:]
    return F.interpolate(x, size=(h * factor, w * factor), mode="bilinear", align_corners=False)


def upsample_nearest(x: torch.Tensor, factor: int = 4) -> torch.Tensor:
    h, w = x.shape[-2:]
    return F.interpolate(x, size=(h * factor, w * factor), mode="nearest")


def resize_bilinear(x: torch.Tensor, h: int, w: int) -> torch.Tensor:
    """Half-pixel bilinear resize without antialiasing (src = (dst + 0.5) * in/out - 0.5,
    negative src clamped to 0, upper neighbour clamped to the last row/column)."""
    if tuple(x.shape[-2:]) == (h, w):
        return x
    return F.interpolate(x, size=(h, w), mode="bilinear", align_corners=False, antialias=False)


def normalise_frames(frame1: torch.Tensor, frame2: torch.Tensor) -> torch.Tensor:
    """docs/model_spec.md step 1: subtract the per-(batch, channel) mean over both frames, divide by 255,
    and concatenate to 6 channels."""
    both = torch.stack((frame1, frame2), dim=2)  # [B, 3, 2, H, W]
    mean = both.reshape(both.shape[0], both.shape[1], -1).mean(dim=-1)
    mean = mean.view(mean.shape[0], mean.shape[1], 1, 1)
    return torch.cat(((frame1 - mean) / RGB_MAX, (frame2 - mean) / RGB_MAX), dim=1)


def check_size(h: int, w: int) -> None:
    if h % 64 or w % 64 or h <= 0 or w <= 0:
        raise ValueError(f"the FlowNet2 networks need H and W multiples of 64, got {h}x{w} (HxW); "
                         "use run_any_size()")


# ------------------------------------------------------------------------------ sub-networks --

class _Decoder(nn.Module):
    """Layers of the FlowNetC/S decoder (concat5/4/3/2 of 1026/770/386/194 channels)."""

    def _make_decoder(self, up_bias: bool) -> None:
        self.deconv5 = _deconv_layer(1024, 512)
        self.deconv4 = _deconv_layer(1026, 256)
        self.deconv3 = _deconv_layer(770, 128)
        self.deconv2 = _deconv_layer(386, 64)
        self.predict_flow6 = _pred_layer(1024)
        self.predict_flow5 = _pred_layer(1026)
        self.predict_flow4 = _pred_layer(770)
        self.predict_flow3 = _pred_layer(386)
        self.predict_flow2 = _pred_layer(194)
        self.upsampled_flow6_to_5 = _up_layer(up_bias)
        self.upsampled_flow5_to_4 = _up_layer(up_bias)
        self.upsampled_flow4_to_3 = _up_layer(up_bias)
        self.upsampled_flow3_to_2 = _up_layer(up_bias)

    def _decode(self, c6, c5, c4, c3, c2) -> dict:
        flow6 = conv2d(self.predict_flow6, c6, False)
        cat5 = torch.cat((c5, deconv2d(self.deconv5, c6, True),
                          deconv2d(self.upsampled_flow6_to_5, flow6, False)), 1)
        flow5 = conv2d(self.predict_flow5, cat5, False)
        cat4 = torch.cat((c4, deconv2d(self.deconv4, cat5, True),
                          deconv2d(self.upsampled_flow5_to_4, flow5, False)), 1)
        flow4 = conv2d(self.predict_flow4, cat4, False)
        cat3 = torch.cat((c3, deconv2d(self.deconv3, cat4, True),
                          deconv2d(self.upsampled_flow4_to_3, flow4, False)), 1)
        flow3 = conv2d(self.predict_flow3, cat3, False)
        cat2 = torch.cat((c2, deconv2d(self.deconv2, cat3, True),
                          deconv2d(self.upsampled_flow3_to_2, flow3, False)), 1)
        flow2 = conv2d(self.predict_flow2, cat2, False)
        return {"flow2": flow2, "flow3": flow3, "flow4": flow4, "flow5": flow5, "flow6": flow6}


class FlowNetC(_Decoder):
    """39,175,298 parameters; input [B, 6, H, W] (normalised frame 1 then frame 2)."""

    def __init__(self):
        super().__init__()
        self.conv1 = _conv_layer(3, 64, 7, 2)
        self.conv2 = _conv_layer(64, 128, 5, 2)
        self.conv3 = _conv_layer(128, 256, 5, 2)
        self.conv_redir = _conv_layer(256, 32, 1, 1)
        self.conv3_1 = _conv_layer(473, 256)
        self.conv4 = _conv_layer(256, 512, 3, 2)
        self.conv4_1 = _conv_layer(512, 512)
        self.conv5 = _conv_layer(512, 512, 3, 2)
        self.conv5_1 = _conv_layer(512, 512)
        self.conv6 = _conv_layer(512, 1024, 3, 2)
        self.conv6_1 = _conv_layer(1024, 1024)
        self._make_decoder(up_bias=True)

    def pyramid(self, x: torch.Tensor) -> dict:
        def stream(img):
            a = conv2d(self.conv1, img, True)
            b = conv2d(self.conv2, a, True)
            return b, conv2d(self.conv3, b, True)

        c2a, c3a = stream(x[:, 0:3])
        _, c3b = stream(x[:, 3:6])
        corr = F.leaky_relu(correlation(c3a, c3b), LEAK)
        redir = conv2d(self.conv_redir, c3a, True)
        c31 = conv2d(self.conv3_1, torch.cat((redir, corr), 1), True)
        c41 = conv2d(self.conv4_1, conv2d(self.conv4, c31, True), True)
        c51 = conv2d(self.conv5_1, conv2d(self.conv5, c41, True), True)
        c61 = conv2d(self.conv6_1, conv2d(self.conv6, c51, True), True)
        return self._decode(c61, c51, c41, c31, c2a)

    def forward(self, x):
        return self.pyramid(x)


class FlowNetS(_Decoder):
    """38,695,322 parameters with 12 input channels, 38,676,506 with 6."""

    def __init__(self, input_channels: int = 12):
        super().__init__()
        self.input_channels = input_channels
        self.conv1 = _conv_layer(input_channels, 64, 7, 2)
        self.conv2 = _conv_layer(64, 128, 5, 2)
        self.conv3 = _conv_layer(128, 256, 5, 2)
        self.conv3_1 = _conv_layer(256, 256)
        self.conv4 = _conv_layer(256, 512, 3, 2)
        self.conv4_1 = _conv_layer(512, 512)
        self.conv5 = _conv_layer(512, 512, 3, 2)
        self.conv5_1 = _conv_layer(512, 512)
        self.conv6 = _conv_layer(512, 1024, 3, 2)
        self.conv6_1 = _conv_layer(1024, 1024)
        self._make_decoder(up_bias=False)

    def pyramid(self, x: torch.Tensor) -> dict:
        c2 = conv2d(self.conv2, conv2d(self.conv1, x, True), True)
        c31 = conv2d(self.conv3_1, conv2d(self.conv3, c2, True), True)
        c41 = conv2d(self.conv4_1, conv2d(self.conv4, c31, True), True)
        c51 = conv2d(self.conv5_1, conv2d(self.conv5, c41, True), True)
        c61 = conv2d(self.conv6_1, conv2d(self.conv6, c51, True), True)
        return self._decode(c61, c51, c41, c31, c2)

    def forward(self, x):
        return self.pyramid(x)


class FlowNetSD(nn.Module):
    """45,371,666 parameters; input [B, 6, H, W]; all 3x3 convolutions, decoder with inter_conv."""

    def __init__(self):
        super().__init__()
        self.conv0 = _conv_layer(6, 64)
        self.conv1 = _conv_layer(64, 64, 3, 2)
        self.conv1_1 = _conv_layer(64, 128)
        self.conv2 = _conv_layer(128, 128, 3, 2)
        self.conv2_1 = _conv_layer(128, 128)
        self.conv3 = _conv_layer(128, 256, 3, 2)
        self.conv3_1 = _conv_layer(256, 256)
        self.conv4 = _conv_layer(256, 512, 3, 2)
        self.conv4_1 = _conv_layer(512, 512)
        self.conv5 = _conv_layer(512, 512, 3, 2)
        self.conv5_1 = _conv_layer(512, 512)
        self.conv6 = _conv_layer(512, 1024, 3, 2)
        self.conv6_1 = _conv_layer(1024, 1024)
        self.deconv5 = _deconv_layer(1024, 512)
        self.deconv4 = _deconv_layer(1026, 256)
        self.deconv3 = _deconv_layer(770, 128)
        self.deconv2 = _deconv_layer(386, 64)
        self.inter_conv5 = _conv_layer(1026, 512)
        self.inter_conv4 = _conv_layer(770, 256)
        self.inter_conv3 = _conv_layer(386, 128)
        self.inter_conv2 = _conv_layer(194, 64)
        self.predict_flow6 = _pred_layer(1024)
        self.predict_flow5 = _pred_layer(512)
        self.predict_flow4 = _pred_layer(256)
        self.predict_flow3 = _pred_layer(128)
        self.predict_flow2 = _pred_layer(64)
        self.upsampled_flow6_to_5 = _up_layer(True)
        self.upsampled_flow5_to_4 = _up_layer(True)
        self.upsampled_flow4_to_3 = _up_layer(True)
        self.upsampled_flow3_to_2 = _up_layer(True)

    def pyramid(self, x: torch.Tensor) -> dict:
        c0 = conv2d(self.conv0, x, True)
        c11 = conv2d(self.conv1_1, conv2d(self.conv1, c0, True), True)
        c21 = conv2d(self.conv2_1, conv2d(self.conv2, c11, True), True)
        c31 = conv2d(self.conv3_1, conv2d(self.conv3, c21, True), True)
        c41 = conv2d(self.conv4_1, conv2d(self.conv4, c31, True), True)
        c51 = conv2d(self.conv5_1, conv2d(self.conv5, c41, True), True)
        c61 = conv2d(self.conv6_1, conv2d(self.conv6, c51, True), True)

        flow6 = conv2d(self.predict_flow6, c61, False)
        cat5 = torch.cat((c51, deconv2d(self.deconv5, c61, True),
                          deconv2d(self.upsampled_flow6_to_5, flow6, False)), 1)
        flow5 = conv2d(self.predict_flow5, conv2d(self.inter_conv5, cat5, False), False)
        cat4 = torch.cat((c41, deconv2d(self.deconv4, cat5, True),
                          deconv2d(self.upsampled_flow5_to_4, flow5, False)), 1)
        flow4 = conv2d(self.predict_flow4, conv2d(self.inter_conv4, cat4, False), False)
        cat3 = torch.cat((c31, deconv2d(self.deconv3, cat4, True),
                          deconv2d(self.upsampled_flow4_to_3, flow4, False)), 1)
        flow3 = conv2d(self.predict_flow3, conv2d(self.inter_conv3, cat3, False), False)
        cat2 = torch.cat((c21, deconv2d(self.deconv2, cat3, True),
                          deconv2d(self.upsampled_flow3_to_2, flow3, False)), 1)
        flow2 = conv2d(self.predict_flow2, conv2d(self.inter_conv2, cat2, False), False)
        return {"flow2": flow2, "flow3": flow3, "flow4": flow4, "flow5": flow5, "flow6": flow6}

    def forward(self, x):
        return self.pyramid(x)


class FlowNetFusion(nn.Module):
    """581,226 parameters; input [B, 11, H, W] at full resolution (H, W multiples of 4)."""

    def __init__(self):
        super().__init__()
        self.conv0 = _conv_layer(11, 64)
        self.conv1 = _conv_layer(64, 64, 3, 2)
        self.conv1_1 = _conv_layer(64, 128)
        self.conv2 = _conv_layer(128, 128, 3, 2)
        self.conv2_1 = _conv_layer(128, 128)
        self.deconv1 = _deconv_layer(128, 32)
        self.deconv0 = _deconv_layer(162, 16)
        self.inter_conv1 = _conv_layer(162, 32)
        self.inter_conv0 = _conv_layer(82, 16)
        self.predict_flow2 = _pred_layer(128)
        self.predict_flow1 = _pred_layer(32)
        self.predict_flow0 = _pred_layer(16)
        self.upsampled_flow2_to_1 = _up_layer(True)
        self.upsampled_flow1_to_0 = _up_layer(True)

    def pyramid(self, x: torch.Tensor) -> dict:
        c0 = conv2d(self.conv0, x, True)
        c11 = conv2d(self.conv1_1, conv2d(self.conv1, c0, True), True)
        c21 = conv2d(self.conv2_1, conv2d(self.conv2, c11, True), True)
        flow2 = conv2d(self.predict_flow2, c21, False)
        cat1 = torch.cat((c11, deconv2d(self.deconv1, c21, True),
                          deconv2d(self.upsampled_flow2_to_1, flow2, False)), 1)
        flow1 = conv2d(self.predict_flow1, conv2d(self.inter_conv1, cat1, False), False)
        cat0 = torch.cat((c0, deconv2d(self.deconv0, cat1, True),
                          deconv2d(self.upsampled_flow1_to_0, flow1, False)), 1)
        flow0 = conv2d(self.predict_flow0, conv2d(self.inter_conv0, cat0, False), False)
        return {"flow0": flow0, "flow1": flow1, "flow2": flow2}

    def forward(self, x):
        return self.pyramid(x)


# ----------------------------------------------------------------------- complete models ----
# Each takes (frame1, frame2) as [B, 3, H, W] RGB in [0, 255] with H, W multiples of 64 and
# returns a dict whose "flow" entry is the model's result in pixels at the input resolution.

class FlowNet2C(FlowNetC):
    """Standalone FlowNet2-C (checkpoint keys without prefix)."""

    def forward(self, frame1, frame2):
        check_size(*frame1.shape[-2:])
        out = self.pyramid(normalise_frames(frame1, frame2))
        out["flow"] = upsample_bilinear(out["flow2"] * DIV_FLOW)
        return out


class FlowNet2S(FlowNetS):
    """Standalone FlowNet2-S: FlowNetS with 6 input channels."""

    def __init__(self):
        super().__init__(input_channels=6)

    def forward(self, frame1, frame2):
        check_size(*frame1.shape[-2:])
        out = self.pyramid(normalise_frames(frame1, frame2))
        out["flow"] = upsample_bilinear(out["flow2"] * DIV_FLOW)
        return out


class FlowNet2SD(FlowNetSD):
    """Standalone FlowNet2-SD (returns bilinear x4 of flow2 * 20, unlike SD inside FlowNet2)."""

    def forward(self, frame1, frame2):
        check_size(*frame1.shape[-2:])
        out = self.pyramid(normalise_frames(frame1, frame2))
        out["flow"] = upsample_bilinear(out["flow2"] * DIV_FLOW)
        return out


def _refine_input(x6: torch.Tensor, flow: torch.Tensor) -> torch.Tensor:
    """[x6, warp(frame 2, flow), flow / 20, |frame 1 - warp|] — the 12-channel FlowNetS input."""
    warped = warp(x6[:, 3:6], flow)
    err = channelnorm(x6[:, 0:3] - warped)
    return torch.cat((x6, warped, flow / DIV_FLOW, err), 1)


class FlowNet2CS(nn.Module):
    def __init__(self):
        super().__init__()
        self.flownetc = FlowNetC()
        self.flownets_1 = FlowNetS(12)

    def forward(self, frame1, frame2):
        check_size(*frame1.shape[-2:])
        x6 = normalise_frames(frame1, frame2)
        f_c = upsample_bilinear(self.flownetc(x6)["flow2"] * DIV_FLOW)
        f_s1 = upsample_bilinear(self.flownets_1(_refine_input(x6, f_c))["flow2"] * DIV_FLOW)
        return {"flownetc": f_c, "flownets_1": f_s1, "flow": f_s1}


class FlowNet2CSS(nn.Module):
    def __init__(self):
        super().__init__()
        self.flownetc = FlowNetC()
        self.flownets_1 = FlowNetS(12)
        self.flownets_2 = FlowNetS(12)

    def forward(self, frame1, frame2):
        check_size(*frame1.shape[-2:])
        x6 = normalise_frames(frame1, frame2)
        f_c = upsample_bilinear(self.flownetc(x6)["flow2"] * DIV_FLOW)
        f_s1 = upsample_bilinear(self.flownets_1(_refine_input(x6, f_c))["flow2"] * DIV_FLOW)
        f_s2 = upsample_nearest(self.flownets_2(_refine_input(x6, f_s1))["flow2"] * DIV_FLOW)
        return {"flownetc": f_c, "flownets_1": f_s1, "flownets_2": f_s2, "flow": f_s2}


class FlowNet2(nn.Module):
    """162,518,834 parameters in 220 tensors."""

    def __init__(self):
        super().__init__()
        self.flownetc = FlowNetC()
        self.flownets_1 = FlowNetS(12)
        self.flownets_2 = FlowNetS(12)
        self.flownets_d = FlowNetSD()
        self.flownetfusion = FlowNetFusion()

    def forward(self, frame1, frame2):
        check_size(*frame1.shape[-2:])
        x6 = normalise_frames(frame1, frame2)
        x1, x2 = x6[:, 0:3], x6[:, 3:6]
        f_c = upsample_bilinear(self.flownetc(x6)["flow2"] * DIV_FLOW)
        f_s1 = upsample_bilinear(self.flownets_1(_refine_input(x6, f_c))["flow2"] * DIV_FLOW)
        f_s2 = upsample_nearest(self.flownets_2(_refine_input(x6, f_s1))["flow2"] * DIV_FLOW)
        # Division, not multiplication: what the reference code does for the SD branch.
        f_sd = upsample_nearest(self.flownets_d(x6)["flow2"] / DIV_FLOW)
        concat3 = torch.cat((
            x1, f_sd, f_s2, channelnorm(f_sd), channelnorm(f_s2),
            channelnorm(x1 - warp(x2, f_sd)), channelnorm(x1 - warp(x2, f_s2))), 1)
        flow = self.flownetfusion(concat3)["flow0"]
        return {"flownetc": f_c, "flownets_1": f_s1, "flownets_2": f_s2, "flownets_d": f_sd,
                "flow": flow}


MODELS = {
    "FlowNet2": FlowNet2,
    "FlowNet2-C": FlowNet2C,
    "FlowNet2-S": FlowNet2S,
    "FlowNet2-SD": FlowNet2SD,
    "FlowNet2-CS": FlowNet2CS,
    "FlowNet2-CSS": FlowNet2CSS,
}

# Parameter counts stated in docs/model_spec.md (the self-test checks the modules against them).
EXPECTED_PARAMETERS = {
    "FlowNetC": 39_175_298,
    "FlowNetS(12)": 38_695_322,
    "FlowNetS(6)": 38_676_506,
    "FlowNetSD": 45_371_666,
    "FlowNetFusion": 581_226,
    "FlowNet2-C": 39_175_298,
    "FlowNet2-S": 38_676_506,
    "FlowNet2-SD": 45_371_666,
    "FlowNet2-CS": 77_870_620,
    "FlowNet2-CSS": 116_565_942,
    "FlowNet2": 162_518_834,
}
EXPECTED_FLOWNET2_TENSORS = 220


def build(kind: str, device=None) -> nn.Module:
    if kind not in MODELS:
        raise ValueError(f"unknown model {kind!r}; expected one of {sorted(MODELS)}")
    if device is None:
        return MODELS[kind]().eval()
    with torch.device(device):
        return MODELS[kind]().eval()


def expected_shapes(kind: str) -> dict:
    """{state_dict name: shape} of a model, without allocating its weights."""
    model = build(kind, device="meta")
    return {k: tuple(v.shape) for k, v in model.state_dict().items()}


def run_any_size(model: nn.Module, frame1: torch.Tensor, frame2: torch.Tensor) -> dict:
    """docs/model_spec.md "Any input size": resize both frames bilinearly to multiples of 64, run, resize
    the flow back and scale u by W/W', v by H/H'. Returns the model's dict (at the working size)
    plus "input1"/"input2" (the resized frames) and "flow" replaced by the flow at H x W
    ("flow_work" keeps the working-size result)."""
    h, w = frame1.shape[-2:]
    hw, ww = 64 * math.ceil(h / 64), 64 * math.ceil(w / 64)
    in1 = resize_bilinear(frame1, hw, ww)
    in2 = resize_bilinear(frame2, hw, ww)
    out = dict(model(in1, in2))
    out["input1"], out["input2"] = in1, in2
    out["flow_work"] = out["flow"]
    flow = resize_bilinear(out["flow"], h, w)
    scale = torch.tensor([w / ww, h / hw], dtype=flow.dtype, device=flow.device).view(1, 2, 1, 1)
    out["flow"] = flow * scale
    return out


def count_parameters(model: nn.Module) -> int:
    return sum(p.numel() for p in model.parameters())
