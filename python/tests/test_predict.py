# SPDX-License-Identifier: Apache-2.0
"""Acceptance: Python computes the numbers of the command line.

DIS flow + the geometric head, through predict() and step by step through dis_flow() and
GeometricHead.rates(), against `inertialnet predict`'s CSV; evaluate() against `inertialnet eval
--json`; `inertialnet flow --flow dis` against dis_flow()."""
import json

import numpy as np
import pytest

import inertialnet
from conftest import csv_text, read_rates_csv


def cli_rates(cli, sequence, tmp_path, *args):
    out = tmp_path / "rates.csv"
    cli("predict", sequence, "-o", out, *args)
    return read_rates_csv(out)


def test_predict_matches_the_cli(cli, sequence, tmp_path):
    header, expected = cli_rates(cli, sequence, tmp_path)
    rates = inertialnet.predict(sequence)
    assert rates.columns == header == ["timestamp_ns", "wx", "wy", "wz", "status", "sigma_wx", "sigma_wy", "sigma_wz"]
    assert len(rates) == len(expected) == 4
    np.testing.assert_array_equal(rates["timestamp_ns"], expected[:, 0].astype(np.int64))
    assert list(rates["status"]) == ["ok"] * 4
    for i, name in enumerate(header[1:], start=1):
        # The CSV holds %.9g: the same doubles, printed to 9 significant digits.
        assert [csv_text(v) for v in rates[name]] == [csv_text(v) for v in expected[:, i]]


def test_predict_flow_lk_matches_the_cli(cli, sequence, tmp_path):
    """flow="lk" is --flow lk: the same rates, to the digit, and not DIS's."""
    header, expected = cli_rates(cli, sequence, tmp_path, "--flow", "lk")
    rates = inertialnet.predict(sequence, flow="lk")
    assert rates.columns == header and len(rates) == len(expected) == 4
    for i, name in enumerate(header[1:4], start=1):
        assert [csv_text(v) for v in rates[name]] == [csv_text(v) for v in expected[:, i]]
    dis = inertialnet.predict(sequence, flow="dis")
    assert not np.array_equal(dis.w, rates.w)
    with pytest.raises(ValueError, match="expected flownet2, dis, dis-fine or lk"):
        inertialnet.predict(sequence, flow="sparse")


@pytest.mark.parametrize("method", ["dis", "dis-fine"])
def test_dis_flow_and_geometric_head_step_by_step_match_the_cli(cli, sequence, tmp_path, method):
    # pair by pair: the two-frame rates; DIS named (the weight-free default is Lucas-Kanade); with
    # dis-fine, predict's geometric head leaves out its edge band as dis_flow(edge_band=True) does
    _, expected = cli_rates(cli, sequence, tmp_path, "--smooth", "off", "--flow", method)
    seq = inertialnet.Sequence(sequence)
    camera, to_body, t = seq.camera, seq.camera_to_body, seq.timestamps_ns
    assert camera.width == 128 and to_body.shape == (3, 3)
    head = inertialnet.GeometricHead()
    for k in range(1, len(seq)):
        flow = inertialnet.dis_flow(seq[k - 1], seq[k], flow_check=0.5, method=method, edge_band=True)  # what predict fits
        assert flow.shape == (96, 128, 2) and flow.dtype == np.float32
        w = head.rates(flow, camera, dt=(t[k] - t[k - 1]) * 1e-9, camera_to_body=to_body)
        assert [csv_text(v) for v in w] == [csv_text(v) for v in expected[k - 1, 1:4]]


def test_cli_flow_dis_matches_dis_flow_bit_for_bit(cli, sequence, tmp_path):
    frames = sorted((sequence / "mav0" / "cam0" / "data").glob("*.png"))
    cli("flow", frames[0], frames[1], "-o", tmp_path / "dis.flo")
    from_cli = inertialnet.read_flo(tmp_path / "dis.flo")
    ours = inertialnet.dis_flow(inertialnet.read_image(frames[0]), inertialnet.read_image(frames[1]))
    np.testing.assert_array_equal(ours.view(np.uint32), from_cli.view(np.uint32))
    # BGR input with order="bgr" and gray input give the same field (gray frames are replicated).
    bgr = inertialnet.dis_flow(inertialnet.read_image(frames[0])[..., ::-1], inertialnet.read_image(frames[1])[..., ::-1],
                               order="bgr")
    np.testing.assert_array_equal(bgr, ours)
    batch = inertialnet.dis_flow(np.stack([inertialnet.read_image(f) for f in frames[:2]]),
                                 np.stack([inertialnet.read_image(f) for f in frames[1:3]]))
    assert batch.shape == (2, 96, 128, 2)
    np.testing.assert_array_equal(batch[0], ours)


