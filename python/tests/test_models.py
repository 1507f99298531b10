# SPDX-License-Identifier: Apache-2.0
"""The networks through Python: FlowNet2 (synthetic weights, small frames) against the CLI's .flo
bit for bit, batches, and the InertialNet head against `inertialnet predict`."""
import json

import numpy as np
import pytest

import inertialnet
from conftest import csv_text, read_rates_csv


@pytest.fixture(scope="module")
def frames(sequence):
    return sorted((sequence / "mav0" / "cam0" / "data").glob("*.png"))


@pytest.fixture(scope="module")
def flownet2_weights(cli, tmp_path_factory):
    path = tmp_path_factory.mktemp("weights") / "flownet2.safetensors"
    cli("weights", "--synthetic", "FlowNet2", "-o", path)
    return path


def test_flownet2_matches_the_cli_flo_bit_for_bit(cli, frames, flownet2_weights, tmp_path):
    cli("flow", frames[0], frames[1], "-w", flownet2_weights, "-o", tmp_path / "cli.flo")
    from_cli = inertialnet.read_flo(tmp_path / "cli.flo")
    net = inertialnet.FlowNet2.load(flownet2_weights)
    assert net.model == "FlowNet2" and net.synthetic
    flow = net.flow(inertialnet.read_image(frames[0]), inertialnet.read_image(frames[1]))
    assert flow.shape == (96, 128, 2) and flow.dtype == np.float32
    np.testing.assert_array_equal(flow.view(np.uint32), from_cli.view(np.uint32))


def test_flownet_takes_its_model_from_the_weights_and_refuses_others(flownet2_weights):
    assert inertialnet.FlowNet.load(flownet2_weights, device="0").model == "FlowNet2"
    with pytest.raises(ValueError, match="flownetc"):
        inertialnet.FlowNet2C.load(flownet2_weights)


def test_flownet_batches_and_gray_frames(cli, frames, tmp_path):
    weights = tmp_path / "c.safetensors"
    cli("weights", "--synthetic", "FlowNet2-C", "-o", weights)
    net = inertialnet.FlowNet2C.load(weights, device=inertialnet.Device())
    a = [inertialnet.read_image(f) for f in frames[:3]]
    single = [net.flow(a[i], a[i + 1]) for i in range(2)]
    batch = net.flow(np.stack(a[:2]), np.stack(a[1:3]))
    assert batch.shape == (2, 96, 128, 2)
    for i in range(2):
        np.testing.assert_allclose(batch[i], single[i], atol=1e-4)
    # Frames of a size that is no multiple of 64, gray: the flow keeps the frames' size.
    gray = [f[:70, :90, 0].copy() for f in a[:2]]
    assert net.flow(gray[0], gray[1]).shape == (70, 90, 2)


def test_inertialnet_head_matches_the_cli(cli, sequence, tmp_path):
    head_weights = tmp_path / "head.safetensors"
    cli("weights", "--synthetic", "InertialNetHead", "--size", "128x96", "-o", head_weights)
    cli("predict", sequence, "-w", head_weights, "--flow", "dis", "--head", "both", "-o", tmp_path / "rates.csv")
    header, expected = read_rates_csv(tmp_path / "rates.csv")
    rates = inertialnet.predict(sequence, head_weights, flow="dis", head="both")
    assert rates.columns == header
    # Each estimator keeps what the CSV states of it: the network's rates and the geometric head's.
    assert rates.heads == ["", "geometric"] and (rates.estimator, rates.frame) == ("network", "body")
    geometric = rates.head("geometric")
    assert (geometric.estimator, geometric.frame) == ("inter_frame", "body")
    np.testing.assert_array_equal(geometric.w[:, 0], rates["wx_geometric"])
    with pytest.raises(ValueError, match="no estimator 'nosuch'"):
        rates.head("nosuch")
    assert repr(inertialnet.InertialNetHead.load(head_weights)) == "<inertialnet.InertialNetHead 128x96>"
    for i, name in enumerate(header[1:], start=1):
        assert [csv_text(v) for v in rates[name]] == [csv_text(v) for v in expected[:, i]]
    head = inertialnet.InertialNetHead.load(head_weights)
    seq = inertialnet.Sequence(sequence)
    flows = np.stack([inertialnet.dis_flow(seq[k - 1], seq[k]) for k in range(1, len(seq))])
    w = head.rates(flows)
    assert w.shape == (len(seq) - 1, 3)
    np.testing.assert_allclose(w[:, 0], rates["wx"], rtol=1e-6, atol=1e-9)
    assert head.rates(flows[0]).shape == (3,)
    # A flow of another size is resized as predict and train do (issue 23; before: a ValueError):
    # a constant field stays constant, its vectors scaled by the size ratio (2 and 1.5 here).
    assert head.config["input"] == "paper" and head.config["flow"] == ""
    small = np.full((64, 64, 2), (0.5, -0.25), np.float32)
    np.testing.assert_allclose(head.rates(small), head.rates(np.full((96, 128, 2), (1.0, -0.375), np.float32)),
                               rtol=1e-5, atol=1e-7)


def with_metadata(source, target, key, value):
    """A copy of a safetensors file with one more __metadata__ entry (the format: an 8-byte
    little-endian header length, the JSON header, the data)."""
    data = source.read_bytes()
    n = int.from_bytes(data[:8], "little")
    header = json.loads(data[8:8 + n])
    header.setdefault("__metadata__", {})[key] = value
    text = json.dumps(header).encode()
    target.write_bytes(len(text).to_bytes(8, "little") + text + data[8 + n:])


