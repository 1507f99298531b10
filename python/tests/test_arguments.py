# SPDX-License-Identifier: Apache-2.0
"""Bad arguments get readable Python errors, as the CLI's checks would give them: a matrix that is
no rotation, a flow the learned head cannot read, negative counts and indices, a negative rate,
exhausted memory. None of them is ignored, and none is answered with pybind11's list of overloads
or its raw "std::bad_alloc"."""
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import inertialnet


@pytest.fixture(scope="module")
def pair(sequence):
    seq = inertialnet.Sequence(sequence)
    return seq, inertialnet.dis_flow(seq[0], seq[1])


@pytest.mark.parametrize("matrix, message", [
    (np.full((3, 3), np.nan), "not orthonormal"),    # NaN rates before
    (np.zeros((3, 3)), "not orthonormal"),           # zero rates
    (2 * np.eye(3), "not orthonormal"),              # doubled rates
    (np.diag([1.0, 1.0, -1.0]), "reflection"),       # a mirror image: one axis turned round
    (np.eye(4), r"shape \(4, 4\)"),
    (np.eye(3).ravel(), r"shape \(9,\)"),
])
def test_camera_to_body_must_be_a_rotation(pair, matrix, message):
    seq, flow = pair
    head = inertialnet.GeometricHead()
    with pytest.raises(ValueError, match="camera_to_body .*" + message):
        head.rates(flow, seq.camera, 0.05, camera_to_body=matrix)


def test_camera_to_body_accepts_rotations(pair):
    seq, flow = pair
    head = inertialnet.GeometricHead()
    camera = head.rates(flow, seq.camera, 0.05)
    # The sequence's own calibration, and a rotation written to 6 decimals (as calibration files
    # hold them): the check's tolerance is the one sensor.yaml's T_BS passes.
    c, s = np.cos(0.3), np.sin(0.3)
    rounded = np.round(np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]), 6)
    np.testing.assert_allclose(head.rates(flow, seq.camera, 0.05, camera_to_body=rounded), rounded @ camera)
    assert np.isfinite(head.rates(flow, seq.camera, 0.05, camera_to_body=seq.camera_to_body)).all()


def test_geometric_head_leaves_out_nan_flow_vectors_as_unknown(pair):
    # NaN, infinity and values above 1e9 are the library's "unknown flow" (flow_io.hpp): the
    # geometric head skips such vectors, as it skips dis_flow's flow_check marks. Documented, not
    # an error.
    seq, flow = pair
    head = inertialnet.GeometricHead()
    marked, nan, inf = flow.copy(), flow.copy(), flow.copy()
    marked[40, 60] = 1e10
    nan[40, 60, 0] = np.nan
    inf[40, 60, 1] = np.inf
    expected = head.rates(marked, seq.camera, 0.05)
    assert np.isfinite(expected).all()
    np.testing.assert_array_equal(head.rates(nan, seq.camera, 0.05), expected)
    np.testing.assert_array_equal(head.rates(inf, seq.camera, 0.05), expected)


@pytest.fixture(scope="module")
def learned_head(cli, tmp_path_factory):
    weights = tmp_path_factory.mktemp("head") / "head.safetensors"
    cli("weights", "--synthetic", "InertialNetHead", "--size", "128x96", "-o", weights)
    return inertialnet.InertialNetHead.load(weights)


@pytest.mark.parametrize("value", [np.nan, np.inf, -np.inf, 1e10])
def test_learned_head_refuses_non_finite_flow_naming_the_index(pair, learned_head, value):
    _, flow = pair
    bad = flow.copy()
    bad[17, 42, 1] = value
    with pytest.raises(ValueError, match=r"flow\[17, 42\] = .* not a finite flow vector"):
        learned_head.rates(bad)
    batch = np.stack([flow, flow, bad])
    with pytest.raises(ValueError, match=r"flow\[2, 17, 42\]"):
        learned_head.rates(batch)
    assert np.isfinite(learned_head.rates(flow)).all()


def test_sequence_takes_python_indices(sequence):
    seq = inertialnet.Sequence(sequence)
    np.testing.assert_array_equal(seq[-1], seq[len(seq) - 1])
    np.testing.assert_array_equal(seq[-len(seq)], seq[0])
    np.testing.assert_array_equal(seq[np.int64(2)], seq[2])
    for index in (len(seq), -len(seq) - 1):
        with pytest.raises(IndexError, match=f"frame {index} is out of range: the sequence has {len(seq)} frames"):
            seq[index]
    with pytest.raises(TypeError, match="Sequence indices must be integers or slices, not float"):
        seq[1.5]


def test_negative_counts_are_value_errors(sequence, tmp_path):
    with pytest.raises(ValueError, match="device spec '-1' is not a device index"):
        inertialnet.Device(-1)
    assert inertialnet.Device(0).name == inertialnet.Device("0").name
    with pytest.raises(ValueError, match="device spec '-1' is not a device index"):
        inertialnet.predict(sequence, device=-1)
    assert len(inertialnet.predict(sequence, device=0, max_pairs=1)) == 1
    with pytest.raises(ValueError, match=r"max_pairs must be a count of pairs \(0 for all\), got -1"):
        inertialnet.predict(sequence, max_pairs=-1)
    with pytest.raises(ValueError, match="seed must be 0 or more, got -1"):
        inertialnet.synth(tmp_path / "seq", frames=2, width=64, height=48, seed=-1)


@pytest.mark.parametrize("name, value", [("rate_hz", -5), ("rate_hz", float("nan")), ("rate_hz", 1e7),
                                         ("fx", -458.0)])
