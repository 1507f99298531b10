# SPDX-License-Identifier: Apache-2.0
"""``inertialnet.stream()``: rates pair by pair as they are computed, from any source ``predict``
reads and from live ones (a camera, a GStreamer pipeline), through the library's streaming
predictor (python/src/stream_bindings.cpp)."""

from __future__ import annotations

import os
from typing import Iterable, Iterator, Optional, Tuple, Union

import numpy as np

from . import _inertialnet as _native

PathLike = Union[str, "os.PathLike[str]"]


def stream(
    sequence: PathLike,
    weights: Union[PathLike, Iterable[PathLike]] = (),
    *,
    flow: Optional[str] = None,
    head: Optional[str] = None,
    model: Optional[str] = None,
    solver: str = "motion-field",
    fx: Optional[float] = None,
    fy: Optional[float] = None,
    cx: Optional[float] = None,
    cy: Optional[float] = None,
    calibration: Optional[PathLike] = None,
    calibration_camera: str = "",
    rate_hz: float = 0.0,
    camera: str = "cam0",
    device: Union[None, str, int] = None,
    max_pairs: int = 0,
    lanes: int = 2,
    flow_check: float = 0.5,
    max_sigma: float = 10.0,
    smooth: str = "lag:2",
    fuse: bool = False,
) -> Iterator[Tuple[int, np.ndarray, Union[str, Tuple[str, ...]]]]:
    """Yields ``(timestamp_ns, rates, status)`` for each frame pair as soon as it is computed,
    in pair order: ``timestamp_ns`` the pair's second frame (int), ``rates`` float64 ``(3,)`` in
    rad/s (NaN when the pair has no answer), ``status`` ``"ok"`` or why not (e.g.
    ``"no_texture"``); with ``head="both"`` a ``(2, 3)`` array and a tuple of two statuses, the
    InertialNet head's first; with ``fuse=True`` as well, ``(3, 3)`` and three statuses, the fused
    estimate last. The numbers are ``predict()``'s, row for row.

    ``sequence`` is anything ``predict`` takes, or a live source: ``"/dev/video0"``,
    ``"camera:0"``, ``"gst:videotestsrc ! videoconvert ! appsink"`` (a GStreamer pipeline ending in
    appsink) or ``"capture:rtsp://…"`` (any OpenCV capture); a live source runs until it ends or
    the loop stops. The other arguments are ``predict()``'s. With ``smooth="lag:L"`` (the default
    ``"lag:2"``) each pair is yielded L pairs late (L frame intervals of latency; the last L when the
    source ends); ``smooth="off"`` yields each pair's two-frame rates as soon as it is computed.

    Frames are read and pushed as the loop asks for pairs; several pairs are computed at once
    behind it, and a loop slower than the devices holds the reading back (bounded memory). Ctrl-C
    raises ``KeyboardInterrupt`` within a frame period; leaving the loop (``break``, an exception)
    stops the computation when the iterator is dropped."""
    if isinstance(weights, (str, os.PathLike)):
        weights = [weights]
    def number(value):
        return None if value is None else float(value)

    return _native._Stream(
        os.fspath(sequence), [os.fspath(w) for w in weights], model or "", flow or "", head or "", solver,
        number(fx), number(fy), number(cx), number(cy), "" if calibration is None else os.fspath(calibration),
        calibration_camera, camera, float(rate_hz), "" if device is None else str(device), int(max_pairs),
        int(lanes), float(flow_check), float(max_sigma), str(smooth), bool(fuse))
