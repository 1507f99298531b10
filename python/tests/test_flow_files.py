# SPDX-License-Identifier: Apache-2.0
"""Flow files and pictures: .flo and KITTI round trips, and the Middlebury colour convention of
flow_to_color and `inertialnet viz` checked against an independent NumPy implementation."""
import numpy as np
import pytest

import inertialnet


def radial_field(size=101, radius=None):
    """Each pixel's flow points from the centre to it, |flow| = distance / radius."""
    c = (size - 1) / 2
    y, x = np.mgrid[0:size, 0:size].astype(np.float32)
    r = radius or c
    return np.stack([(x - c) / r, (y - c) / r], axis=-1).astype(np.float32)


def middlebury_wheel():
    """Baker et al.'s colour wheel: 55 colours, RY 15, YG 6, GC 4, CB 11, BM 13, MR 6."""
    segments = [(15, lambda s: (255, s, 0)), (6, lambda s: (255 - s, 255, 0)), (4, lambda s: (0, 255, s)),
                (11, lambda s: (0, 255 - s, 255)), (13, lambda s: (s, 0, 255)), (6, lambda s: (255, 0, 255 - s))]
    wheel = []
    for n, colour in segments:
        wheel += [colour(255 * i // n) for i in range(n)]
    return np.array(wheel, dtype=np.float64)


def middlebury_color(u, v):
    """The reference computeColor() of the Middlebury flow code for one normalised vector."""
    wheel = middlebury_wheel()
    n = len(wheel)
    rad = np.hypot(u, v)
    a = np.arctan2(-v, -u) / np.pi
    fk = (a + 1) / 2 * (n - 1)
    k0 = int(np.floor(fk))
    k1 = (k0 + 1) % n
    f = fk - k0
    col = (1 - f) * wheel[k0] / 255 + f * wheel[k1] / 255
    col = 1 - rad * (1 - col) if rad <= 1 else col * 0.75
    return np.floor(255 * col)


ANGLES = [0, 30, 45, 60, 90, 120, 135, 180, 200, 225, 270, 300, 315]


def check_radial_picture(rgb, size):
    """The picture of radial_field(size) scaled so that the rim is the normalising radius."""
    c = (size - 1) / 2
    for degrees in ANGLES:
        t = np.radians(degrees)
        # Sample at 0.8 of the radius, at a pixel centre; the expected colour is of that pixel's own vector.
        x = int(round(c + 0.8 * c * np.cos(t)))
        y = int(round(c + 0.8 * c * np.sin(t)))
        u, v = (x - c) / c, (y - c) / c
        expected = middlebury_color(u, v)
        assert np.abs(rgb[y, x].astype(int) - expected).max() <= 1, (degrees, rgb[y, x], expected)
    # Named directions of the convention: right is red, down is yellowish, left blue-cyan, up violet.
    assert tuple(rgb[int(c), size - 1]) == (255, 0, 0)
    assert tuple(rgb[int(c), int(c)]) == (255, 255, 255)  # zero flow is white


def test_flow_to_color_follows_the_middlebury_wheel():
    size = 101
    flow = radial_field(size) * 7.0  # |flow| up to 7 px at the rim
    rgb = inertialnet.flow_to_color(flow, max_magnitude=7.0)
    assert rgb.shape == (size, size, 3) and rgb.dtype == np.uint8
    check_radial_picture(rgb, size)


def test_viz_writes_the_same_colours(cli, tmp_path):
    size = 101
    flow = radial_field(size) * 7.0
    inertialnet.write_flo(tmp_path / "radial.flo", flow)
    inertialnet.write_kitti_flow(tmp_path / "radial_kitti.png", flow)
    out = cli("viz", "radial.flo", "radial_kitti.png", "-o", "pics", "--max-magnitude", "7", cwd=tmp_path)
    assert "pics/radial_color.png" in out
    flo_picture = inertialnet.read_image(tmp_path / "pics" / "radial_color.png")
    check_radial_picture(flo_picture, size)
    np.testing.assert_array_equal(flo_picture, inertialnet.flow_to_color(flow, 7.0))
    # KITTI quantises to 1/64 px: colours within a level or two of the exact field's.
    kitti_picture = inertialnet.read_image(tmp_path / "pics" / "radial_kitti_color.png")
    assert np.abs(kitti_picture.astype(int) - flo_picture.astype(int)).max() <= 2
    # --legend draws the wheel in the bottom-right corner; --shared-scale is the largest flow.
    cli("viz", "radial.flo", "--legend", "--shared-scale", cwd=tmp_path)
    legend = inertialnet.read_image(tmp_path / "radial_color.png")
    assert not np.array_equal(legend, flo_picture)
    np.testing.assert_array_equal(legend, inertialnet.flow_to_color(flow, 0.0, legend=True))


def test_flo_round_trip_is_bit_exact(tmp_path):
    rng = np.random.default_rng(1)
    flow = rng.normal(0, 20, size=(37, 53, 2)).astype(np.float32)
    inertialnet.write_flo(tmp_path / "f.flo", flow)
    back = inertialnet.read_flo(tmp_path / "f.flo")
    assert back.dtype == np.float32 and back.shape == flow.shape
    np.testing.assert_array_equal(back.view(np.uint32), flow.view(np.uint32))
    np.testing.assert_array_equal(inertialnet.read_flow(tmp_path / "f.flo"), flow)


def test_unknown_flow_is_nan_in_python_and_1e10_in_flo_files(tmp_path):
    """Python sees NaN where a file marks unknown flow (1e10 made flow.mean() about 2.6e8); the
    .flo writer keeps Middlebury's 1e10 mark, so other readers still see it."""
    flow = np.ones((6, 8, 2), np.float32)
    flow[3, 4] = [1e10, 0]
    flow[1, 2] = [np.nan, 5]
    inertialnet.write_flo(tmp_path / "f.flo", flow)
    raw = np.fromfile(tmp_path / "f.flo", dtype="<f4", offset=12).reshape(6, 8, 2)
    assert list(raw[3, 4]) == [1e10, 1e10] and list(raw[1, 2]) == [1e10, 1e10]
    back = inertialnet.read_flo(tmp_path / "f.flo")
    assert np.isnan(back[3, 4]).all() and np.isnan(back[1, 2]).all()
    assert np.isnan(back).sum() == 4 and np.nanmean(back) == 1.0
    # The flow_check marks of dis_flow are NaN too.
    rng = np.random.default_rng(3)
    frame = (rng.random((48, 64)) * 255).astype(np.uint8)
    checked = inertialnet.dis_flow(frame, np.roll(frame, 9, axis=1), flow_check=0.01)
    assert np.isnan(checked).any() and not (np.abs(checked) > 1e9).any()
    assert np.array_equal(np.isnan(checked[..., 0]), np.isnan(checked[..., 1]))


@pytest.mark.parametrize("method, band", [("dis", 0), ("dis-fine", 6)])
def test_dis_flow_edge_band_marks_the_edges_only(method, band):
    # 64x48 frames: dis-fine's band is an eighth of the 48 rows (its patch is 8 px); dis has none yet.
    rng = np.random.default_rng(4)
    frame = (rng.random((48, 64)) * 255).astype(np.uint8)
    moved = np.roll(frame, 3, axis=1)
    plain = inertialnet.dis_flow(frame, moved, method=method)
    banded = inertialnet.dis_flow(frame, moved, method=method, edge_band=True)
    edge = np.ones((48, 64), bool)
    edge[band:48 - band, band:64 - band] = False
    assert np.isnan(banded[edge]).all() and np.isfinite(plain).all()
    np.testing.assert_array_equal(banded[~edge], plain[~edge])
    # with a batch, each pair's band; with the check, both marks
    both = inertialnet.dis_flow(np.stack([frame, frame])[..., None], np.stack([moved, moved])[..., None], method=method,
                                flow_check=0.01, edge_band=True)
    checked = inertialnet.dis_flow(frame, moved, method=method, flow_check=0.01)
    assert both.shape == (2, 48, 64, 2)
    for pair in both:
        np.testing.assert_array_equal(np.isnan(pair[..., 0]), edge | np.isnan(checked[..., 0]))


def test_kitti_round_trip_is_exact_to_one_64th_pixel(tmp_path):
    rng = np.random.default_rng(2)
    flow = rng.uniform(-500, 500, size=(41, 67, 2)).astype(np.float32)
    on_grid = np.round(flow * 64) / 64
    inertialnet.write_kitti_flow(tmp_path / "grid.png", on_grid)
    np.testing.assert_array_equal(inertialnet.read_kitti_flow(tmp_path / "grid.png"), on_grid)
    inertialnet.write_kitti_flow(tmp_path / "any.png", flow)
    back = inertialnet.read_flow(tmp_path / "any.png")
    assert np.abs(back - flow).max() <= 1 / 128 + 1e-6
    # Unknown flow (NaN) becomes KITTI's invalid pixel and reads back as unknown (NaN).
    flow[0, 0] = [np.nan, np.nan]
    inertialnet.write_kitti_flow(tmp_path / "invalid.png", flow)
    back = inertialnet.read_kitti_flow(tmp_path / "invalid.png")
    assert np.isnan(back[0, 0]).all() and np.isfinite(back[0, 1]).all()


def test_flow_file_errors_are_value_errors_with_the_library_message(tmp_path):
    with pytest.raises(FileNotFoundError, match="does not exist") as missing:
        inertialnet.read_flo(tmp_path / "missing.flo")
    assert missing.value.filename == str(tmp_path / "missing.flo")
    (tmp_path / "text.flo").write_text("hello")
    with pytest.raises(ValueError, match="neither a Middlebury"):
        inertialnet.read_flow(tmp_path / "text.flo")
    with pytest.raises(ValueError, match=r"\(H, W, 2\)"):
        inertialnet.write_flo(tmp_path / "bad.flo", np.zeros((4, 4, 3), np.float32))
    with pytest.raises(ValueError, match="radius"):
        inertialnet.flow_to_color(np.zeros((4, 4, 2), np.float32), max_magnitude=-1)
