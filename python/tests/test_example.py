# SPDX-License-Identifier: Apache-2.0
"""The example script runs as documented."""
import pathlib
import subprocess
import sys

EXAMPLE = pathlib.Path(__file__).resolve().parents[2] / "examples" / "flow_and_rates.py"


def test_example_script_runs(tmp_path):
    done = subprocess.run([sys.executable, str(EXAMPLE), str(tmp_path)], capture_output=True, text=True)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "predict() agrees with the loop: True" in done.stdout
    for name in ("last.flo", "last_kitti.png", "last_color.png"):
        assert (tmp_path / name).exists()
