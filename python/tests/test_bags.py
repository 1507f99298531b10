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
