# SPDX-License-Identifier: Apache-2.0
"""A ROS bag as a Sequence: the frames and header stamps of its image topic, as the same frames
given as a EuRoC folder (the bag written by tests/support/write_bag.py with PyPI rosbags)."""
import subprocess
import sys

import numpy as np
import pytest

import inertialnet
from conftest import REPO

pytest.importorskip("rosbags")


def write_bag(sequence, out, *options):
    subprocess.run([sys.executable, str(REPO / "tests" / "support" / "write_bag.py"), str(sequence), str(out), *options],
                   check=True)


def test_a_bag_reads_as_its_euroc_folder(sequence, tmp_path):
    bag = tmp_path / "rgb8.bag"
    write_bag(sequence, bag, "--encoding", "rgb8", "--camera-info", "--compression", "lz4")
    folder = inertialnet.Sequence(sequence)
    from_bag = inertialnet.Sequence(bag, image_topic="/cam0/image_raw")
    assert len(from_bag) == len(folder) == 5
    np.testing.assert_array_equal(from_bag.timestamps_ns, folder.timestamps_ns)  # header stamps, not log times
    for i in range(len(folder)):
        np.testing.assert_array_equal(from_bag[i], folder[i])
    assert from_bag.camera is not None and from_bag.camera.fx == folder.camera.fx
    assert from_bag.camera_to_body is None  # CameraInfo has no extrinsics
    assert "ROS 1 bag" in from_bag.description


def test_a_missing_topic_lists_the_bags_topics(sequence, tmp_path):
    bag = tmp_path / "mono8.bag"
    write_bag(sequence, bag)
    with pytest.raises(ValueError, match=r"has no topic /cam1/image_raw .*/cam0/image_raw \(sensor_msgs/Image, 5 messages\)"):
        inertialnet.Sequence(bag, image_topic="/cam1/image_raw")


def test_predict_and_evaluate_on_a_bag_give_the_euroc_folders_numbers(sequence, tmp_path):
    # predict(Sequence(bag, image_topic=…)) carries the topic; evaluate takes the bag's IMU topic
    # and its camera-IMU rotation as eval --imu-topic --T-cam-imu do.
    bag = tmp_path / "mono8.bag"
    write_bag(sequence, bag, "--camera-info")
    from_bag = inertialnet.predict(inertialnet.Sequence(bag, image_topic="/cam0/image_raw"))
    camera = inertialnet.Sequence(sequence).camera  # the synthetic camera has no distortion
    from_frames = inertialnet.predict(sequence / "mav0" / "cam0" / "data", fx=camera.fx, fy=camera.fy, cx=camera.cx,
                                      cy=camera.cy)
    assert from_bag.frame == from_frames.frame == "camera"  # a CameraInfo has no extrinsics
    np.testing.assert_array_equal(from_bag.w, from_frames.w)
    sensor = sequence / "mav0" / "cam0" / "sensor.yaml"
    on_bag = inertialnet.evaluate(from_bag, bag, image_topic="/cam0/image_raw", imu_topic="/imu0", T_cam_imu=sensor)
    on_folder = inertialnet.evaluate(inertialnet.predict(sequence), sequence)
    rmse = lambda report: report["estimators"][0]["raw"]["rmse_deg_s"]
    np.testing.assert_allclose([rmse(on_bag)[k] for k in "xyz"], [rmse(on_folder)[k] for k in "xyz"], atol=1e-5)


def test_evaluate_reads_a_gyro_csv_by_its_columns_and_units(sequence, tmp_path):
    # EuRoC's imu0 rewritten as seconds and deg/s, columns reordered among others: imu_columns and
    # imu_units (eval's --imu-columns and --imu-units) give the EuRoC folder's numbers.
    # Times as exact decimal seconds (through a float they would move by tens of nanoseconds, and
    # the first sample would fall after the first frame).
    lines = (sequence / "mav0" / "imu0" / "data.csv").read_text().splitlines()[1:]
    gyro = tmp_path / "gyro.csv"
    with open(gyro, "w") as f:
        f.write("temp,gz,stamp,gx,gy\n")
        for line in lines:
            t_ns, wx, wy, wz = line.split(",")[:4]
            t = int(t_ns)
            deg = [repr(float(np.degrees(float(v)))) for v in (wx, wy, wz)]
            f.write(f"21.5,{deg[2]},{t // 10**9}.{t % 10**9:09d},{deg[0]},{deg[1]}\n")
    frames = sequence / "mav0" / "cam0" / "data"
    sensor = sequence / "mav0" / "cam0" / "sensor.yaml"
    rates = inertialnet.predict(frames, calibration=sensor)
    by_columns = inertialnet.evaluate(rates, frames, imu=gyro, imu_columns="stamp,gx,gy,gz", imu_units=("s", "deg/s"),
                                      calibration=sensor)
    euroc = inertialnet.evaluate(rates, frames, imu=sequence / "mav0" / "imu0" / "data.csv", calibration=sensor)
    rmse = lambda report: report["estimators"][0]["raw"]["rmse_deg_s"]
    np.testing.assert_allclose([rmse(by_columns)[k] for k in "xyz"], [rmse(euroc)[k] for k in "xyz"], atol=1e-5)
    with pytest.raises(ValueError, match="imu_units"):
        inertialnet.evaluate(rates, frames, imu=gyro, imu_units="s,furlongs")
    with pytest.raises(ValueError, match="imu_columns must hold 4 values"):
        inertialnet.evaluate(rates, frames, imu=gyro, imu_columns=["stamp", "gx"])
