# SPDX-License-Identifier: Apache-2.0
"""Self-test of the PyTorch reference: the generator, parameter counts and names, and each op
against a loop written straight from docs/model_spec.md (test_fixtures.py checks the fixtures).

Run: .venv-reference/bin/python -m pytest tools/reference/tests -q
"""

import math

import numpy as np
import pytest
import torch

import flownet2 as fn
import head as hd
import synthetic as sy

torch.set_grad_enabled(False)
M64 = (1 << 64) - 1


# ----------------------------------------------------------------------------- generator ----

def _splitmix64_scalar(x):
    z = (x + 0x9E3779B97F4A7C15) & M64
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & M64
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & M64
    return z ^ (z >> 31)


def test_known_hash_values():
    # Published constants: FNV-1a 64 of "" and "a"; splitmix64's first output for state 0.
    assert sy.fnv1a64("") == 0xCBF29CE484222325
    assert sy.fnv1a64("a") == 0xAF63DC4C8601EC8C
    assert int(sy.splitmix64_array(0, 1)[0]) == 0xE220A8397B1DCDAF


@pytest.mark.parametrize("seed", [0, 1, 12345, M64])
def test_vectorised_generator_matches_scalar_arithmetic(seed):
    for name in ["flownetc.conv1.0.weight", "head.fc2.bias", "t\u00ebst"]:
        key = (sy.fnv1a64(name) ^ ((seed * 0x9E3779B97F4A7C15) & M64)) & M64
        assert sy.stream_key(name, seed) == key
        n = 1000
        expect = [(_splitmix64_scalar((key + i) & M64) >> 40) / 2.0**23 - 1.0 for i in range(n)]
        assert np.array_equal(sy.uniform(name, n, seed), np.array(expect))


def test_generator_wraps_the_counter_modulo_2_64():
    # A counter start within 3 of 2^64 makes key + i wrap inside the stream.
    start = M64 - 2
    z = sy.splitmix64_array(start, 6)
    assert [int(v) for v in z] == [_splitmix64_scalar((start + i) & M64) for i in range(6)]


def test_weight_and_bias_formulas():
    seed = 7
    w = sy.synthetic_tensor("x.predict_flow3.weight", (2, 5, 3, 3), "conv", seed)
    u = sy.uniform("x.predict_flow3.weight", 90, seed)
    assert np.array_equal(w.reshape(-1), ((u * math.sqrt(6.0 / 45)) * 0.7).astype(np.float32))
    b = sy.synthetic_tensor("x.conv1.0.bias", (64,), "conv", seed)
    assert np.array_equal(b, (0.01 * sy.uniform("x.conv1.0.bias", 64, seed)).astype(np.float32))
    d = sy.synthetic_tensor("deconv5.0.weight", (8, 3, 4, 4), "deconv", seed)
    ud = sy.uniform("deconv5.0.weight", d.size, seed)
    assert np.array_equal(d.reshape(-1), (ud * math.sqrt(6.0 / 32)).astype(np.float32))
    assert sy.gain_for("flownetc.upsampled_flow6_to_5.weight") == 0.7
    assert sy.gain_for("flownetc.conv1.0.weight") == 1.0
    assert sy.fan_in_for("linear", (128, 384)) == 384
    u_all = sy.uniform("range", 200000, 3)
    assert u_all.min() >= -1.0 and u_all.max() < 1.0 and abs(u_all.mean()) < 0.01


# ------------------------------------------------------------------------- models / names ----

@pytest.mark.parametrize("kind", sorted(fn.MODELS))
def test_parameter_counts(kind):
    model = fn.build(kind, device="meta")
    assert fn.count_parameters(model) == fn.EXPECTED_PARAMETERS[kind]


def test_subnetwork_parameter_counts():
    with torch.device("meta"):
        nets = {"FlowNetC": fn.FlowNetC(), "FlowNetS(12)": fn.FlowNetS(12),
                "FlowNetS(6)": fn.FlowNetS(6), "FlowNetSD": fn.FlowNetSD(),
                "FlowNetFusion": fn.FlowNetFusion()}
    for name, net in nets.items():
        assert fn.count_parameters(net) == fn.EXPECTED_PARAMETERS[name], name