def test_a_head_of_normalized_input_needs_camera_and_interval(cli, tmp_path):
    # Issue 23: the head's metadata says its input is the flow per second over the focal lengths;
    # rates() then divides as predict and train do, and refuses to guess dt or the camera.
    paper_file, normalized_file = tmp_path / "paper.safetensors", tmp_path / "normalized.safetensors"
    cli("weights", "--synthetic", "InertialNetHead", "--size", "32x24", "-o", paper_file)
    with_metadata(paper_file, normalized_file, "inertialnet.head_input", '{"convention":"normalized","flow":"dis"}')
    paper = inertialnet.InertialNetHead.load(paper_file)
    normalized = inertialnet.InertialNetHead.load(normalized_file)
    assert (normalized.config["input"], normalized.config["flow"]) == ("normalized", "dis")
    # Written without "frame" (before heads learned camera-frame rates): its training rig's body frame.
    assert paper.config["frame"] == "body" and normalized.config["frame"] == "body"
    camera_file = tmp_path / "camera.safetensors"
    with_metadata(paper_file, camera_file, "inertialnet.head_input",
                  '{"convention":"normalized","flow":"dis","frame":"camera"}')
    assert inertialnet.InertialNetHead.load(camera_file).config["frame"] == "camera"
    camera = inertialnet.Camera(64, 48, 40.0, 30.0, 31.5, 23.5)
    flow = np.full((48, 64, 2), (2.0, -1.2), np.float32)  # pixels at 64x48, 0.05 s apart
    # At 32x24 the vectors halve and so do the focal lengths: u/(fx·dt) = 2/(40·0.05) = 1.
    want = paper.rates(np.full((24, 32, 2), (1.0, -0.8), np.float32))
    np.testing.assert_allclose(normalized.rates(flow, camera=camera, dt=0.05), want, rtol=1e-5, atol=1e-7)
    with pytest.raises(ValueError, match="trained on normalized input.*camera=.*dt="):
        normalized.rates(flow)
    with pytest.raises(ValueError, match="trained on normalized input"):
        normalized.rates(flow, camera=camera)


def test_fused_estimator_matches_the_cli(cli, sequence, tmp_path):
    # predict(fuse=True) is predict --fuse (issue 23): a third estimator "fused" whose σ is at most
    # the smaller of the two heads' wherever both answer; the stream yields it last.
    head_weights = tmp_path / "head.safetensors"
    cli("weights", "--synthetic", "InertialNetHead", "--size", "128x96", "-o", head_weights)
    cli("predict", sequence, "-w", head_weights, "--flow", "dis", "--head", "both", "--fuse", "--smooth", "off",
        "-o", tmp_path / "rates.csv")
    header, expected = read_rates_csv(tmp_path / "rates.csv")
    rates = inertialnet.predict(sequence, head_weights, flow="dis", head="both", fuse=True, smooth="off")
    assert rates.columns == header and rates.heads == ["", "geometric", "fused"]
    for i, name in enumerate(header[1:], start=1):
        assert [csv_text(v) for v in rates[name]] == [csv_text(v) for v in expected[:, i]]
    fused = rates.head("fused")
    assert (fused.estimator, fused.frame) == ("inter_frame", "body")
    both = (rates.status == "ok") & (rates.head("geometric").status == "ok")
    assert both.any()
    assert np.all(fused.sigma[both] <= np.minimum(rates.sigma[both], rates.head("geometric").sigma[both]))
    stream = list(inertialnet.stream(sequence, head_weights, flow="dis", head="both", fuse=True, smooth="off"))
    assert stream[0][1].shape == (3, 3) and len(stream[0][2]) == 3
    np.testing.assert_array_equal(np.stack([s[1][2] for s in stream]), fused.w)


def test_a_head_ensemble_answers_its_members_mean(cli, sequence, tmp_path):
    # Issue 23: train --ensemble 2 writes two heads (seeds 1 and 2) and one ensemble file of both;
    # InertialNetHead.rates() on the ensemble is the members' mean, as predict reports it.
    out = tmp_path / "ens.safetensors"
    cli("train", "--train", sequence, "--val", sequence, "--head-size", "32x24", "--optimizer", "adam", "--lr", "1e-3",
        "--epochs", "1", "--ensemble", "2", "--cache", tmp_path / "cache", "-o", out)
    ensemble = inertialnet.InertialNetHead.load(out)
    members = [inertialnet.InertialNetHead.load(tmp_path / f"ens.member{k}.safetensors") for k in (0, 1)]
    assert ensemble.config["members"] == 2 and members[0].config["members"] == 1
    s = inertialnet.Sequence(sequence)
    flow = inertialnet.dis_flow(s[0], s[1])
    dt = float(s.timestamps_ns[1] - s.timestamps_ns[0]) * 1e-9
    got = ensemble.rates(flow, camera=s.camera, dt=dt)
    each = [m.rates(flow, camera=s.camera, dt=dt) for m in members]
    assert not np.array_equal(each[0], each[1])  # two seeds, two heads
    np.testing.assert_allclose(got, (each[0] + each[1]) / 2, rtol=1e-12, atol=0)
