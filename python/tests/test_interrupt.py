# SPDX-License-Identifier: Apache-2.0
"""Long calls stop when asked: Ctrl-C raises KeyboardInterrupt within a pair or two instead of
after the whole run, and predict()'s progress callback reports and can stop the run.

The Ctrl-C tests send a real SIGINT to a child process, so that a KeyboardInterrupt that arrives
late cannot escape into pytest itself."""
import os
import signal
import subprocess
import sys
import textwrap

import pytest

import inertialnet

# The child sets Python's SIGINT handler itself: a process started with SIGINT ignored (a
# background job of a non-interactive shell, as under some CI runners) would otherwise keep
# ignoring it, and the test would measure the shell, not predict().
CHILD_PREAMBLE = """
import signal, sys
import numpy as np
import inertialnet
signal.signal(signal.SIGINT, signal.default_int_handler)
"""


def run_child(body, *args, send_sigint_when):
    """Runs CHILD_PREAMBLE + body with args; reads its stdout line by line and sends it SIGINT at
    the first line for which send_sigint_when(line) is true. Returns every line it printed."""
    child = subprocess.Popen([sys.executable, "-c", CHILD_PREAMBLE + textwrap.dedent(body), *map(str, args)],
                             stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    lines, sent = [], False
    try:
        for line in child.stdout:
            lines.append(line.strip())
            if not sent and send_sigint_when(lines[-1]):
                child.send_signal(signal.SIGINT)
                sent = True
    finally:
        child.wait(timeout=600)
    assert sent, "the child never got to the point of interruption:\n" + "\n".join(lines)
    return lines


@pytest.fixture(scope="module")
def long_sequence(tmp_path_factory):
    """300 frames: seconds of predict() on PoCL, so a run that ignored Ctrl-C would finish it."""
    out = tmp_path_factory.mktemp("long") / "rotation"
    assert inertialnet.synth(out, frames=300, width=128, height=96, seed=11) == 300
    return out


def test_ctrl_c_stops_predict_within_a_few_pairs(long_sequence):
    lines = run_child("""
        def progress(done, total):
            print("progress", done, total, flush=True)
        try:
            rates = inertialnet.predict(sys.argv[1], progress=progress)
            print("returned", len(rates), flush=True)
        except KeyboardInterrupt:
            print("KeyboardInterrupt", flush=True)
        """, long_sequence, send_sigint_when=lambda line: line.startswith("progress") and int(line.split()[1]) >= 2)
    assert lines[-1] == "KeyboardInterrupt", "\n".join(lines)
    reports = [tuple(map(int, line.split()[1:])) for line in lines if line.startswith("progress")]
    done, total = reports[-1]
    # Before the fix the run went on to the last of the 299 pairs and raised only then.
    assert total == 299 and done < total


def test_ctrl_c_stops_a_flownet_batch(cli, tmp_path):
    weights = tmp_path / "s.safetensors"
    cli("weights", "--synthetic", "FlowNet2-S", "-o", weights)
    # 24 pairs of 448x320 take seconds on PoCL; the child interrupts itself half a second into
    # the call. Whether the batch ran to its end shows in NumPy's allocations, which tracemalloc
    # sees: a finished call allocated its (24, 320, 448, 2) float32 result before the
    # KeyboardInterrupt (as before the fix, when the interrupt waited for the whole batch); a
    # stopped one never does.
    child = subprocess.run([sys.executable, "-c", CHILD_PREAMBLE + textwrap.dedent("""
        import os, threading, tracemalloc
        net = inertialnet.FlowNet.load(sys.argv[1])
        rng = np.random.default_rng(1)
        a = rng.integers(0, 255, (24, 320, 448, 3), dtype=np.uint8)
        b = np.roll(a, 2, axis=2)
        tracemalloc.start()
        threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT)).start()
        try:
            flow = net.flow(a, b)
            print("returned", flow.shape)
        except KeyboardInterrupt:
            print("KeyboardInterrupt", tracemalloc.get_traced_memory()[1])
        """), str(weights)], capture_output=True, text=True, timeout=600)
    words = child.stdout.split()
    assert words[:1] == ["KeyboardInterrupt"], child.stdout + child.stderr
    assert int(words[1]) < 24 * 320 * 448 * 2 * 4, "the batch ran to its end before the interrupt"


def test_progress_reports_every_pair_to_the_end(sequence):
    reports = []
    rates = inertialnet.predict(sequence, progress=lambda done, total: reports.append((done, total)))
    assert len(rates) == 4
    assert reports[-1] == (4, 4)
    assert all(total == 4 for _, total in reports)
    done = [d for d, _ in reports]
    assert done == sorted(set(done))  # each count once, rising


def test_an_exception_in_progress_stops_predict_and_propagates(long_sequence):
    class Enough(Exception):
        pass

    reports = []

    def progress(done, total):
        reports.append(done)
        if done >= 2:
            raise Enough(f"stopped at {done} of {total}")

    with pytest.raises(Enough, match="stopped at"):
        inertialnet.predict(long_sequence, progress=progress)
    # Called no more once it raised, and long before the last of the 299 pairs.
    assert [d for d in reports if d >= 2] == [reports[-1]] and reports[-1] < 299
    with pytest.raises(TypeError, match="progress must be a callable"):
        inertialnet.predict(long_sequence, progress=5)
