# SPDX-License-Identifier: Apache-2.0
"""tools/convert_checkpoint.py on checkpoints the reference models save themselves.

Run: .venv-reference/bin/python -m pytest tools/reference/tests -q
"""

import json
import os
import subprocess
import sys

import pytest
import torch
from safetensors import safe_open

import convert_checkpoint as cc
import flownet2 as fn
import head as hd
import synthetic as sy

SCRIPT = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))),
                      "convert_checkpoint.py")


def _cli(*args):
    return subprocess.run([sys.executable, SCRIPT, *map(str, args)], capture_output=True,
                          text=True)


@pytest.fixture(scope="module")
def flownet2_s_checkpoint(tmp_path_factory):
    model = fn.build("FlowNet2-S")
    sy.fill_synthetic(model, 5)
    path = tmp_path_factory.mktemp("ckpt") / "FlowNet2-S_checkpoint.pth.tar"
    # The published checkpoints predate torch's zip format: save the legacy way.
    torch.save({"epoch": 3, "state_dict": model.state_dict(), "best_EPE": 4.2}, path,
               _use_new_zipfile_serialization=False)
    return path, model.state_dict()


def _read(path):
    with safe_open(str(path), framework="pt") as f:
        return {k: f.get_tensor(k) for k in f.keys()}, f.metadata()


def test_flownet2_s_round_trip_bit_for_bit(flownet2_s_checkpoint, tmp_path):
    src, state = flownet2_s_checkpoint
    out = tmp_path / "s.safetensors"
    r = _cli(src, out, "--check")
    assert r.returncode == 0, r.stderr
    assert "FlowNet2-S, 42 tensors, 38,676,506 parameters, verified bit for bit" in r.stdout
    tensors, meta = _read(out)
    assert meta["inertialnet.model"] == "FlowNet2-S" and meta["inertialnet.synthetic"] == "false"
    assert set(tensors) == set(state)
    for k, v in state.items():
        assert torch.equal(tensors[k].view(torch.int32), v.view(torch.int32)), k


def test_check_detects_a_changed_tensor(flownet2_s_checkpoint, tmp_path):
    src, state = flownet2_s_checkpoint
    out = tmp_path / "s.safetensors"
    assert cc.main([str(src), str(out), "-q"]) == 0
    tensors = {k: v.clone().contiguous() for k, v in state.items()}
    tensors["conv1.0.bias"][3] = torch.nextafter(tensors["conv1.0.bias"][3], torch.tensor(1.0))
    problems = cc.check(str(out), tensors, {"inertialnet.model": "FlowNet2-S"})
    assert problems == ["conv1.0.bias: 1 element(s) differ bitwise"]


def test_mismatches_are_all_listed_with_exit_code_2(tmp_path):
    model = fn.build("FlowNet2-S")
    state = dict(model.state_dict())
    del state["deconv3.0.bias"], state["predict_flow2.weight"]
    state["conv1.0.weight"] = torch.zeros(64, 12, 7, 7)
    state["upsampled_flow6_to_5.bias"] = torch.zeros(2)
    path = tmp_path / "bad.pth.tar"
    torch.save({"epoch": 0, "state_dict": state, "best_EPE": 0.0}, path)
    r = _cli(path, tmp_path / "bad.safetensors")
    assert r.returncode == 2
    assert "missing 2 tensor(s): deconv3.0.bias, predict_flow2.weight" in r.stderr
    assert "1 unexpected tensor(s): upsampled_flow6_to_5.bias" in r.stderr
    assert "conv1.0.weight: file [64,12,7,7], model [64,6,7,7]" in r.stderr
    assert not (tmp_path / "bad.safetensors").exists()


