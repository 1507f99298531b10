# SPDX-License-Identifier: Apache-2.0
"""ROS 2 bags as a Sequence, in both rosbag2 storages and in each form a user has them (the bag
folder, its .db3 or .mcap file): the frames and header stamps of the EuRoC folder they were written
from (by tests/support/write_bag.py with PyPI rosbags). Damaged bags are a ValueError naming them."""
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


@pytest.mark.parametrize("storage, suffix, kind", [("sqlite3", ".db3", "(sqlite3)"), ("mcap", ".mcap", "(MCAP)")])
def test_a_ros2_bag_reads_as_its_euroc_folder(sequence, tmp_path, storage, suffix, kind):
    folder_bag = tmp_path / storage
    write_bag(sequence, folder_bag, "--storage", storage, "--encoding", "rgb8", "--camera-info")
    (storage_file,) = folder_bag.glob("*" + suffix)
    folder = inertialnet.Sequence(sequence)
    for path in (folder_bag, storage_file):
        from_bag = inertialnet.Sequence(path, image_topic="/cam0/image_raw")
        assert len(from_bag) == len(folder) == 5
        np.testing.assert_array_equal(from_bag.timestamps_ns, folder.timestamps_ns)  # header stamps
        for i in range(len(folder)):
            np.testing.assert_array_equal(from_bag[i], folder[i])
        assert from_bag.camera is not None and from_bag.camera.fx == folder.camera.fx
        assert "ROS 2 bag" in from_bag.description and kind in from_bag.description


def test_a_cut_mcap_file_is_a_value_error_naming_it(sequence, tmp_path):
    write_bag(sequence, tmp_path / "bag", "--storage", "mcap")
    (storage_file,) = (tmp_path / "bag").glob("*.mcap")
    data = storage_file.read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[:len(data) // 2])
    with pytest.raises(ValueError, match=r'The MCAP file ".*cut\.mcap" is damaged'):
        inertialnet.Sequence(cut, image_topic="/cam0/image_raw")
