# SPDX-License-Identifier: Apache-2.0
"""``inertialnet.stream()``: rates pair by pair as they are computed, from any source ``predict``
reads and from live ones (a camera, a GStreamer pipeline), through the library's streaming
predictor (python/src/stream_bindings.cpp)."""

from __future__ import annotations

import os
from typing import Iterable, Iterator, Tuple, Union

import numpy as np

from . import _inertialnet as _native
from ._options import PredictOptions, takes_predict_options

PathLike = Union[str, "os.PathLike[str]"]


# predict()'s keywords but those of a finished sequence's file (topics, time offset, readout time),
# of decoding ahead and of predict()'s own returns.
@takes_predict_options(
    omit=("image_topic", "camera_info_topic", "time_offset", "readout_time", "decode_threads", "keep_flow", "progress"),
    annotations={"device": "Union[None, str, int]"})
def stream(
    sequence: PathLike,
    weights: Union[PathLike, Iterable[PathLike]] = (),
    *,
    options: PredictOptions,
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
    return _native._Stream(os.fspath(sequence), [os.fspath(w) for w in weights], **options.native())