def test_flownet2_state_dict_names():
    shapes = fn.expected_shapes("FlowNet2")
    assert len(shapes) == fn.EXPECTED_FLOWNET2_TENSORS
    assert shapes["flownetc.conv1.0.weight"] == (64, 3, 7, 7)
    assert shapes["flownets_1.conv1.0.weight"] == (64, 12, 7, 7)
    assert shapes["flownets_1.deconv5.0.bias"] == (512,)
    assert shapes["flownetc.upsampled_flow6_to_5.weight"] == (2, 2, 4, 4)
    assert "flownetc.upsampled_flow6_to_5.bias" in shapes
    assert "flownets_2.upsampled_flow6_to_5.bias" not in shapes
    assert shapes["flownetc.predict_flow6.weight"] == (2, 1024, 3, 3)
    assert shapes["flownetc.conv3_1.0.weight"] == (256, 473, 3, 3)
    assert shapes["flownets_d.inter_conv2.0.weight"] == (64, 194, 3, 3)
    assert shapes["flownetfusion.deconv0.0.weight"] == (162, 16, 4, 4)
    assert shapes["flownetfusion.predict_flow0.weight"] == (2, 16, 3, 3)
    prefixes = {k.split(".")[0] for k in shapes}
    assert prefixes == {"flownetc", "flownets_1", "flownets_2", "flownets_d", "flownetfusion"}
    standalone = fn.expected_shapes("FlowNet2-S")
    assert standalone["conv1.0.weight"] == (64, 6, 7, 7)


def test_networks_reject_sizes_that_are_not_multiples_of_64():
    model = fn.build("FlowNet2-S", device="meta")
    with pytest.raises(ValueError, match="multiples of 64"):
        model(torch.zeros(1, 3, 96, 128, device="meta"), torch.zeros(1, 3, 96, 128, device="meta"))


# ---------------------------------------------------------------- ops against spec loops ----

def test_correlation_matches_definition():
    g = torch.Generator().manual_seed(0)
    f1 = torch.randn(2, 5, 6, 7, generator=g, dtype=torch.float64)
    f2 = torch.randn(2, 5, 6, 7, generator=g, dtype=torch.float64)
    md, s2 = 4, 2
    out = fn.correlation(f1, f2, md, s2)
    r = md // s2
    assert out.shape == (2, (2 * r + 1) ** 2, 6, 7)
    a, b = f1.numpy(), f2.numpy()
    for dyi in range(2 * r + 1):
        for dxi in range(2 * r + 1):
            dy, dx = (dyi - r) * s2, (dxi - r) * s2
            ch = dyi * (2 * r + 1) + dxi
            for y in range(6):
                for x in range(7):
                    yy, xx = y + dy, x + dx
                    want = np.zeros(2)
                    if 0 <= yy < 6 and 0 <= xx < 7:
                        want = (a[:, :, y, x] * b[:, :, yy, xx]).sum(1) / 5
                    # float64 on both sides, sums of 5 products: only rounding differs.
                    np.testing.assert_allclose(out[:, ch, y, x].numpy(), want, rtol=0, atol=1e-12)


def _warp_loop(img, flow):
    b, c, h, w = img.shape
    out = np.zeros_like(img)
    for n in range(b):
        for y in range(h):
            for x in range(w):
                xf, yf = x + flow[n, 0, y, x], y + flow[n, 1, y, x]
                al, be = xf - math.floor(xf), yf - math.floor(yf)
                xl = min(max(math.floor(xf), 0), w - 1)
                xr = min(max(math.floor(xf) + 1, 0), w - 1)
                yt = min(max(math.floor(yf), 0), h - 1)
                yb = min(max(math.floor(yf) + 1, 0), h - 1)
                out[n, :, y, x] = ((1 - al) * (1 - be) * img[n, :, yt, xl]
                                   + al * (1 - be) * img[n, :, yt, xr]
                                   + (1 - al) * be * img[n, :, yb, xl]
                                   + al * be * img[n, :, yb, xr])
    return out


def test_warp_matches_definition_including_borders():
    g = torch.Generator().manual_seed(1)
    img = torch.randn(2, 3, 7, 9, generator=g, dtype=torch.float64)
    flow = torch.randn(2, 2, 7, 9, generator=g, dtype=torch.float64) * 4  # many outside
    flow[0, :, 0, 0] = torch.tensor([2.0, -1.0])  # integer displacement
    flow[1, :, 3, 3] = torch.tensor([-30.0, 25.5])  # far outside
    out = fn.warp(img, flow).numpy()
    # float64, the same four-term formula: only the order of rounding differs.
    np.testing.assert_allclose(out, _warp_loop(img.numpy(), flow.numpy()), rtol=0, atol=1e-12)


def _interp_weights(n_in, n_out):
    """(i0, i1, lambda) per output index: half-pixel source, negative clamped to 0."""
    scale = n_in / n_out
    res = []
    for d in range(n_out):
        s = max((d + 0.5) * scale - 0.5, 0.0)
        i0 = min(int(math.floor(s)), n_in - 1)
        i1 = min(i0 + 1, n_in - 1)
        res.append((i0, i1, s - i0))
    return res


