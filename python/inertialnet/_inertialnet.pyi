# SPDX-License-Identifier: Apache-2.0
# Type stubs of the native module (python/src/bindings.cpp). The package's own classes (Rates,
# Sequence, FlowNet, InertialNetHead) and predict/evaluate are typed in their Python files.
import os
from typing import Any, Callable, Iterable, Optional, Sequence as _Seq, SupportsIndex, Union

import numpy as np
import numpy.typing as npt

_Path = Union[str, os.PathLike]
_DeviceArg = Union[None, str, int, "Device"]

__version__: str

def devices() -> list[dict[str, Any]]: ...
def select_devices(spec: str = "") -> list[dict[str, Any]]: ...

class Device:
    # A --device spec, or a device index (an int >= 0: the spec "0", "1", …).
    def __init__(self, spec: Union[str, int] = "") -> None: ...
    @property
    def name(self) -> str: ...
    @property
    def info(self) -> dict[str, Any]: ...
    def __repr__(self) -> str: ...

class Camera:
    def __init__(self, width: int, height: int, fx: float, fy: float, cx: float, cy: float,
                 distortion: str = "none", coefficients: _Seq[float] = ...) -> None: ...
    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float
    coefficients: list[float]
    def __repr__(self) -> str: ...

class _FlowNet:
    def __init__(self, weights: Union[_Path, Iterable[_Path]], device: _DeviceArg = None, model: str = "") -> None: ...
    def flow(self, img1: npt.NDArray[Any], img2: npt.NDArray[Any], order: str = "rgb") -> npt.NDArray[np.float32]: ...
    model: str
    device: str
    synthetic: bool

# Images: uint8, uint16 or floats in [0, 1]; (H, W), (H, W, C) or batches (N, H, W, C).
# Flow: NaN where unknown (flow_check marks, invalid file pixels).
def dis_flow(img1: npt.NDArray[Any], img2: npt.NDArray[Any], order: str = "rgb",
             flow_check: float = 0.0) -> npt.NDArray[np.float32]: ...

class GeometricHead:
    def __init__(self, device: _DeviceArg = None, solver: str = "motion-field", stride: int = 4) -> None: ...
    # camera_to_body: a 3x3 rotation (orthonormal rows within 1e-3, determinant +1), else ValueError.
    # NaN, infinite and > 1e9 flow vectors are unknown flow and left out.
    # flow (H, W, 2) -> (3,); a batch (N, H, W, 2) -> (N, 3), dt one number or N of them.
    def rates(self, flow: npt.NDArray[np.float32], camera: Camera, dt: Union[float, npt.ArrayLike],
              camera_to_body: Optional[npt.NDArray[np.float64]] = None) -> npt.NDArray[np.float64]: ...
    def __repr__(self) -> str: ...

class _InertialNetHead:
    def __init__(self, weights: Union[_Path, Iterable[_Path]], device: _DeviceArg = None) -> None: ...
    # ValueError naming the index of the first NaN, infinite or unknown (> 1e9) flow value.
    # dt (s), fx, fy (px): needed by a head of normalized input (config["input"]); 0: not given.
    def rates(self, flow: npt.NDArray[np.float32], dt: float = 0.0, fx: float = 0.0,
              fy: float = 0.0) -> npt.NDArray[np.float64]: ...
    config: dict[str, Union[int, str]]

# Wrapped by inertialnet.Sequence (a collections.abc.Sequence, python/inertialnet/_sequence.py).
class _Sequence:
    # rate_hz: 0 (the source's frame times) or a finite positive rate up to 1e6 Hz, else ValueError.
    # A missing path: FileNotFoundError. image_topic: a ROS bag's image topic ("": its only one).
    def __init__(self, path: _Path, rate_hz: float = 0.0, image_topic: str = "") -> None: ...
    def __len__(self) -> int: ...
    # Python indexing: seq[-1] is the last frame; IndexError beyond either end. Random access on
    # videos too (a step back re-opens the video).
    def __getitem__(self, index: SupportsIndex) -> npt.NDArray[np.uint8]: ...
    timestamps_ns: npt.NDArray[np.int64]
    camera: Optional[Camera]
    camera_to_body: Optional[npt.NDArray[np.float64]]
    description: str
    path: str
    image_topic: str
    rate_hz: float
    sequential: bool

