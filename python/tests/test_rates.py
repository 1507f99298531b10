# SPDX-License-Identifier: Apache-2.0
"""Rates carry what the CLI's rates CSV states, so that evaluate() gives `inertialnet eval`'s numbers.

predict() used to return a bare structured array: evaluate() then assumed the spline target and
the body frame, and the README's example gave 3.60/2.96/1.83 deg/s where `inertialnet eval` on the
CLI's CSV gave 0.093/0.064/0.051."""
import json
import pathlib
import re

import numpy as np
import pytest

import inertialnet

README = pathlib.Path(__file__).resolve().parents[2] / "README.md"


def readme_example():
    """The statements of the README's Python example up to evaluate(): the block after `## Python`."""
    text = README.read_text()
    block = re.search(r"## Python\n.*?```python\n(.*?)```", text, re.S).group(1)
    lines = block.splitlines()
    end = next(i for i, line in enumerate(lines) if "inertialnet.evaluate(" in line)
    return "\n".join(lines[:end + 1])


def rmse(report, key="bias_corrected"):
    return [report["estimators"][0][key]["rmse_deg_s"][a] for a in "xyz"]


def test_readme_example_gives_the_numbers_of_cli_eval(cli, sequence, tmp_path):
    code = readme_example()
    assert '"data/synthetic-rotation"' in code
    # The README's sequence is the 40-frame default; the same code on the small test sequence.
    scope = {}
    exec(code.replace('"data/synthetic-rotation"', repr(str(sequence))), scope)
    cli("predict", sequence, "-o", tmp_path / "rates.csv")
    expected = json.loads(cli("eval", tmp_path / "rates.csv", sequence, "--json", stdout_only=True))
    report = scope["report"]
    assert report["estimators"][0]["target"] == expected["estimators"][0]["target"] == "mean"
    for key in ("raw", "bias_corrected"):
        np.testing.assert_allclose(rmse(report, key), rmse(expected, key), rtol=1e-9)
    assert report["estimators"][0]["rates_frame"] == "body"


def test_rates_state_estimator_frame_and_times(sequence):
    rates = inertialnet.predict(sequence, time_offset=0.004, readout_time=0.02)
    assert isinstance(rates, inertialnet.Rates) and len(rates) == 4
    assert rates.estimator == "inter_frame" and rates.frame == "body"
    assert rates.time_offset_s == 0.004 and rates.readout_time_s == 0.02
    assert rates.w.shape == (4, 3) and rates.w.dtype == np.float64
    np.testing.assert_array_equal(np.asarray(rates), rates.w)
    np.testing.assert_array_equal(rates.w[:, 1], rates["wy"])
    assert rates.timestamps_ns.dtype == np.int64 and list(rates.status) == ["ok"] * 4
    assert rates.columns == ["timestamp_ns", "wx", "wy", "wz", "status", "sigma_wx", "sigma_wy", "sigma_wz"]
    assert "estimator=inter_frame" in repr(rates) and "4 pairs" in repr(rates)
    # Rows keep the metadata; a row is a dict.
    assert rates[1:3].frame == "body" and len(rates[rates.ok]) == 4
    assert rates[0]["timestamp_ns"] == rates.timestamps_ns[0]


def test_evaluate_uses_the_time_offset_the_rates_state(cli, sequence, tmp_path):
    """A time offset and readout time given to predict() reach evaluate() as eval reads them from
    the CSV of `predict --time-offset --readout-time`."""
    args = ("--time-offset", "0.004", "--readout-time", "0.02")
    cli("predict", sequence, "-o", tmp_path / "rates.csv", *args)
    expected = json.loads(cli("eval", tmp_path / "rates.csv", sequence, "--json", stdout_only=True))
    report = inertialnet.evaluate(inertialnet.predict(sequence, time_offset=0.004, readout_time=0.02), sequence)
    assert report["estimators"][0]["time_offset_s"] == pytest.approx(0.014)
    np.testing.assert_allclose(rmse(report), rmse(expected), rtol=1e-9)
    # The evaluate() keywords override them, as eval's options override the CSV's.
    overridden = json.loads(cli("eval", tmp_path / "rates.csv", sequence, "--json", "--time-offset", "0",
                                "--readout-time", "0", stdout_only=True))
    report = inertialnet.evaluate(tmp_path / "rates.csv", sequence, time_offset=0.0, readout_time=0.0)
    assert report["estimators"][0]["time_offset_s"] == 0
    np.testing.assert_allclose(rmse(report), rmse(overridden), rtol=1e-9)


def test_csv_round_trip_keeps_rows_and_metadata(cli, sequence, tmp_path):
    rates = inertialnet.predict(sequence, time_offset=-0.01)
    rates.to_csv(tmp_path / "mine.csv")
    back = inertialnet.read_rates(tmp_path / "mine.csv")
    assert back.metadata["time_offset_s"] == "-0.01" and back.estimator == "inter_frame"
    np.testing.assert_array_equal(back.timestamps_ns, rates.timestamps_ns)
    np.testing.assert_allclose(back.w, rates.w, rtol=1e-8)  # %.9g in the file
    # The CLI's file reads the same.
    cli("predict", sequence, "-o", tmp_path / "cli.csv", "--time-offset", "-0.01")
    from_cli = inertialnet.read_rates(tmp_path / "cli.csv")
    assert from_cli.metadata == back.metadata
    np.testing.assert_array_equal(from_cli.w, back.w)