def test_cli_flow_dis_fine_matches_dis_flow_method_dis_fine(cli, sequence, tmp_path):
    """Issue 23: the fine DIS (a recipe v3 head's flow) from Python is the CLI's, and another field
    than the MEDIUM preset's."""
    frames = sorted((sequence / "mav0" / "cam0" / "data").glob("*.png"))
    cli("flow", frames[0], frames[1], "--flow", "dis-fine", "-o", tmp_path / "fine.flo")
    from_cli = inertialnet.read_flo(tmp_path / "fine.flo")
    a, b = inertialnet.read_image(frames[0]), inertialnet.read_image(frames[1])
    fine = inertialnet.dis_flow(a, b, method="dis-fine")
    np.testing.assert_array_equal(fine.view(np.uint32), from_cli.view(np.uint32))
    assert not np.array_equal(fine, inertialnet.dis_flow(a, b))
    for method in ("farneback", "", "lk", "flownet2"):
        with pytest.raises(ValueError, match=f"method '{method}': expected dis or dis-fine"):
            inertialnet.dis_flow(a, b, method=method)


def test_save_flow_matches_keep_flow(cli, sequence, tmp_path):
    cli("predict", sequence, "-o", tmp_path / "r.csv", "--save-flow", tmp_path / "flows")
    rates, flows = inertialnet.predict(sequence, keep_flow=True, max_pairs=2)
    assert len(rates) == len(flows) == 2
    for t, flow in zip(rates["timestamp_ns"], flows):
        np.testing.assert_array_equal(flow, inertialnet.read_flo(tmp_path / "flows" / f"{t}.flo"))


def test_evaluate_matches_cli_eval_json(cli, sequence, tmp_path):
    header, _ = cli_rates(cli, sequence, tmp_path)
    from_cli = json.loads(cli("eval", tmp_path / "rates.csv", sequence, "--json", stdout_only=True))
    report = inertialnet.evaluate(tmp_path / "rates.csv", sequence)
    assert report == from_cli
    # From predict()'s array, through the same CSV writer: the same metrics.
    # An array states no estimator, so the target is named: the one the CLI chose from the CSV.
    # The rates state their estimator, as the CSV does: the same target is chosen.
    from_array = inertialnet.evaluate(inertialnet.predict(sequence), sequence)
    assert from_array["estimators"][0]["target"] == report["estimators"][0]["target"]
    assert from_array["estimators"][0]["bias_corrected"] == report["estimators"][0]["bias_corrected"]


def test_errors_map_to_python_exceptions_with_the_cli_messages(cli, sequence, tmp_path):
    message = cli("predict", sequence, "--head", "inertialnet", expect=2)
    with pytest.raises(ValueError) as error:
        inertialnet.predict(sequence, head="inertialnet")
    # The CLI's message, with the keyword arguments where it names its options.
    assert "--flow flownet2 and --head inertialnet need weights: --weights FILE" in message
    assert 'flow="flownet2" and head="inertialnet" need weights: weights=FILE' in str(error.value)
    assert "--" not in str(error.value).split("`")[0]
    with pytest.raises(ValueError, match="nosuch"):
        inertialnet.Device("nosuch")
    with pytest.raises(FileNotFoundError, match="weights file does not exist"):
        inertialnet.FlowNet2.load(tmp_path / "missing.safetensors")
    with pytest.raises(FileNotFoundError, match="sequence does not exist"):
        inertialnet.predict(tmp_path / "missing")
    with pytest.raises(ValueError, match="uint8"):
        inertialnet.dis_flow(np.zeros((32, 32), np.int32), np.zeros((32, 32), np.int32))
    with pytest.raises(ValueError, match="at least 16x16"):
        inertialnet.dis_flow(np.zeros((8, 8), np.uint8), np.zeros((8, 8), np.uint8))


def test_devices_and_selection():
    devices = inertialnet.devices()
    assert devices and {"index", "address", "name", "platform", "type"} <= set(devices[0])
    assert inertialnet.select_devices("0")[0]["index"] == 0
    assert inertialnet.Device("0").name == devices[0]["name"]


def test_a_frame_without_texture_costs_its_pairs_not_the_run(cli, tmp_path):
    """Every pair has a row: a uniform frame makes its two pairs `no_texture` with NaN rates, as
    in the CLI's CSV, and evaluate() leaves them out (it used to end predict() with an error)."""
    out = tmp_path / "flat"
    assert inertialnet.synth(out, frames=6, width=128, height=96, seed=7) == 6
    frames = sorted((out / "mav0" / "cam0" / "data").glob("*.png"))
    # A binary PGM under the PNG's name: OpenCV reads an image by its content.
    frames[3].write_bytes(b"P5\n128 96\n255\n" + bytes([128]) * (128 * 96))
    rates = inertialnet.predict(out)
    assert len(rates) == 5
    assert list(rates["status"]) == ["ok", "ok", "no_texture", "no_texture", "ok"]
    assert np.isnan(rates["wx"][2:4]).all() and np.isfinite(rates["wx"][[0, 1, 4]]).all()
    header, expected = cli_rates(cli, out, tmp_path)
    assert list(expected[:, header.index("status")]) == list(rates["status"])
    report = inertialnet.evaluate(rates, out)["estimators"][0]
    assert report["rows_not_ok"] == 2 and report["not_ok_by_status"] == {"no_texture": 2}
    assert report["frames_evaluated"] == 3