def read_image(path: _Path) -> npt.NDArray[np.uint8]: ...
def read_flo(path: _Path) -> npt.NDArray[np.float32]: ...
def write_flo(path: _Path, flow: npt.NDArray[np.float32]) -> None: ...
def read_kitti_flow(path: _Path) -> npt.NDArray[np.float32]: ...
def write_kitti_flow(path: _Path, flow: npt.NDArray[np.float32]) -> None: ...
def read_flow(path: _Path) -> npt.NDArray[np.float32]: ...
def flow_to_color(flow: npt.NDArray[np.float32], max_magnitude: float = 0.0, legend: bool = False,
                  order: str = "rgb") -> npt.NDArray[np.uint8]: ...
def write_flow_png(path: _Path, flow: npt.NDArray[np.float32], max_magnitude: float = 0.0) -> None: ...
def synth(out: _Path, frames: int = 40, motion: str = "rotation", seed: SupportsIndex = 1, width: int = 752,
          height: int = 480, noise: bool = True, overwrite: bool = False) -> int: ...

# The native halves of inertialnet.predict, evaluate, Rates.to_csv and read_rates.
def _predict(sequence: _Path, weights: list[str], model: str, flow: str, head: str, solver: str,
             fx: Optional[float], fy: Optional[float], cx: Optional[float], cy: Optional[float], rate_hz: float,
             device: str, keep_flow: bool, max_pairs: SupportsIndex, lanes: int, decode_threads: int,
             flow_check: float, progress: Optional[Callable[[int, int], object]], time_offset: Optional[float],
             readout_time: float, camera: str, calibration: str, calibration_camera: str, image_topic: str,
             camera_info_topic: str, max_sigma: float, smooth: str, fuse: bool) -> tuple[list[str], npt.NDArray[np.int64], npt.NDArray[np.float64], list[npt.NDArray[np.float32]],
                        list[list[str]], list[tuple[str, str]], npt.NDArray[np.float64]]: ...
def _evaluate_json(rates: _Path, sequence: _Path, target: str, head: str, gyro_bias: Union[None, str, list[float]],
                   camera_frame: bool, plot: str, series: bool, time_offset: Union[None, float, str],
                   time_offset_range: float, readout_time: Optional[float], imu: str, imu_time_unit: str,
                   T_cam_imu: str, camchain: str, camera: str, rate_hz: float, calibration: str,
                   calibration_camera: str, imu_columns: list[str], imu_units: list[str], image_topic: str,
                   imu_topic: str, camera_info_topic: str) -> str: ...
def _write_rates_csv(path: _Path, columns: list[str], t: npt.ArrayLike, values: npt.ArrayLike,
                     status_names: list[str], statuses: list[list[str]], metadata: list[tuple[str, str]]) -> None: ...
def _read_rates_csv(path: _Path) -> tuple[list[str], npt.NDArray[np.int64], npt.NDArray[np.float64], list[str],
                                          list[list[str]], list[tuple[str, str]]]: ...

# The native halves of inertialnet.batch (batch.py): the CLI's batch files, names and table.
def _predict_rates_file(rates: _Path, skip_current: bool, sequence: _Path, weights: list[str], model: str, flow: str,
                        head: str, solver: str, fx: Optional[float], fy: Optional[float], cx: Optional[float],
                        cy: Optional[float], rate_hz: float, device: str, keep_flow: bool, max_pairs: SupportsIndex,
                        lanes: int, decode_threads: int, flow_check: float,
                        progress: Optional[Callable[[int, int], object]], time_offset: Optional[float],
                        readout_time: float, camera: str, calibration: str, calibration_camera: str,
                        image_topic: str, camera_info_topic: str, max_sigma: float, smooth: str, fuse: bool) -> dict[str, Union[str, int]]: ...
def _batch_rates_paths(sequences: list[_Path], folder: _Path) -> list[str]: ...
def _read_batch_manifest(manifest: _Path) -> list[str]: ...
def _eval_table(rates: list[_Path], sequences: list[_Path], format: str, plot: _Path, target: str, head: str) -> str: ...

# python/src/stream_bindings.cpp: what inertialnet.stream() returns (streaming.py has the arguments).
class _Stream:
    def __init__(self, sequence: str, weights: list[str], model: str, flow: str, head: str, solver: str,
                 fx: Optional[float], fy: Optional[float], cx: Optional[float], cy: Optional[float],
                 calibration: str, calibration_camera: str, camera: str, rate_hz: float, device: str,
                 max_pairs: int, lanes: int, flow_check: float, max_sigma: float, smooth: str) -> None: ...
    def __iter__(self) -> "_Stream": ...
    # (timestamp_ns, rates (3,) or (2, 3) rad/s, status or a tuple of statuses)
    def __next__(self) -> tuple[int, npt.NDArray[np.float64], Union[str, tuple[str, ...]]]: ...