def test_predict_refuses_what_the_cli_refuses(sequence, name, value):
    # Ignored before (a rate or focal length <= 0 read as "not given"); the CLI says --rate: must
    # be a finite positive number, got -5.
    with pytest.raises(ValueError, match=name + " must be"):
        inertialnet.predict(sequence, **{name: value})


def test_sequence_refuses_a_negative_rate(sequence):
    with pytest.raises(ValueError, match="rate_hz must be a finite positive number"):
        inertialnet.Sequence(sequence, rate_hz=-5)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc/self/status")
def test_out_of_memory_is_a_readable_memory_error():
    # A child whose address space is capped just above what it holds: converting a 4000x4000
    # frame (192 MB of floats) cannot be allocated. pybind11 alone said "std::bad_alloc".
    child = subprocess.run([sys.executable, "-c", textwrap.dedent("""
        import resource
        import numpy as np
        import inertialnet
        frame = np.zeros((4000, 4000), np.uint8)
        size_kb = next(int(l.split()[1]) for l in open("/proc/self/status") if l.startswith("VmSize:"))
        resource.setrlimit(resource.RLIMIT_AS, ((size_kb + 64 * 1024) * 1024, resource.RLIM_INFINITY))
        try:
            inertialnet.dis_flow(frame, frame)
        except MemoryError as e:
            print("MemoryError:", e)
        """)], capture_output=True, text=True, timeout=300)
    assert child.stdout.startswith("MemoryError: out of host memory"), child.stdout + child.stderr


@pytest.mark.parametrize("value", [1e300, -1.0, float("nan")])
def test_flow_check_is_bounded_and_named(sequence, value):
    # 1e300 switched the forward-backward check off silently (no upper bound); the message names
    # the keyword, not the library's "flow check threshold".
    with pytest.raises(ValueError, match=r"flow_check should be from 0 \(off\) to 1000 pixels"):
        inertialnet.predict(sequence, flow_check=value)
    a = np.zeros((48, 64, 3), np.uint8)
    with pytest.raises(ValueError, match=r"flow_check should be from 0 \(off\) to 1000 pixels"):
        inertialnet.dis_flow(a, a, flow_check=value)


@pytest.mark.parametrize("value", [float("nan"), 1e300, 2, None, "yes", []])
def test_edge_band_is_true_or_false(value):
    # pybind11's bool took NaN, 1e300 and 2 as True and None as False, and answered "yes" with its
    # list of overloads; the keyword is a yes/no, so anything but a bool is a TypeError naming it.
    a = np.zeros((48, 64, 3), np.uint8)
    with pytest.raises(TypeError, match="edge_band must be True or False, not "):
        inertialnet.dis_flow(a, a, method="dis-fine", edge_band=value)


def test_edge_band_takes_numpy_bools():
    a = (np.random.default_rng(5).random((48, 64)) * 255).astype(np.uint8)
    for yes, no in [(True, False), (np.True_, np.False_)]:
        assert np.isnan(inertialnet.dis_flow(a, a, method="dis-fine", edge_band=yes)).any()
        assert not np.isnan(inertialnet.dis_flow(a, a, method="dis-fine", edge_band=no)).any()


BAD_FLAGS = [float("nan"), 1e300, 2, None, "yes", []]


@pytest.mark.parametrize("value", BAD_FLAGS)
@pytest.mark.parametrize("keyword", ["keep_flow", "fuse"])
def test_predict_flags_are_true_or_false(sequence, keyword, value):
    # As edge_band: pybind11's bool read NaN, 1e300 and 2 as True and None as False.
    with pytest.raises(TypeError, match=keyword + " must be True or False, not "):
        inertialnet.predict(sequence, max_pairs=1, **{keyword: value})


@pytest.mark.parametrize("value", BAD_FLAGS)
@pytest.mark.parametrize("keyword", ["camera_frame", "series"])
def test_evaluate_flags_are_true_or_false(sequence, keyword, value):
    rates = inertialnet.predict(sequence, max_pairs=2)
    with pytest.raises(TypeError, match=keyword + " must be True or False, not "):
        inertialnet.evaluate(rates, sequence, **{keyword: value})
    assert inertialnet.evaluate(rates, sequence, **{keyword: np.True_})


@pytest.mark.parametrize("value", BAD_FLAGS)
def test_flow_to_color_legend_is_true_or_false(value):
    flow = np.zeros((48, 64, 2), np.float32)
    with pytest.raises(TypeError, match="legend must be True or False, not "):
        inertialnet.flow_to_color(flow, legend=value)
    assert inertialnet.flow_to_color(flow, legend=np.False_).shape == (48, 64, 3)


@pytest.mark.parametrize("value", BAD_FLAGS)
@pytest.mark.parametrize("keyword", ["noise", "overwrite"])
def test_synth_flags_are_true_or_false_and_leave_a_sequence_as_it_was(tmp_path, keyword, value):
    # overwrite=float("nan") was True: it replaced the sequence already there.
    out = tmp_path / "seq"
    assert inertialnet.synth(out, frames=2, width=64, height=48) == 2
    before = {p: p.read_bytes() for p in sorted(out.rglob("*")) if p.is_file()}
    with pytest.raises(TypeError, match=keyword + " must be True or False, not "):
        inertialnet.synth(out, frames=3, width=64, height=48, seed=2, **{keyword: value})
    assert {p: p.read_bytes() for p in sorted(out.rglob("*")) if p.is_file()} == before