def test_evaluate_takes_imu_and_extrinsics_for_a_folder_as_eval_does(cli, sequence, tmp_path):
    """An image folder with a gyro log beside it, the rotation given as a 4x4 matrix: the same
    numbers as `eval --imu --T-cam-imu`, and errors that name keywords, not CLI flags."""
    folder = sequence / "mav0" / "cam0" / "data"
    imu = sequence / "mav0" / "imu0" / "data.csv"
    seq = inertialnet.Sequence(sequence)
    T = np.eye(4)
    T[:3, :3] = seq.camera_to_body.T  # body (IMU) to camera
    text = " ".join(repr(float(v)) for v in T.ravel())
    camera = seq.camera
    intrinsics = dict(fx=camera.fx, fy=camera.fy, cx=camera.cx, cy=camera.cy)
    cli("predict", folder, "-o", tmp_path / "rates.csv", "--fx", camera.fx, "--fy", camera.fy, "--cx", camera.cx,
        "--cy", camera.cy)
    expected = json.loads(cli("eval", tmp_path / "rates.csv", folder, "--imu", imu, "--T-cam-imu", text, "--json",
                              stdout_only=True))
    rates = inertialnet.predict(folder, **intrinsics)
    report = inertialnet.evaluate(rates, folder, imu=imu, T_cam_imu=T)
    np.testing.assert_allclose(rmse(report, "raw"), rmse(expected, "raw"), rtol=1e-9)
    with pytest.raises(ValueError) as error:
        inertialnet.evaluate(rates, folder)
    assert "--" not in str(error.value) and "imu=" in str(error.value) and "T_cam_imu=" in str(error.value)
    with pytest.raises(FileNotFoundError):
        inertialnet.evaluate(rates, folder, imu=tmp_path / "missing.csv")
    with pytest.raises(ValueError, match="time_offset must be a number of seconds or \"auto\""):
        inertialnet.evaluate(rates, sequence, time_offset="soon")
    with pytest.raises(ValueError, match="readout_time must be a finite number of seconds, got nan"):
        inertialnet.evaluate(rates, sequence, readout_time=float("nan"))


def test_an_old_structured_array_still_evaluates(sequence):
    records = inertialnet.predict(sequence).to_records()
    assert records.dtype.names == ("timestamp_ns", "wx", "wy", "wz", "status", "sigma_wx", "sigma_wy", "sigma_wz")
    report = inertialnet.evaluate(records, sequence, target="mean")
    assert report["estimators"][0]["frames_evaluated"] == 4


def test_calibration_file_for_a_folder_as_predict_and_eval_take_it(cli, sequence, tmp_path):
    """calibration= is --calibration: the frames as a plain image folder with the sequence's own
    sensor.yaml give the EuRoC folder's rates, in the body frame (its T_BS), and evaluate() with
    the IMU beside them the numbers of `eval --imu --calibration`."""
    folder = sequence / "mav0" / "cam0" / "data"
    yaml = sequence / "mav0" / "cam0" / "sensor.yaml"
    imu = sequence / "mav0" / "imu0" / "data.csv"
    rates = inertialnet.predict(folder, calibration=yaml)
    assert rates.frame == "body"
    np.testing.assert_array_equal(rates.w, inertialnet.predict(sequence).w)
    cli("predict", folder, "--calibration", yaml, "-o", tmp_path / "rates.csv")
    expected = json.loads(cli("eval", tmp_path / "rates.csv", folder, "--imu", imu, "--calibration", yaml, "--json",
                              stdout_only=True))
    report = inertialnet.evaluate(rates, folder, imu=imu, calibration=yaml)
    np.testing.assert_allclose(rmse(report, "raw"), rmse(expected, "raw"), rtol=1e-9)
    with pytest.raises(FileNotFoundError):
        inertialnet.predict(folder, calibration=tmp_path / "missing.yaml")


# Issue 22: each rate's σ, the --max-sigma limit and the smoother, as the CLI's keywords.
def test_sigma_max_sigma_and_smooth_as_predict_takes_them(cli, sequence, tmp_path):
    rates = inertialnet.predict(sequence, smooth="off")
    assert rates.sigma.shape == (4, 3) and np.all(np.isfinite(rates.sigma)) and np.all(rates.sigma > 0)
    np.testing.assert_array_equal(rates.sigma[:, 2], rates["sigma_wz"])
    # The CLI's CSV holds the same σ (to its %.9g digits).
    cli("predict", str(sequence), "--smooth", "off", "-o", str(tmp_path / "r.csv"))
    np.testing.assert_allclose(inertialnet.read_rates(tmp_path / "r.csv").sigma, rates.sigma, rtol=1e-7)
    # A limit below every σ: every pair is uncertain, its rates NaN, its σ kept.
    strict = inertialnet.predict(sequence, smooth="off", max_sigma=1e-6)
    assert list(strict.status) == ["uncertain"] * 4 and np.all(np.isnan(strict.w))
    np.testing.assert_array_equal(strict.sigma, rates.sigma)
    # The default smoother (lag 2) changes the rates and lowers σ; the metadata says so.
    smoothed = inertialnet.predict(sequence)
    assert smoothed.metadata.get("smoothing") == "lag:2,q:40" and "smoothing" not in rates.metadata
    assert np.all(smoothed.sigma <= rates.sigma) and not np.array_equal(smoothed.w, rates.w)
    with pytest.raises(ValueError, match="\"lag:x\": expected off"):
        inertialnet.predict(sequence, smooth="lag:x")
    with pytest.raises(ValueError, match="max.sigma.* must be a non-negative number"):
        inertialnet.predict(sequence, max_sigma=-1)
