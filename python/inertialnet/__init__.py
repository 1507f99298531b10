# SPDX-License-Identifier: Apache-2.0
"""InertialNet-CL for Python: camera angular velocity from image sequences.

FlowNet2 optical flow and the InertialNet rotation head run as OpenCL kernels (any GPU, or the
CPU through PoCL); OpenCV's DIS flow and a geometric head run without weights. The functions
compute exactly what the ``inertialnet`` command line computes: ``predict`` gives the numbers of
``inertialnet predict``, ``evaluate`` those of ``inertialnet eval``.

Images are NumPy ``uint8`` (or ``uint16``) arrays, or floats in [0, 1]: ``(H, W)`` gray,
``(H, W, 3)`` RGB (``order="bgr"`` for OpenCV's order), ``(H, W, 4)`` with alpha dropped, or
batches ``(N, H, W, C)``. Flow is float32 ``(H, W, 2)`` or ``(N, H, W, 2)``: u (right) and v
(down) in pixels, NaN where unknown. Rates are float64 rad/s: :class:`Rates` from ``predict``.

Errors keep the library's messages, with keyword arguments where the CLI names its options: bad
input raises ``ValueError`` (``TypeError`` for an argument of the wrong type), a missing file
``FileNotFoundError``, a failure of the device or driver ``RuntimeError``, exhausted host memory
``MemoryError``. Ctrl-C stops every long call (``predict``, networks, heads and DIS flow on
batches) within a pair or a layer: ``KeyboardInterrupt``.
"""

from __future__ import annotations

import dataclasses
import os
from typing import Iterable, List, Optional, Sequence as _Seq, Union

import numpy as np