def test_head_round_trip_with_hyper_parameters(tmp_path):
    cfg = hd.HeadConfig(input_height=30, input_width=38, conv1_channels=8, fc1_units=32)
    model = hd.InertialNetHead(cfg)
    sy.fill_synthetic(model, 9)
    src = tmp_path / "head.pth"
    torch.save(model.state_dict(), src)
    out = tmp_path / "head.safetensors"
    r = _cli(src, out, "--head-input", "38x30", "--head-dropout", "0.25", "--check")
    assert r.returncode == 0, r.stderr
    tensors, meta = _read(out)
    assert meta["inertialnet.model"] == "InertialNetHead"
    stored = json.loads(meta["inertialnet.head"])
    assert stored["input_width"] == 38 and stored["input_height"] == 30
    assert stored["conv1_channels"] == 8 and stored["fc1_units"] == 32
    assert stored["dropout"] == 0.25 and stored["conv3_channels"] == 8
    for k, v in model.state_dict().items():
        assert torch.equal(tensors[k], v), k


def test_bare_head_state_dict_and_wrong_input_size(tmp_path):
    model = hd.InertialNetHead(hd.HeadConfig(input_height=24, input_width=32))
    bare = {k[len("head."):]: v for k, v in model.state_dict().items()}
    src = tmp_path / "bare.pth"
    torch.save(bare, src)
    assert _cli(src, tmp_path / "a.safetensors").returncode == 2  # no input size given
    r = _cli(src, tmp_path / "b.safetensors", "--head-input", "40x24")
    assert r.returncode == 2 and "head.fc1.weight: file [128,384], model [128,480]" in r.stderr
    assert _cli(src, tmp_path / "c.safetensors", "--head-input", "32x24").returncode == 0


def test_kind_detection_from_names():
    for kind in fn.MODELS:
        names = list(fn.expected_shapes(kind))
        assert cc.detect_kind(names) == kind
    assert cc.detect_kind(hd.expected_shapes(hd.HeadConfig())) == "InertialNetHead"
    with pytest.raises(cc.InputError):
        cc.detect_kind(["foo.weight"])


def test_data_parallel_prefix_is_stripped(tmp_path):
    model = hd.InertialNetHead(hd.HeadConfig(input_height=24, input_width=32))
    src = tmp_path / "dp.pth"
    torch.save({"state_dict": {"module." + k: v for k, v in model.state_dict().items()},
                "head_config": {"input_width": 32, "input_height": 24}}, src)
    assert cc.main([str(src), str(tmp_path / "dp.safetensors"), "-q", "--check"]) == 0


def test_usage_errors_and_help(tmp_path):
    assert _cli("--help").returncode == 0
    assert _cli().returncode == 2
    assert _cli(tmp_path / "none.pth.tar", tmp_path / "x.safetensors").returncode == 2
    junk = tmp_path / "junk.pth.tar"
    junk.write_bytes(b"not a checkpoint")
    r = _cli(junk, tmp_path / "x.safetensors")
    assert r.returncode == 2 and "junk.pth.tar" in r.stderr


def test_ptlflow_lightning_checkpoint_runs_the_same_network(tmp_path):
    """A Lightning checkpoint as ptlflow publishes them (torch's zip format, the state dict beside
    Lightning's keys), converted without torch, loads strictly into the reference network and
    gives the original network's flow bit for bit."""
    model = fn.build("FlowNet2-CS")
    sy.fill_synthetic(model, 11)
    src = tmp_path / "flownetcs-things-mine.ckpt"
    torch.save({"epoch": 0, "global_step": 0, "pytorch-lightning_version": "1.3.8",
                "state_dict": model.state_dict(), "hyper_parameters": {"div_flow": 20.0, "input_channels": 12}},
               src)
    out = tmp_path / "cs.safetensors"
    r = _cli(src, out, "--check")
    assert r.returncode == 0, r.stderr
    tensors, meta = _read(out)
    assert meta["inertialnet.checkpoint.layout"] == "ptlflow-lightning"
    assert meta["inertialnet.checkpoint.format"] == "torch-zip"
    converted = fn.build("FlowNet2-CS")
    converted.load_state_dict(tensors, strict=True)
    g = torch.Generator().manual_seed(0)
    frame1 = torch.rand(1, 3, 64, 128, generator=g) * 255
    frame2 = torch.roll(frame1, shifts=(2, 3), dims=(2, 3))
    with torch.no_grad():
        want = model(frame1, frame2)["flow"]
        got = converted(frame1, frame2)["flow"]
    assert torch.equal(got, want)
