"""InertialNet-CL for Python: camera angular velocity from image sequences.

FlowNet2 optical flow and the InertialNet rotation head run as OpenCL kernels (any GPU, or the
CPU through PoCL); OpenCV's DIS flow and a geometric head run without weights. The functions
compute exactly what the ``inertialnet`` command line computes: ``predict`` gives the numbers of
``inertialnet predict``, ``evaluate`` those of ``inertialnet eval``.

Images are NumPy ``uint8`` arrays: ``(H, W)`` gray, ``(H, W, 3)`` RGB (``order="bgr"`` for
OpenCV's order), ``(H, W, 4)`` with alpha dropped, or batches ``(N, H, W, C)``. Flow is float32
``(H, W, 2)``: u (right) and v (down) in pixels. Rates are float64 rad/s.

Errors keep the library's messages: bad input raises ``ValueError``, a failure of the device or
driver ``RuntimeError``, exhausted host memory ``MemoryError``. Ctrl-C stops every long call
(``predict``, networks and DIS flow on batches) within a pair or a layer: ``KeyboardInterrupt``.
"""

from __future__ import annotations

import os
from typing import Callable, Iterable, Optional, Sequence as _Seq, Union

import numpy as np

from ._inertialnet import (  # noqa: F401  (re-exported)
    Camera,
    Device,
    GeometricHead,
    Sequence,
    __version__,
    devices,
    dis_flow,
    flow_to_color,
    read_flo,
    read_flow,
    read_image,
    read_kitti_flow,
    select_devices,
    synth,
    write_flo,
    write_flow_png,
    write_kitti_flow,
)
from . import _inertialnet as _native

PathLike = Union[str, "os.PathLike[str]"]
Weights = Union[PathLike, Iterable[PathLike]]
DeviceLike = Union[None, str, int, Device]

__all__ = [
    "Camera", "Device", "FlowNet", "FlowNet2", "FlowNet2C", "FlowNet2S", "FlowNet2SD", "FlowNet2CS",
    "FlowNet2CSS", "GeometricHead", "InertialNetHead", "Sequence", "devices", "dis_flow", "evaluate",
    "flow_to_color", "predict", "read_flo", "read_flow", "read_image", "read_kitti_flow", "select_devices",
    "synth", "write_flo", "write_flow_png", "write_kitti_flow", "write_rates_csv",
]


class FlowNet:
    """A FlowNet2-family network on one device.

    ``FlowNet.load(weights)`` takes the model from the weights' metadata; the subclasses
    (``FlowNet2``, ``FlowNet2C``, …) ask for theirs, so wrong weights are a ``ValueError`` listing
    every missing or mis-shaped tensor.
    """

    MODEL = ""

    def __init__(self, native: "_native._FlowNet"):
        self._net = native

    @classmethod
    def load(cls, weights: Weights, device: DeviceLike = None, model: Optional[str] = None) -> "FlowNet":
        """Loads safetensors weights (a path or several) onto ``device`` (a spec such as ``"0"``,
        ``"cpu"``, ``"pocl"``, a :class:`Device`, or None for ``$INERTIALNET_DEVICE``/the default)."""
        return cls(_native._FlowNet(weights, device, model or cls.MODEL))

    def flow(self, img1: np.ndarray, img2: np.ndarray, order: str = "rgb") -> np.ndarray:
        """Flow from img1 to img2: float32 ``(H, W, 2)``, or ``(N, H, W, 2)`` for batches.

        Frames of any size: the network runs at the next multiples of 64 and the flow is resized
        back with its vectors rescaled. Runs without the GIL."""
        return self._net.flow(img1, img2, order)

    @property
    def model(self) -> str:
        return self._net.model

    @property
    def device(self) -> str:
        return self._net.device

    @property
    def synthetic(self) -> bool:
        """True for the deterministic synthetic weights: their flow measures nothing."""
        return self._net.synthetic

    def __repr__(self) -> str:
        return f"<inertialnet.{type(self).__name__} {self.model} on {self.device}>"


class FlowNet2(FlowNet):
    MODEL = "FlowNet2"


class FlowNet2C(FlowNet):
    MODEL = "FlowNet2-C"


class FlowNet2S(FlowNet):
    MODEL = "FlowNet2-S"


class FlowNet2SD(FlowNet):
    MODEL = "FlowNet2-SD"


class FlowNet2CS(FlowNet):
    MODEL = "FlowNet2-CS"


class FlowNet2CSS(FlowNet):
    MODEL = "FlowNet2-CSS"


class InertialNetHead:
    """The learned InertialNet rotation head (weights with the ``head.*`` tensors)."""

    def __init__(self, native: "_native._InertialNetHead"):
        self._head = native

    @classmethod
    def load(cls, weights: Weights, device: DeviceLike = None) -> "InertialNetHead":
        return cls(_native._InertialNetHead(weights, device))

    def rates(self, flow: np.ndarray, camera: Optional[Camera] = None, dt: Optional[float] = None) -> np.ndarray:
        """ω in rad/s: ``(3,)`` for one flow ``(H, W, 2)``, ``(N, 3)`` for a batch. The flow must have
        the size the head was built for (``config``) and a finite, known vector at every pixel: NaN,
        infinity or an unknown-flow mark (above 1e9, as ``dis_flow(flow_check=…)`` and KITTI files
        write them) is a ``ValueError`` naming the first such index. ``camera`` and ``dt`` are
        accepted for symmetry with :class:`GeometricHead` and ignored: the learned head knows its
        camera and rate."""
        del camera, dt
        return self._head.rates(flow)

    @property
    def config(self) -> dict:
        return self._head.config


