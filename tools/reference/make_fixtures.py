# SPDX-License-Identifier: Apache-2.0
"""Writes the committed test fixtures of tests/data/fixtures/ (see tools/reference/README.md).

Every network runs with the deterministic synthetic weights (synthetic.py). The reference runs
in float64 (weights and inputs are float32 values, promoted exactly) and the results are stored
rounded to float32, so a fixture is as close to the exact result of the specified arithmetic as
float32 storage allows; a float32 implementation is then compared against that.

Usage: python tools/reference/make_fixtures.py [--out DIR] [--check-only]
"""

from __future__ import annotations

import argparse
import hashlib
import json
import math
import os
import sys

import numpy as np
import torch
from safetensors.numpy import load_file

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import flownet2 as fn  # noqa: E402
import head as hd  # noqa: E402
import synthetic as sy  # noqa: E402

REPO = os.path.dirname(os.path.dirname(HERE))
DEFAULT_OUT = os.path.join(REPO, "tests", "data", "fixtures")
SEED = 1
WIDTH, HEIGHT = 128, 96
MAX_TOTAL_BYTES = 5 * 1024 * 1024


# ------------------------------------------------------------------------------ inputs ------

def _texture(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """A smooth-plus-edges RGB pattern (values roughly 0..255) defined for any real (x, y)."""
    r = 128 + 70 * np.sin(0.23 * x + 0.11 * y) + 45 * np.sin(0.09 * x - 0.31 * y)
    g = 128 + 80 * np.sin(0.17 * y + 0.05 * x + 1.0) * np.cos(0.12 * x)
    checker = (np.floor(x / 16) + np.floor(y / 16)) % 2 - 0.5
    b = 128 + 60 * np.cos(0.2 * x + 0.19 * y) + 50 * checker
    return np.stack([r, g, b])


def make_frames(w: int = WIDTH, h: int = HEIGHT):
    """frame1 = texture; frame2 = the texture seen after a 3 degree rotation about the centre and a
    (+3, -2) pixel shift. Integer values 0..255 as float32, [1, 3, H, W], RGB."""
    y, x = np.mgrid[0:h, 0:w].astype(np.float64)
    f1 = _texture(x, y)
    th = math.radians(3.0)
    cx, cy = w / 2.0, h / 2.0
    xs = math.cos(th) * (x - cx) - math.sin(th) * (y - cy) + cx + 3.0
    ys = math.sin(th) * (x - cx) + math.cos(th) * (y - cy) + cy - 2.0
    f2 = _texture(xs, ys)
    q = lambda a: np.clip(np.round(a), 0, 255).astype(np.float32)[None]  # noqa: E731
    return q(f1), q(f2)


def make_fusion_input(w: int = WIDTH, h: int = HEIGHT) -> np.ndarray:
    """11 channels shaped like FlowNet2's concat3: image-like, two flows, four non-negative norms."""
    rng = np.random.default_rng(20240611)
    img = rng.uniform(-0.5, 0.5, size=(3, h, w))
    flows = rng.normal(0.0, 2.0, size=(4, h, w))
    norms = np.abs(rng.normal(0.0, 1.0, size=(4, h, w)))
    return np.concatenate([img, flows, norms])[None].astype(np.float32)


def make_head_input(w: int, h: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return rng.normal(0.0, 3.0, size=(2, 2, h, w)).astype(np.float32)


# ------------------------------------------------------------------------------ helpers -----

def _np(t: torch.Tensor) -> np.ndarray:
    return np.ascontiguousarray(t.detach().to(torch.float32).cpu().numpy())


def _t(a: np.ndarray) -> torch.Tensor:
    return torch.from_numpy(a).to(torch.float64)


def synthetic_model(kind_or_module, seed: int = SEED):
    model = fn.build(kind_or_module) if isinstance(kind_or_module, str) else kind_or_module
    sy.fill_synthetic(model, seed)  # float32 values ...
    return model.double().eval()    # ... promoted exactly


def _meta(model: str, extra: dict | None = None) -> dict:
    m = {
        "inertialnet.model": model,
        "inertialnet.synthetic": "true",
        "inertialnet.seed": str(SEED),
        "fixture.generator": "tools/reference/make_fixtures.py",
        "fixture.computed_in": "float64",
        "fixture.torch": torch.__version__.split("+")[0],
    }
    m.update(extra or {})
    return {k: str(v) for k, v in m.items()}


def _frames_meta(work_w: int, work_h: int) -> dict:
    return {"fixture.input_width": WIDTH, "fixture.input_height": HEIGHT,
            "fixture.work_width": work_w, "fixture.work_height": work_h}


def flow_stats(name: str, flow: torch.Tensor) -> dict:
    """Magnitude and the share of pixels whose warp target lies inside the image."""
    f = flow.detach().to(torch.float64)
    _, _, h, w = f.shape
    mag = f.norm(dim=1)
    xs = torch.arange(w, dtype=f.dtype).view(1, 1, w) + f[:, 0]
    ys = torch.arange(h, dtype=f.dtype).view(1, h, 1) + f[:, 1]
    inside = ((xs >= 0) & (xs <= w - 1) & (ys >= 0) & (ys <= h - 1)).double().mean().item()
    return {"name": name, "shape": list(f.shape), "mean_abs_px": mag.mean().item(),
            "max_abs_px": mag.max().item(), "u_min": f[:, 0].min().item(),
            "u_max": f[:, 0].max().item(), "v_min": f[:, 1].min().item(),
            "v_max": f[:, 1].max().item(), "inside": inside,
            "finite": bool(torch.isfinite(f).all().item())}


def write_safetensors(path: str, arrays: dict, meta: dict) -> None:
    """A byte-reproducible safetensors writer (safetensors' own orders the header through a hash
    map, so regenerated fixtures would differ in bytes): metadata first with sorted keys, tensors
    in the given order, header padded with spaces to a multiple of 8 bytes."""
    header = {"__metadata__": dict(sorted(meta.items()))}
    offset = 0
    for name, a in arrays.items():
        header[name] = {"dtype": "F32", "shape": list(a.shape),
                        "data_offsets": [offset, offset + a.nbytes]}
        offset += a.nbytes
    text = json.dumps(header, separators=(",", ":")).encode("utf-8")
    text += b" " * (-len(text) % 8)
    with open(path, "wb") as f:
        f.write(len(text).to_bytes(8, "little"))
        f.write(text)
        for a in arrays.values():
            f.write(a.astype("<f4").tobytes())


def _save(out_dir: str, fname: str, tensors: dict, meta: dict, written: list) -> None:
    path = os.path.join(out_dir, fname)
    arrays = {k: np.ascontiguousarray(v, dtype=np.float32) for k, v in tensors.items()}
    for k, v in arrays.items():
        if not np.all(np.isfinite(v)):
            raise RuntimeError(f"{fname}: tensor {k} holds non-finite values")
    write_safetensors(path, arrays, meta)
    back = load_file(path)
    assert set(back) == set(arrays) and all(np.array_equal(back[k], arrays[k]) for k in arrays)
    written.append(path)


# ------------------------------------------------------------------------------ fixtures ----

def flownet2_family(out_dir: str, written: list, stats: list) -> None:
    frame1, frame2 = make_frames()
    t1, t2 = _t(frame1), _t(frame2)

    model = synthetic_model("FlowNet2")
    out = fn.run_any_size(model, t1, t2)
    wh, ww = out["input1"].shape[-2:]
    for key in ("flownetc", "flownets_1", "flownets_2", "flownets_d", "flow_work", "flow"):
        stats.append(flow_stats(f"FlowNet2.{key}", out[key]))
    _save(out_dir, f"flownet2_{WIDTH}x{HEIGHT}.safetensors", {
        "frame1": frame1, "frame2": frame2,
        "input1": _np(out["input1"]), "input2": _np(out["input2"]),
        "flownetc": _np(out["flownetc"]), "flownets_1": _np(out["flownets_1"]),
        "flownets_2": _np(out["flownets_2"]), "flownets_d": _np(out["flownets_d"]),
        "flow_work": _np(out["flow_work"]), "flow": _np(out["flow"]),
    }, _meta("FlowNet2", _frames_meta(ww, wh)), written)
    full = {k: out[k] for k in ("flownetc", "flownets_1", "flownets_2")}
    del model

    for kind, fname, same_as in (("FlowNet2-CS", "flownet2-cs", "flownets_1"),
                                 ("FlowNet2-CSS", "flownet2-css", "flownets_2")):
        model = synthetic_model(kind)
        o = fn.run_any_size(model, t1, t2)
        # Same tensor names and seed, hence the same weights: the cascade prefix must agree.
        if not torch.equal(o["flow_work"], full[same_as]):
            raise RuntimeError(f"{kind} disagrees with FlowNet2's {same_as}")
        stats.append(flow_stats(f"{kind}.flow", o["flow"]))
        _save(out_dir, f"{fname}_{WIDTH}x{HEIGHT}.safetensors", {"flow": _np(o["flow"])},
              _meta(kind, {**_frames_meta(ww, wh),
                           "fixture.inputs": f"frame1, frame2 of flownet2_{WIDTH}x{HEIGHT}.safetensors"}),
              written)
        del model

    for kind, fname in (("FlowNet2-C", "flownet2-c"), ("FlowNet2-S", "flownet2-s"),
                        ("FlowNet2-SD", "flownet2-sd")):
        model = synthetic_model(kind)
        o = fn.run_any_size(model, t1, t2)
        stats.append(flow_stats(f"{kind}.flow", o["flow"]))
        tensors = {f"flow{i}": _np(o[f"flow{i}"]) for i in range(2, 7)}
        tensors["flow"] = _np(o["flow"])
        _save(out_dir, f"{fname}_{WIDTH}x{HEIGHT}.safetensors", tensors,
              _meta(kind, {**_frames_meta(ww, wh),
                           "fixture.inputs": f"frame1, frame2 of flownet2_{WIDTH}x{HEIGHT}.safetensors"}),
              written)
        del model


def fusion(out_dir: str, written: list, stats: list) -> None:
    x = make_fusion_input()
    # flownetfusion.* names: the weights the fusion network has inside FlowNet2.
    model = fn.FlowNetFusion()
    sy.fill_synthetic(model, SEED, prefix="flownetfusion.")
    model = model.double().eval()
    o = model(_t(x))
    stats.append(flow_stats("FlowNetFusion.flow0", o["flow0"]))
    _save(out_dir, f"flownetfusion_{WIDTH}x{HEIGHT}.safetensors", {
        "input": x, "flow0": _np(o["flow0"]), "flow1": _np(o["flow1"]), "flow2": _np(o["flow2"]),
    }, _meta("FlowNetFusion", {"fixture.input_width": WIDTH, "fixture.input_height": HEIGHT,
                               "fixture.weight_prefix": "flownetfusion."}), written)


def heads(out_dir: str, written: list, stats: list) -> None:
    configs = [
        ("head_32x24", hd.HeadConfig(input_height=24, input_width=32), 101),
        ("head_38x30", hd.HeadConfig(input_height=30, input_width=38), 102),
        ("head_custom_38x30", hd.HeadConfig(input_height=30, input_width=38, conv1_channels=8,
                                            conv1_kernel=5, conv2_channels=12, conv3_channels=4,
                                            conv3_kernel=3, fc1_units=32, flow_scale=0.5), 103),
    ]
    for fname, cfg, data_seed in configs:
        model = hd.InertialNetHead(cfg)
        sy.fill_synthetic(model, SEED)
        model = model.double().eval()
        x = make_head_input(cfg.input_width, cfg.input_height, data_seed)
        with torch.no_grad():
            omega = model(_t(x))
            # The flattened conv3 activations: what fc1 sees (NCHW flatten order).
            h = model.head
            f = _t(x) * cfg.flow_scale
            f = torch.relu(torch.nn.functional.conv2d(f, h.conv1.weight, h.conv1.bias, 1, h.conv1.padding))
            f = torch.nn.functional.max_pool2d(f, cfg.pool, cfg.pool)
            f = torch.relu(torch.nn.functional.conv2d(f, h.conv2.weight, h.conv2.bias, 1, h.conv2.padding))
            f = torch.nn.functional.max_pool2d(f, cfg.pool, cfg.pool)
            f = torch.relu(torch.nn.functional.conv2d(f, h.conv3.weight, h.conv3.bias, 1, h.conv3.padding))
            features = torch.flatten(f, 1)
        stats.append({"name": fname, "omega": omega.tolist(),
                      "features_nonzero": float((features > 0).double().mean())})
        _save(out_dir, f"{fname}.safetensors",
              {"flow": x, "features": _np(features), "omega": _np(omega)},
              _meta("InertialNetHead", {"inertialnet.head": cfg.to_json()}), written)


# --------------------------------------------------------------- synthetic weight checks ----

def _hex32(v) -> str:
    return float(np.float32(v)).hex()


def synthetic_weights_json(out_dir: str, written: list) -> None:
    flownet2_names = [
        "flownetc.conv1.0.weight", "flownetc.conv1.0.bias", "flownetc.conv_redir.0.weight",
        "flownetc.conv3_1.0.weight", "flownets_1.deconv5.0.weight", "flownets_1.deconv5.0.bias",
        "flownetc.predict_flow6.weight", "flownetc.predict_flow2.bias",
        "flownetc.upsampled_flow6_to_5.weight", "flownetc.upsampled_flow6_to_5.bias",
        "flownets_2.upsampled_flow3_to_2.weight", "flownets_d.inter_conv5.0.weight",
        "flownets_d.conv0.0.weight", "flownetfusion.predict_flow0.weight",
        "flownetfusion.deconv0.0.weight", "flownetfusion.upsampled_flow1_to_0.bias",
    ]
    picks = [("FlowNet2", n) for n in flownet2_names]
    picks += [("FlowNet2-S", "conv1.0.weight"), ("FlowNet2-C", "conv_redir.0.bias"),
              ("FlowNet2-SD", "conv0.0.weight"), ("FlowNet2-C", "upsampled_flow3_to_2.weight")]
    head_names = ["head.conv1.weight", "head.conv1.bias", "head.conv3.weight",
                  "head.fc1.weight", "head.fc1.bias", "head.fc2.weight", "head.fc2.bias"]

    kinds_cache = {}

    def kinds_of(kind):
        if kind not in kinds_cache:
            if kind == "InertialNetHead":
                with torch.device("meta"):
                    m = hd.InertialNetHead(hd.HeadConfig())
            else:
                m = fn.build(kind, device="meta")
            kinds_cache[kind] = sy.parameter_kinds(m)
        return kinds_cache[kind]

    def entry(model, name, seed):
        kind, wshape = kinds_of(model)[name]
        shape = wshape if not sy.is_bias(name) else (wshape[1] if kind == "deconv" else wshape[0],)
        values = sy.synthetic_tensor(name, shape, kind, seed, wshape)
        le = values.astype("<f4").tobytes()
        d = {"model": model, "name": name, "shape": list(shape), "numel": int(values.size)}
        d.update(sy.describe(name, shape, kind, wshape))
        d["fnv1a64"] = f"0x{sy.fnv1a64(name):016x}"
        d["key"] = f"0x{sy.stream_key(name, seed):016x}"
        d["first4_u"] = [float(u).hex() for u in sy.uniform(name, 4, seed)]
        flat = values.reshape(-1)
        d["first4_hex"] = [_hex32(v) for v in flat[:4]]
        d["first4"] = [float(v) for v in flat[:4]]
        d["last_hex"] = _hex32(flat[-1])
        d["sha256"] = hashlib.sha256(le).hexdigest()
        return d

    doc = {
        "description": "Deterministic synthetic weights (docs/model_spec.md): per tensor, its layer "
                       "kind, fan_in, gain, the stream key, the first four u values and float32 "
                       "values as exact hex floats, and the sha256 of all its little-endian float32 "
                       "bytes. Head tensors are those of the default head (input 752x480, so fc1 has "
                       "8*120*188 = 180,480 inputs).",
        "generator": "tools/reference/make_fixtures.py",
        "fnv1a64": {s: f"0x{sy.fnv1a64(s):016x}" for s in ["", "a", "conv1.0.weight", "t\u00ebst.weight"]},
        "splitmix64": {f"0x{k:016x}": f"0x{int(sy.splitmix64_array(k, 1)[0]):016x}"
                       for k in (0, 1, 0x9E3779B97F4A7C15, (1 << 64) - 1)},
        "seeds": [],
    }
    for seed in (1, 12345, (1 << 64) - 1):
        tensors = [entry(m, n, seed) for m, n in picks]
        tensors += [entry("InertialNetHead", n, seed) for n in head_names]
        if seed == (1 << 64) - 1:
            tensors = tensors[:3] + tensors[-2:]
        doc["seeds"].append({"seed": seed, "tensors": tensors})
    path = os.path.join(out_dir, "synthetic_weights.json")
    with open(path, "w", encoding="utf-8") as f:
        json.dump(doc, f, indent=1, ensure_ascii=False)
        f.write("\n")
    written.append(path)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=DEFAULT_OUT, help="output folder (default: %(default)s)")
    args = ap.parse_args(argv)
    torch.set_grad_enabled(False)
    torch.manual_seed(0)
    os.makedirs(args.out, exist_ok=True)
    written, stats = [], []
    flownet2_family(args.out, written, stats)
    fusion(args.out, written, stats)
    heads(args.out, written, stats)
    synthetic_weights_json(args.out, written)

    total = 0
    for p in written:
        size = os.path.getsize(p)
        total += size
        print(f"{size:>10,d}  {os.path.relpath(p, REPO)}")
    print(f"{total:>10,d}  total")
    for s in stats:
        if "mean_abs_px" in s:
            print(f"{s['name']:<24} {str(s['shape']):<18} mean|f| {s['mean_abs_px']:.4f} px, "
                  f"max {s['max_abs_px']:.4f} px, u [{s['u_min']:.3f}, {s['u_max']:.3f}], "
                  f"v [{s['v_min']:.3f}, {s['v_max']:.3f}], warp inside {100 * s['inside']:.1f} %, "
                  f"finite {s['finite']}")
        else:
            print(f"{s['name']:<24} omega {s['omega']}, conv3 active {100 * s['features_nonzero']:.0f} %")
    bad = [s["name"] for s in stats if "finite" in s and (not s["finite"] or s["max_abs_px"] == 0)]
    if bad:
        print(f"degenerate flows: {bad}", file=sys.stderr)
        return 1
    if total > MAX_TOTAL_BYTES:
        print(f"fixtures total {total} bytes, over the {MAX_TOTAL_BYTES} budget", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