from ._inertialnet import (  # noqa: F401  (re-exported)
    Camera,
    Device,
    GeometricHead,
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
from ._options import PredictOptions, takes_predict_options
from ._rates import Rates, read_rates, _rates_of_predict
from ._sequence import Sequence
from . import _inertialnet as _native
from .streaming import stream  # noqa: F401  (re-exported)

PathLike = Union[str, "os.PathLike[str]"]
Weights = Union[PathLike, Iterable[PathLike]]
DeviceLike = Union[None, str, int, Device]
SequenceLike = Union[PathLike, Sequence]

__all__ = [
    "Rates", "read_rates",  # _rates.py
    "Camera", "Device", "FlowNet", "FlowNet2", "FlowNet2C", "FlowNet2S", "FlowNet2SD", "FlowNet2CS",
    "FlowNet2CSS", "GeometricHead", "InertialNetHead", "Sequence", "devices", "dis_flow", "evaluate",
    "flow_to_color", "predict", "read_flo", "read_flow", "read_image", "read_kitti_flow", "select_devices",
    "synth", "write_flo", "write_flow_png", "write_kitti_flow", "write_rates_csv",
]
__all__ += ["stream"]  # streaming.py


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
        """ω in rad/s: ``(3,)`` for one flow ``(H, W, 2)``, ``(N, 3)`` for a batch, of frames of any
        size: the flow is turned into the head's input as ``predict`` and ``train`` do (resized to
        the head's size, ``config["input_width"]`` × ``config["input_height"]``; for a head of
        ``config["input"] == "normalized"`` also divided by ``dt`` and the focal lengths of
        ``camera``, which it then needs). Every vector must be finite and known: NaN (what
        ``dis_flow(flow_check=…)`` and the flow readers give for unknown flow), infinity or a value
        above 1e9 is a ``ValueError`` naming the first such index. A paper head (``"paper"``)
        ignores ``camera`` and ``dt``. The rates are in the frame ``config["frame"]`` names:
        ``"camera"`` for a head trained on camera-frame targets (what ``train`` writes for the
        normalized input; turn them with the rig's camera-to-IMU rotation for the gyro's frame, as
        ``predict`` does), ``"body"`` for the IMU frame of the rig the head was trained on."""
        return self._head.rates(flow, float(dt) if dt is not None else 0.0,
                                float(camera.fx) if camera is not None else 0.0,
                                float(camera.fy) if camera is not None else 0.0)

    @property
    def config(self) -> dict:
        return self._head.config

    def __repr__(self) -> str:
        c = self.config
        return f"<inertialnet.InertialNetHead {c['input_width']}x{c['input_height']}>"


@takes_predict_options()
def predict(sequence: SequenceLike, weights: Weights = (), *, options: PredictOptions):
    """Angular rates of every frame pair of a sequence, as ``inertialnet predict`` computes them.

    ``sequence`` is a path (EuRoC folder, image folder, video, ROS bag) or a :class:`Sequence` (its
    ``rate_hz`` and ``image_topic`` are used unless given). Returns :class:`Rates`: one row per frame pair,
    ``.timestamps_ns`` (the pair's second frame), ``.w`` (N, 3) rad/s, ``.status`` (``"ok"``, or
    why the pair has no answer, e.g. ``"no_texture"``; its rates are then NaN), and what the CLI's
    rates CSV states: ``.estimator``, ``.frame``, ``.time_offset_s``, ``.readout_time_s``. With
    ``head="both"`` the geometric head's columns follow (``rates["wx_geometric"]``,
    ``rates.head("geometric")``). The arguments are the CLI's options: without weights, sparse
    Lucas–Kanade flow (DIS with ``readout_time``) and the geometric head; ``camera`` is ``--camera`` (a EuRoC sequence's cam0 or cam1);
    ``calibration`` is ``--calibration`` (EuRoC sensor.yaml, Kalibr camchain, OpenCV YAML/XML;
    ``calibration_camera`` picks a camchain's camera) and ``fx``, ``fy``, ``cx``, ``cy`` are
    ``--fx`` … (None: not given; ``cx=0`` is a principal point at the corner);
    ``image_topic`` and ``camera_info_topic`` are a ROS bag's ``--image-topic`` and
    ``--camera-info-topic`` (None: a :class:`Sequence`'s own, else the bag's only image topic);
    ``time_offset`` and ``readout_time`` are ``--time-offset`` and ``--readout-time`` (seconds;
    stated in the rates for :func:`evaluate`, the readout time also corrects the geometric head);
    ``flow`` is ``--flow``: ``"flownet2"``, ``"dis"``, ``"dis-fine"`` (DIS down to the full resolution,
    the flow of recipe heads since v3) or ``"lk"`` (sparse Lucas–Kanade at the
    geometric head's sample points, for the geometric head only; None: a trained head's own flow (its
    metadata), flownet2 with other weights, lk
    without, dis without weights when ``readout_time`` is given). ``flow_check`` is ``--flow-check`` (the DIS or LK forward-backward check for the
    geometric head, pixels at 752 columns; 0: off). ``max_sigma`` is ``--max-sigma`` (deg/s: a geometric rate whose standard deviation
    along its least certain direction exceeds it gets the status ``"uncertain"``; 0: no limit) and
    ``smooth`` is ``--smooth`` (``"lag:2"``, the default: a fixed-lag smoother over the pairs using
    their σ; ``"off"``: the two-frame rates); ``rates.sigma`` holds each rate's σ. ``fuse`` is
    ``--fuse`` (with ``head="both"``: a third estimator, ``rates.head("fused")``, the two heads'
    rates weighted by their σ). With ``keep_flow=True`` returns ``(rates, flows)``, flows a
    list of ``(H, W, 2)`` arrays (as computed, without the check's marks).

    ``rate_hz``, ``fx`` and ``fy`` are 0 or None (not given) or what the CLI accepts for ``--rate``,
    ``--fx``, ``--fy`` (finite, positive, at most 1e6); ``max_pairs`` is 0 (all) or a count:
    anything else is a ``ValueError``. A missing sequence or weights file is a
    ``FileNotFoundError``.

    ``progress(done, total)``, if given, is called on the calling thread as pairs complete (at
    most every 50 ms, and once at the end): ``done`` pairs of ``total``. An exception it raises
    stops the run and propagates. Ctrl-C stops the run within a pair or two and raises
    ``KeyboardInterrupt``; the pairs computed so far are dropped."""
    if isinstance(sequence, Sequence) and not options.rate_hz:
        options = dataclasses.replace(options, rate_hz=sequence.rate_hz)
    options = dataclasses.replace(options, image_topic=_image_topic_of(sequence, options.image_topic))
    if isinstance(weights, (str, os.PathLike)):
        weights = [weights]
    columns, t_ns, values, flows, statuses, metadata, sigmas = _native._predict(
        os.fspath(sequence), [os.fspath(w) for w in weights], **options.native())
    rates = _rates_of_predict(columns, t_ns, values, statuses, metadata, sigmas)
    return (rates, flows) if options.keep_flow else rates


def write_rates_csv(path: PathLike, rates: Union[Rates, np.ndarray]) -> None:
    """Writes :class:`Rates` (or a structured array with the CSV's fields) as the CLI's rates
    CSV, atomically; the same as ``rates.to_csv(path)``."""
    _as_rates(rates).to_csv(path)


def _as_rates(rates: Union[Rates, np.ndarray]) -> Rates:
    return rates if isinstance(rates, Rates) else Rates.from_records(np.asarray(rates))


def _image_topic_of(sequence, image_topic: Optional[str]) -> str:
    """A bag's image topic: the one given, else a :class:`Sequence`'s own, else "" (the only one)."""
    if image_topic is not None:
        return str(image_topic)
    return sequence.image_topic if isinstance(sequence, Sequence) else ""


def _pair_of_words(value, name: str, *, count: int) -> List[str]:
    """``imu_columns=`` / ``imu_units=`` as the CLI's comma lists: a string "a,b" or a sequence."""
    if value is None:
        return []
    words = value.split(",") if isinstance(value, str) else [str(v) for v in value]
    if len(words) != count:
        raise ValueError(f"{name} must hold {count} values, got {len(words)}: {value!r}")
    return [w.strip() for w in words]


def _t_cam_imu_text(T_cam_imu) -> str:
    """``T_cam_imu=`` as the library's parser takes --T-cam-imu: a 4x4 matrix (anything NumPy
    reads as one, or 16 numbers) as 16 numbers, a path or a string of numbers as it is."""
    if T_cam_imu is None:
        return ""
    if isinstance(T_cam_imu, (str, os.PathLike)):
        return os.fspath(T_cam_imu)
    matrix = np.asarray(T_cam_imu, dtype=np.float64)
    if matrix.size != 16:
        raise ValueError(f"T_cam_imu must be a 4x4 matrix (IMU to camera), 16 numbers or a YAML file; "
                         f"got an array of shape {matrix.shape}")
    return " ".join(repr(float(v)) for v in matrix.ravel())


def evaluate(
    rates: Union[PathLike, Rates, np.ndarray],
    sequence: SequenceLike,
    *,
    target: Optional[str] = None,
    head: Optional[str] = None,
    gyro_bias: Union[None, str, _Seq[float]] = None,
    camera_frame: bool = False,
    time_offset: Union[None, float, str] = None,
    time_offset_range: float = 0.2,
    readout_time: Optional[float] = None,
    imu: Optional[PathLike] = None,
    imu_time_unit: Optional[str] = None,
    imu_columns: Union[None, str, _Seq[Union[str, int]]] = None,
    imu_units: Union[None, str, _Seq[str]] = None,
    image_topic: Optional[str] = None,
    imu_topic: str = "",
    camera_info_topic: str = "",
    T_cam_imu=None,
    camchain: Optional[PathLike] = None,
    calibration: Optional[PathLike] = None,
    calibration_camera: str = "",
    camera: str = "cam0",
    rate_hz: float = 0.0,
    plot: Optional[PathLike] = None,
    series: bool = False,
) -> dict:
    """The paper's metrics, as ``inertialnet eval --json``.

    ``rates`` is :class:`Rates` from :func:`predict`, a rates CSV, or a structured array with the
    CSV's fields; ``sequence`` a EuRoC folder with ``imu0``, or an image folder or a video with
    ``imu``. What the rates state (estimator, frame, time offset, readout time) is used as
    ``inertialnet eval`` uses it from the CSV: ``evaluate(predict(seq), seq)`` gives eval's numbers
    on predict's CSV. The keywords are eval's options: ``target`` ("spline" or "mean"; None picks
    the one that fits the estimator), ``head="geometric"`` (the ``wx_geometric, …`` columns),
    ``gyro_bias`` (x, y, z rad/s in the IMU frame, or "auto"), ``camera_frame``, ``time_offset``
    (seconds, t_imu = t_cam + offset, or "auto" to estimate it within ±``time_offset_range``;
    None: the rates' own), ``readout_time`` (seconds; None: the rates' own), ``imu`` (a gyro log:
    EuRoC CSV, any CSV, Gyroflow .gcsv, a GoPro MP4; ``imu_time_unit`` s|ms|us|ns; ``imu_columns``
    the time and gyro columns by name or index, ``imu_units`` (time unit, gyro unit), as
    ``--imu-columns t,gx,gy,gz --imu-units s,deg/s``), a ROS bag's ``image_topic``, ``imu_topic``,
    ``camera_info_topic`` (``--image-topic`` …; None/"": its only one), ``T_cam_imu`` (IMU to
    camera: a 4x4 matrix, 16 numbers, or a YAML file), ``camchain`` (a Kalibr camchain's cam0),
    ``calibration`` (a calibration file whose camera-IMU extrinsic, if it has one, stands for
    ``camchain``; ``calibration_camera`` picks a camchain's camera), ``camera`` (a EuRoC sequence's cam0 or cam1), ``rate_hz`` (a folder's or video's
    frame rate, as predict was given it), ``plot`` (a PNG).

    Returns the ``inertialnet.eval/1`` document as a dict: its ``estimators`` list holds one
    report (``series=True`` adds the per-frame values). A missing file is a ``FileNotFoundError``."""
    import json
    import tempfile

    if isinstance(sequence, Sequence) and not rate_hz:
        rate_hz = sequence.rate_hz
    if not isinstance(rates, (str, os.PathLike)):
        # Through the CLI's CSV writer, metadata and %.9g values included: the numbers of eval on
        # the CSV that `inertialnet predict` writes.
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, "rates.csv")
            _as_rates(rates).to_csv(path)
            return evaluate(path, sequence, target=target, head=head, gyro_bias=gyro_bias, camera_frame=camera_frame,
                            time_offset=time_offset, time_offset_range=time_offset_range,
                            readout_time=readout_time, imu=imu, imu_time_unit=imu_time_unit,
                            imu_columns=imu_columns, imu_units=imu_units, image_topic=image_topic,
                            imu_topic=imu_topic, camera_info_topic=camera_info_topic, T_cam_imu=T_cam_imu,
                            camchain=camchain, calibration=calibration, calibration_camera=calibration_camera,
                            camera=camera, rate_hz=rate_hz, plot=plot, series=series)
    if isinstance(gyro_bias, str):
        bias = gyro_bias
    else:
        bias = None if gyro_bias is None else [float(b) for b in gyro_bias]
    text = _native._evaluate_json(
        os.fspath(rates), os.fspath(sequence), target or "", head or "", bias, camera_frame,
        "" if plot is None else os.fspath(plot), series,
        time_offset if time_offset is None or isinstance(time_offset, str) else float(time_offset),
        float(time_offset_range), None if readout_time is None else float(readout_time),
        "" if imu is None else os.fspath(imu), imu_time_unit or "", _t_cam_imu_text(T_cam_imu),
        "" if camchain is None else os.fspath(camchain), camera, float(rate_hz),
        "" if calibration is None else os.fspath(calibration), calibration_camera,
        _pair_of_words(imu_columns, "imu_columns", count=4), _pair_of_words(imu_units, "imu_units", count=2),
        _image_topic_of(sequence, image_topic), imu_topic, camera_info_topic)
    return json.loads(text)