def predict(
    sequence: PathLike,
    weights: Weights = (),
    *,
    flow: Optional[str] = None,
    head: Optional[str] = None,
    model: Optional[str] = None,
    solver: str = "motion-field",
    fx: float = 0.0,
    fy: float = 0.0,
    cx: float = 0.0,
    cy: float = 0.0,
    rate_hz: float = 0.0,
    device: Union[None, str, int] = None,
    max_pairs: int = 0,
    lanes: int = 2,
    decode_threads: int = 2,
    keep_flow: bool = False,
    flow_check: float = 0.5,
    progress: Optional[Callable[[int, int], object]] = None,
):
    """Angular rates of every frame pair of a sequence, as ``inertialnet predict`` computes them.

    Returns a NumPy structured array with one row per frame pair and the fields ``timestamp_ns``
    (int64, the pair's second frame), ``wx, wy, wz`` (float64, rad/s) and ``status`` (str:
    ``"ok"``, or why the pair has no answer, e.g. ``"no_texture"``; its rates are then NaN), plus
    ``wx_geometric, wy_geometric, wz_geometric, status_geometric`` with ``head="both"``. The
    arguments are the CLI's options: without weights, DIS flow and the geometric head;
    ``flow_check`` is ``--flow-check`` (the DIS forward-backward check for the geometric head,
    pixels at 752 columns; 0: off). With ``keep_flow=True`` returns ``(rates, flows)``, flows a
    list of ``(H, W, 2)`` arrays (as computed, without the check's marks).

    ``rate_hz``, ``fx`` and ``fy`` are 0 (not given) or what the CLI accepts for ``--rate``,
    ``--fx``, ``--fy`` (finite, positive, at most 1e6); ``max_pairs`` is 0 (all) or a count:
    anything else is a ``ValueError``.

    ``progress(done, total)``, if given, is called on the calling thread as pairs complete (at
    most every 50 ms, and once at the end): ``done`` pairs of ``total``. An exception it raises
    stops the run and propagates. Ctrl-C stops the run within a pair or two and raises
    ``KeyboardInterrupt``; the pairs computed so far are dropped."""
    if isinstance(weights, (str, os.PathLike)):
        weights = [weights]
    columns, t_ns, values, flows, statuses = _native._predict(
        os.fspath(sequence), [os.fspath(w) for w in weights], model or "", flow or "", head or "", solver,
        float(fx), float(fy), float(cx), float(cy), float(rate_hz), "" if device is None else str(device),
        keep_flow, max_pairs, int(lanes), int(decode_threads), float(flow_check), progress)
    # Fields as in the rates CSV: wx,wy,wz,status then wx_geometric,…,status_geometric.
    dtype = [("timestamp_ns", np.int64)]
    status_fields = []
    for e in range(len(columns) // 3):
        dtype += [(name, np.float64) for name in columns[3 * e:3 * e + 3]]
        status_fields.append("status" + columns[3 * e][2:])
        dtype.append((status_fields[-1], "U16"))
    rates = np.zeros(len(t_ns), dtype=dtype)
    rates["timestamp_ns"] = t_ns
    for i, name in enumerate(columns):
        rates[name] = values[:, i]
    for e, name in enumerate(status_fields):
        rates[name] = [row[e] for row in statuses]
    return (rates, flows) if keep_flow else rates


def write_rates_csv(path: PathLike, rates: np.ndarray) -> None:
    """Writes a structured array from :func:`predict` as the CLI's rates CSV (atomically)."""
    names = list(rates.dtype.names)
    status_names = [n for n in names[1:] if n == "status" or n.startswith("status_")]
    numeric = [n for n in names[1:] if n not in status_names]
    values = np.stack([rates[n] for n in numeric], axis=1) if len(rates) else np.zeros((0, len(numeric)))
    statuses = [[str(s) for s in rates[n]] for n in status_names]
    _native._write_rates_csv(os.fspath(path), numeric, rates[names[0]], values, status_names, statuses)


def evaluate(
    rates: Union[PathLike, np.ndarray],
    sequence: PathLike,
    *,
    target: Optional[str] = None,
    head: Optional[str] = None,
    gyro_bias: Optional[_Seq[float]] = None,
    camera_frame: bool = False,
    plot: Optional[PathLike] = None,
    series: bool = False,
) -> dict:
    """The paper's metrics, as ``inertialnet eval --json``: ``rates`` is a rates CSV or the array
    from :func:`predict`, ``sequence`` a EuRoC folder with ``imu0``. ``head="geometric"`` compares
    the ``wx_geometric, …`` columns. ``target`` is "spline" or "mean"; ``None`` picks the one that
    fits the estimator the CSV states, as the CLI does (an array states none: spline). Returns the
    ``inertialnet.eval/1`` document as a dict: its ``estimators`` list holds one report
    (``series=True`` adds the per-frame values)."""
    import json
    import tempfile

    if isinstance(rates, np.ndarray):
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, "rates.csv")
            write_rates_csv(path, rates)
            return evaluate(path, sequence, target=target, head=head, gyro_bias=gyro_bias,
                            camera_frame=camera_frame, plot=plot, series=series)
    text = _native._evaluate_json(os.fspath(rates), os.fspath(sequence), target or "", head or "",
                                  None if gyro_bias is None else list(gyro_bias), camera_frame,
                                  "" if plot is None else os.fspath(plot), series)
    return json.loads(text)
