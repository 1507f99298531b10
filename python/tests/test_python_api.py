# SPDX-License-Identifier: Apache-2.0
"""The package behaves as Python code expects: Sequence is a collections.abc.Sequence (videos
included), heads take the batches the flow functions return, float images in [0, 1] are images,
missing files are FileNotFoundError, colours come in either channel order, and every object has a
repr."""
import collections.abc

import numpy as np
import pytest

import inertialnet


def test_sequence_is_a_python_sequence(sequence):
    seq = inertialnet.Sequence(sequence)
    assert isinstance(seq, collections.abc.Sequence) and len(seq) == 5
    assert repr(seq) == f"<inertialnet.Sequence {str(sequence)!r}: 5 frames, {seq.description}>"
    frames = seq[1:4]
    assert isinstance(frames, list) and len(frames) == 3
    np.testing.assert_array_equal(frames[0], seq[1])
    np.testing.assert_array_equal(seq[::-2][0], seq[-1])
    assert seq[10:] == []
    assert [f.shape for f in seq] == [(96, 128, 3)] * 5
    np.testing.assert_array_equal(list(reversed(seq))[0], seq[4])
    with pytest.raises(IndexError):
        seq[5]
    with pytest.raises(TypeError, match="integers or slices, not str"):
        seq["0"]
    # Membership and search compare whole frames.
    assert seq[3] in seq and seq.index(seq[3]) == 3 and seq.count(seq[2]) == 1
    assert np.zeros((96, 128, 3), np.uint8) not in seq
    with pytest.raises(ValueError, match="not in the sequence"):
        seq.index(seq[3], 0, 2)
    # A Sequence is path-like: predict takes it.
    assert len(inertialnet.predict(seq, max_pairs=1)) == 1


def test_a_video_is_random_access(video):
    """A video decodes in order only (FrameSource::sequential); a step back opens it again, so any
    order gives the frames that in-order decoding gives."""
    seq = inertialnet.Sequence(video)
    assert seq.sequential and len(seq) == 40
    in_order = list(seq)[:6]
    seq = inertialnet.Sequence(video)
    for k in (5, 2, 2, 0, 4, -36):
        np.testing.assert_array_equal(seq[k], in_order[k % 40])
    np.testing.assert_array_equal(seq[3:0:-1][0], in_order[3])


def test_missing_files_are_file_not_found_errors(tmp_path):
    missing = tmp_path / "missing"
    for call in (lambda: inertialnet.Sequence(missing), lambda: inertialnet.read_image(missing),
                 lambda: inertialnet.read_flow(missing), lambda: inertialnet.read_rates(missing),
                 lambda: inertialnet.InertialNetHead.load(missing)):
        with pytest.raises(FileNotFoundError) as error:
            call()
        assert error.value.filename == str(missing)


def test_a_file_of_no_frame_format_is_a_value_error(tmp_path):
    # "DICM" at byte 128 once sent the bytes to OpenCV's DICOM decoder, whose assert ended the
    # interpreter; now they are refused before any decoder sees them.
    damaged = tmp_path / "frame.png"
    damaged.write_bytes(b"\x89PDO" + bytes(124) + b"DICM\x02\x00")
    with pytest.raises(ValueError, match=r"frame\.png.* cannot be decoded: it is a DICOM file"):
        inertialnet.read_image(damaged)


def test_geometric_head_takes_the_batches_dis_flow_returns(sequence):
    seq = inertialnet.Sequence(sequence)
    t = seq.timestamps_ns
    flows = inertialnet.dis_flow(np.stack(seq[0:3]), np.stack(seq[1:4]))
    assert flows.shape == (3, 96, 128, 2)
    head = inertialnet.GeometricHead()
    dts = np.diff(t[:4]) * 1e-9
    batch = head.rates(flows, seq.camera, dts, camera_to_body=seq.camera_to_body)
    assert batch.shape == (3, 3)
    for k in range(3):
        np.testing.assert_array_equal(batch[k], head.rates(flows[k], seq.camera, dts[k],
                                                           camera_to_body=seq.camera_to_body))
    np.testing.assert_array_equal(head.rates(flows, seq.camera, 0.05)[1], head.rates(flows[1], seq.camera, 0.05))
    with pytest.raises(ValueError, match=r"one per pair \(3\)"):
        head.rates(flows, seq.camera, [0.05, 0.05])
    assert repr(head).startswith("<inertialnet.GeometricHead motion-field stride 4 on ")