def _resize_loop(a, h, w):
    rows, cols = _interp_weights(a.shape[2], h), _interp_weights(a.shape[3], w)
    out = np.zeros(a.shape[:2] + (h, w))
    for y, (y0, y1, ly) in enumerate(rows):
        for x, (x0, x1, lx) in enumerate(cols):
            out[:, :, y, x] = ((1 - ly) * ((1 - lx) * a[:, :, y0, x0] + lx * a[:, :, y0, x1])
                               + ly * ((1 - lx) * a[:, :, y1, x0] + lx * a[:, :, y1, x1]))
    return out


@pytest.mark.parametrize("src,dst", [((3, 5), (12, 20)), ((96, 128), (128, 128)),
                                     ((128, 128), (96, 128)), ((7, 9), (5, 4))])
def test_bilinear_resize_matches_half_pixel_definition(src, dst):
    a = torch.randn(1, 2, *src, dtype=torch.float64, generator=torch.Generator().manual_seed(2))
    got = fn.resize_bilinear(a, *dst).numpy()
    # float64; PyTorch factors the interpolation differently from the loop, so allow rounding.
    np.testing.assert_allclose(got, _resize_loop(a.numpy(), *dst), rtol=0, atol=1e-12)
    if dst == (src[0] * 4, src[1] * 4):
        np.testing.assert_allclose(fn.upsample_bilinear(a).numpy(), got, rtol=0, atol=0)


def test_nearest_upsampling_repeats_each_pixel():
    a = torch.arange(6, dtype=torch.float64).view(1, 1, 2, 3)
    up = fn.upsample_nearest(a)
    assert torch.equal(up, a.repeat_interleave(4, 2).repeat_interleave(4, 3))


def test_channelnorm_and_normalisation():
    x = torch.tensor([[[[3.0]], [[4.0]]]], dtype=torch.float64)
    assert fn.channelnorm(x).item() == 5.0
    f1 = torch.rand(2, 3, 4, 5, dtype=torch.float64) * 255
    f2 = torch.rand(2, 3, 4, 5, dtype=torch.float64) * 255
    x6 = fn.normalise_frames(f1, f2).numpy()
    mean = np.concatenate([f1.numpy(), f2.numpy()], axis=3).mean(axis=(2, 3), keepdims=True)
    # float64 means of 40 values in [0, 255], divided by 255: rounding only.
    np.testing.assert_allclose(x6[:, :3], (f1.numpy() - mean) / 255, atol=1e-15)
    np.testing.assert_allclose(x6[:, 3:], (f2.numpy() - mean) / 255, atol=1e-15)


def test_any_size_scales_the_flow_components():
    class Constant(torch.nn.Module):
        def forward(self, a, b):
            f = torch.ones(a.shape[0], 2, *a.shape[-2:], dtype=a.dtype)
            return {"flow": f}

    out = fn.run_any_size(Constant(), torch.zeros(1, 3, 96, 100), torch.zeros(1, 3, 96, 100))
    assert out["flow_work"].shape == (1, 2, 128, 128) and out["flow"].shape == (1, 2, 96, 100)
    assert torch.allclose(out["flow"][0, 0], torch.full((96, 100), 100 / 128))
    assert torch.allclose(out["flow"][0, 1], torch.full((96, 100), 96 / 128))


# --------------------------------------------------------------------------------- head ------

def test_head_shapes_flatten_order_and_dropout():
    cfg = hd.HeadConfig(input_height=30, input_width=38)
    assert cfg.fc1_inputs() == 8 * 7 * 9
    shapes = hd.expected_shapes(hd.HeadConfig())
    assert shapes["head.fc1.weight"] == (128, 8 * 120 * 188)
    assert list(shapes) == ["head.conv1.weight", "head.conv1.bias", "head.conv2.weight",
                            "head.conv2.bias", "head.conv3.weight", "head.conv3.bias",
                            "head.fc1.weight", "head.fc1.bias", "head.fc2.weight", "head.fc2.bias"]
    model = hd.InertialNetHead(cfg).double()
    sy.fill_synthetic(model, 1)
    x = torch.randn(2, 2, 30, 38, dtype=torch.float64)
    model.eval()
    y1, y2 = model(x), model(x)
    assert y1.shape == (2, 3) and torch.equal(y1, y2)
    model.train()
    torch.manual_seed(0)
    assert not torch.equal(model(x), y1)
    with pytest.raises(ValueError):
        model(torch.zeros(1, 2, 30, 40, dtype=torch.float64))
    with pytest.raises(ValueError):
        hd.HeadConfig.from_dict({"input_height": 24, "input_width": 32, "bogus": 1})
