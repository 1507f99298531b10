# SPDX-License-Identifier: Apache-2.0
"""The committed fixtures of tests/data/fixtures/: budget, metadata, and agreement with a fresh run
of the reference (for the models that are quick to recompute; the rest share their code).

Run: .venv-reference/bin/python -m pytest tools/reference/tests -q
"""

import json
import os

import numpy as np
import torch
from safetensors import safe_open

import flownet2 as fn
import head as hd
import make_fixtures as mf
import synthetic as sy

torch.set_grad_enabled(False)
FIXTURES = mf.DEFAULT_OUT


def test_synthetic_weights_json_matches_generator():
    with open(os.path.join(FIXTURES, "synthetic_weights.json"), encoding="utf-8") as f:
        doc = json.load(f)
    for block in doc["seeds"]:
        for t in block["tensors"][:6]:
            v = sy.synthetic_tensor(t["name"], t["shape"], t["kind"], block["seed"],
                                    None if t["param"] == "bias" else t["shape"])
            assert [float(x).hex() for x in v.reshape(-1)[:4]] == t["first4_hex"]


def _load(fname):
    with safe_open(os.path.join(FIXTURES, fname), framework="np") as f:
        return {k: f.get_tensor(k) for k in f.keys()}, f.metadata()


def test_fixture_budget_and_metadata():
    total = sum(os.path.getsize(os.path.join(FIXTURES, f)) for f in os.listdir(FIXTURES))
    assert total < mf.MAX_TOTAL_BYTES
    t, meta = _load("flownet2_128x96.safetensors")
    assert meta["inertialnet.model"] == "FlowNet2" and meta["inertialnet.seed"] == "1"
    assert t["frame1"].shape == (1, 3, 96, 128) and t["flow"].shape == (1, 2, 96, 128)
    assert t["flownetc"].shape == (1, 2, 128, 128)
    assert np.array_equal(t["frame1"], np.round(t["frame1"]))
    _, hmeta = _load("head_38x30.safetensors")
    cfg = hd.HeadConfig.from_dict(json.loads(hmeta["inertialnet.head"]))
    assert (cfg.input_width, cfg.input_height) == (38, 30)


def test_committed_fixtures_are_current_for_the_cheap_models():
    # The heads and a standalone network are quick to recompute; the rest follow the same code.
    frames, _ = _load("flownet2_128x96.safetensors")
    f1, f2 = mf.make_frames()
    assert np.array_equal(frames["frame1"], f1) and np.array_equal(frames["frame2"], f2)
    for fname in ["head_32x24.safetensors", "head_custom_38x30.safetensors"]:
        t, meta = _load(fname)
        cfg = hd.HeadConfig.from_dict(json.loads(meta["inertialnet.head"]))
        model = hd.InertialNetHead(cfg)
        sy.fill_synthetic(model, 1)
        got = model.double().eval()(torch.from_numpy(t["flow"]).double()).float().numpy()
        assert np.array_equal(got, t["omega"]), fname
    t, _ = _load("flownet2-s_128x96.safetensors")
    model = mf.synthetic_model("FlowNet2-S")
    out = fn.run_any_size(model, torch.from_numpy(f1).double(), torch.from_numpy(f2).double())
    assert np.array_equal(out["flow"].float().numpy(), t["flow"])
    assert np.array_equal(out["flow6"].float().numpy(), t["flow6"])