def test_float_images_in_0_1_are_images(sequence):
    seq = inertialnet.Sequence(sequence)
    a, b = seq[0], seq[1]
    expected = inertialnet.dis_flow(a, b)
    # float64 and float32 in [0, 1]: the same picture as uint8 (x / 255 · 255 rounds back exactly
    # for float64; float32 within DIS's tolerance of it).
    np.testing.assert_array_equal(inertialnet.dis_flow(a / 255.0, b / 255.0), expected)
    as_float32 = inertialnet.dis_flow((a / 255.0).astype(np.float32), (b / 255.0).astype(np.float32))
    assert np.nanmax(np.abs(as_float32 - expected)) < 0.05
    image = a / 255.0
    inertialnet.dis_flow(image, image)
    assert image.max() <= 1.0  # the caller's array is not scaled in place
    with pytest.raises(ValueError, match=r"img1 holds 1[0-9.]+: a float image must hold values in \[0, 1\]"):
        inertialnet.dis_flow(a.astype(np.float32), b.astype(np.float32))


def test_flow_to_color_in_bgr_order():
    flow = np.zeros((8, 8, 2), np.float32)
    flow[..., 0] = 3.0  # motion to the right: red
    rgb = inertialnet.flow_to_color(flow)
    bgr = inertialnet.flow_to_color(flow, order="bgr")
    np.testing.assert_array_equal(bgr, rgb[..., ::-1])
    assert rgb[0, 0, 0] == 255 and bgr[0, 0, 2] == 255
    with pytest.raises(ValueError, match="expected rgb or bgr"):
        inertialnet.flow_to_color(flow, order="hsv")


def test_devices_by_index_and_object_everywhere(sequence):
    device = inertialnet.Device(0)
    assert repr(device) == f"<inertialnet.Device {device.name}>"
    by_object = inertialnet.predict(sequence, device=device, max_pairs=1)
    np.testing.assert_array_equal(by_object.w, inertialnet.predict(sequence, device=0, max_pairs=1).w)
    assert repr(inertialnet.GeometricHead(device=0)).endswith(f"on {device.name}>")
    with pytest.raises(TypeError, match="device must be None, a device spec string, an index"):
        inertialnet.predict(sequence, device=0.5)
    # The native constructors answer as predict does: a bool is not a device index.
    for wrong in (0.5, True):
        with pytest.raises(TypeError, match="device must be None, a device spec string, an index"):
            inertialnet.GeometricHead(device=wrong)


def test_native_signatures_name_the_types_they_take():
    """help() shows what an argument must be: the native functions that check an argument
    themselves (True or False, an integer, a device, a rotation matrix) do not show it as object."""
    import re

    def signatures(obj):
        for name in dir(obj):
            if name.startswith("_") and name != "__init__":
                continue
            doc = getattr(getattr(obj, name), "__doc__", None) or ""
            yield from (f"{name}: {line}" for line in doc.splitlines() if re.match(r"\w+\(", line))

    native = inertialnet._native
    public = [native] + [getattr(native, n) for n in dir(native) if isinstance(getattr(native, n), type)
                         and not n.startswith("_")]
    lines = [line for obj in public for line in signatures(obj)]
    assert any(line.startswith("dis_flow: dis_flow(") for line in lines)
    assert [line for line in lines if re.search(r"\w: object\b", line)] == []
    assert "edge_band: bool = False" in next(line for line in lines if line.startswith("dis_flow:"))


def test_stubs_name_what_the_native_module_has():
    """_inertialnet.pyi lists the native module's functions and classes, and each of them exists
    (a renamed or removed binding fails here rather than in a user's type checker)."""
    import ast
    import pathlib

    stubs = ast.parse((pathlib.Path(inertialnet.__file__).parent / "_inertialnet.pyi").read_text())
    names = [node.name for node in stubs.body if isinstance(node, (ast.FunctionDef, ast.ClassDef))]
    assert "_Sequence" in names and "_read_rates_csv" in names
    assert [n for n in names if not hasattr(inertialnet._native, n)] == []
    for cls in (node for node in stubs.body if isinstance(node, ast.ClassDef)):
        for member in cls.body:
            if isinstance(member, ast.FunctionDef):
                assert hasattr(getattr(inertialnet._native, cls.name), member.name), (cls.name, member.name)
