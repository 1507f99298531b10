# SPDX-License-Identifier: Apache-2.0
"""inertialnet.stream(): pair by pair, the numbers of predict() in its order; live sources (a
GStreamer pipeline) as they come; Ctrl-C raises KeyboardInterrupt on a source that never ends."""
import math
import signal
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import inertialnet

# A never-ending live source (is-live=true: frames at 20 Hz for ever, as from a camera); the
# colour bars move sideways, so that pairs have texture and motion.
ENDLESS = ("gst:videotestsrc is-live=true pattern=smpte horizontal-speed=2 ! video/x-raw,width=96,height=64,"
           "framerate=20/1 ! videoconvert ! appsink")


def test_stream_yields_predicts_rates_pair_by_pair(sequence):
    want = inertialnet.predict(sequence)
    got = list(inertialnet.stream(sequence))
    assert len(got) == len(want) == 4
    assert any(status == "ok" for _, _, status in got), "no pair answered: the comparison would prove nothing"
    for k, (t, rates, status) in enumerate(got):
        assert t == want.timestamps_ns[k]
        assert status == want.status[k]
        assert rates.dtype == np.float64 and rates.shape == (3,)
        for value, expected in zip(rates, want.w[k]):
            assert (math.isnan(value) and math.isnan(expected)) or value == expected


def test_stream_stops_at_max_pairs_and_says_bad_arguments(sequence):
    assert [t for t, _, _ in inertialnet.stream(sequence, max_pairs=2)] == \
        list(inertialnet.predict(sequence, max_pairs=2).timestamps_ns)
    with pytest.raises(ValueError, match="max_pairs must be a count"):
        inertialnet.stream(sequence, max_pairs=-1)
    with pytest.raises(ValueError, match="no camera at /dev/video97"):
        inertialnet.stream("/dev/video97", fx=80)


def test_stream_of_a_live_pipeline_comes_pair_by_pair():
    pairs = list(inertialnet.stream(
        "gst:videotestsrc num-buffers=5 pattern=smpte horizontal-speed=2 ! video/x-raw,width=96,height=64,"
        "framerate=20/1 ! videoconvert ! appsink", fx=80, max_sigma=0))  # bars sliding sideways: σ up to
    assert len(pairs) == 4                                             # ≈6 deg/s, above --max-sigma's 5
    stamps = [t for t, _, _ in pairs]
    assert stamps == sorted(set(stamps))  # the capture clock's times, increasing
    assert all(status == "ok" for _, _, status in pairs), pairs


def test_ctrl_c_stops_a_never_ending_stream():
    # In a child, so that a KeyboardInterrupt arriving late cannot reach pytest; it sets Python's
    # SIGINT handler itself (a process started with SIGINT ignored would keep ignoring it).
    body = textwrap.dedent("""
        import signal, sys
        import inertialnet
        signal.signal(signal.SIGINT, signal.default_int_handler)
        try:
            for t, rates, status in inertialnet.stream(sys.argv[1], fx=80):
                print("pair", t, status, flush=True)
        except KeyboardInterrupt:
            print("KeyboardInterrupt", flush=True)
        """)
    child = subprocess.Popen([sys.executable, "-c", body, ENDLESS], stdout=subprocess.PIPE,
                             stderr=subprocess.STDOUT, text=True)
    lines, sent = [], False
    try:
        for line in child.stdout:
            lines.append(line.strip())
            if not sent and sum(x.startswith("pair") for x in lines) >= 3:
                child.send_signal(signal.SIGINT)
                sent = True
    finally:
        child.wait(timeout=120)
    assert sent, "the stream gave fewer than 3 pairs:\n" + "\n".join(lines)
    assert lines[-1] == "KeyboardInterrupt", "\n".join(lines)
    assert child.returncode == 0
