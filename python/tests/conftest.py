# SPDX-License-Identifier: Apache-2.0
"""Shared fixtures: a small synthetic sequence and the `inertialnet` command line to compare with.

The command line is $INERTIALNET_CLI, else build/inertialnet in the repository (what
tools/build.sh makes); the tests that compare with it are skipped, saying so, when neither exists.
"""
import csv
import os
import pathlib
import subprocess

import numpy as np
import pytest

import inertialnet

REPO = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def cli():
    path = os.environ.get("INERTIALNET_CLI") or str(REPO / "build" / "inertialnet")
    if not os.access(path, os.X_OK):
        pytest.skip(f"no inertialnet command line at {path} (set INERTIALNET_CLI)")

    def run(*args, cwd=None, expect=0, stdout_only=False):
        """Runs `inertialnet ARGS`, checks the exit code, returns stdout + stderr (or stdout)."""
        done = subprocess.run([path, *map(str, args)], cwd=cwd, capture_output=True, text=True)
        assert done.returncode == expect, f"inertialnet {' '.join(map(str, args))}: exit {done.returncode}\n{done.stdout}{done.stderr}"
        return done.stdout if stdout_only else done.stdout + done.stderr

    return run


@pytest.fixture(scope="session")
def sequence(tmp_path_factory):
    """A 5-frame 128x96 synthetic EuRoC sequence (rotation, EuRoC noise), written by the library."""
    out = tmp_path_factory.mktemp("seq") / "rotation"
    assert inertialnet.synth(out, frames=5, width=128, height=96, seed=7) == 5
    return out


@pytest.fixture(scope="session")
def video(tmp_path_factory):
    """clip.avi of tests/cli/make_test_video: 40 MJPEG frames of 188x120 at 20 Hz.

    The maker is $INERTIALNET_MAKE_TEST_VIDEO (set by ctest), else build/tests/cli/make_test_video;
    the tests that need it are skipped, saying so, when neither exists."""
    maker = os.environ.get("INERTIALNET_MAKE_TEST_VIDEO") or str(REPO / "build" / "tests" / "cli" / "make_test_video")
    if not os.access(maker, os.X_OK):
        pytest.skip(f"no make_test_video at {maker} (set INERTIALNET_MAKE_TEST_VIDEO)")
    folder = tmp_path_factory.mktemp("video")
    subprocess.run([maker, str(folder)], check=True, capture_output=True)
    return folder / "clip.avi"


def read_rates_csv(path):
    """The header and the rows of a rates CSV (schema inertialnet.rates/3, or 2): timestamps as int, the
    status columns as their words, rates as float (NaN where a pair has no answer: empty cells)."""
    with open(path) as f:
        rows = [r for r in csv.reader(f) if r and not r[0].startswith("#")]  # `# key: value` lines aside
    header, body = rows[0], rows[1:]
    status = [name == "status" or name.startswith("status_") for name in header]
    return header, np.array([[int(r[0])] + [v if status[i] else float(v or "nan") for i, v in enumerate(r) if i > 0]
                             for r in body], dtype=object)


def csv_text(value):
    """A cell as the rates CSV writes it: rates to 9 significant digits (%.9g), status words as they are."""
    return str(value) if isinstance(value, str) else "%.9g" % value
