# SPDX-License-Identifier: Apache-2.0
"""inertialnet.Sequence: a recording's frames as a Python sequence."""

from __future__ import annotations

import collections.abc
import os
from typing import Optional, Union

import numpy as np

from . import _inertialnet as _native

PathLike = Union[str, "os.PathLike[str]"]


class Sequence(collections.abc.Sequence):
    """A EuRoC folder, an image folder, a video or a ROS bag (``image_topic``: its image topic, ""
    for its only one), frame by frame, as ``inertialnet predict``
    reads it: a ``collections.abc.Sequence`` of uint8 RGB frames ``(H, W, 3)``.

    ``seq[k]`` decodes frame k (``seq[-1]`` the last; ``IndexError`` beyond either end);
    ``seq[a:b:c]`` decodes the frames of the slice into a list (decoded images are large: a list
    makes the cost explicit, where a lazy view would hide it); ``for frame in seq`` decodes in
    order. Videos decode in order only: random access works, but a frame before the last one read
    opens the video again and decodes from its start (``seq.sequential`` says which kind it is).
    ``len(seq)``, ``seq.timestamps_ns`` (int64, ns), ``seq.camera`` (:class:`Camera`, or None
    without a calibration), ``seq.camera_to_body`` (3x3, or None) and ``seq.description``.

    A Sequence is path-like: ``predict(seq)`` and ``evaluate(rates, seq)`` take it (with its
    ``rate_hz``). Missing paths raise ``FileNotFoundError``.

    A ROS bag reads the frames of ``image_topic`` (``""``: the bag's only image topic) at their
    header stamps; ``camera`` comes from its CameraInfo, ``camera_to_body`` is None.
    """

    def __init__(self, path: PathLike, rate_hz: float = 0.0, image_topic: str = ""):
        self._native = _native._Sequence(os.fspath(path), float(rate_hz), str(image_topic))

    def __len__(self) -> int:
        return len(self._native)

    def __getitem__(self, index):
        if isinstance(index, slice):
            return [self._native[k] for k in range(*index.indices(len(self)))]
        if isinstance(index, (bool, np.bool_)) or not hasattr(index, "__index__"):
            raise TypeError(f"Sequence indices must be integers or slices, not {type(index).__name__}")
        return self._native[index]

    def __iter__(self):
        for k in range(len(self)):
            yield self._native[k]

    # collections.abc.Sequence compares elements with ==, which NumPy answers elementwise (and
    # `frame in seq` with "truth value of an array is ambiguous"): frames compare as whole arrays.
    def __contains__(self, value) -> bool:
        return any(np.array_equal(frame, value) for frame in self)

    def index(self, value, start: int = 0, stop: Optional[int] = None) -> int:
        for k in range(*slice(start, stop).indices(len(self))):
            if np.array_equal(self._native[k], value):
                return k
        raise ValueError("the frame is not in the sequence")

    def count(self, value) -> int:
        return sum(1 for frame in self if np.array_equal(frame, value))

    def __fspath__(self) -> str:
        return self._native.path

    def __repr__(self) -> str:
        return f"<inertialnet.Sequence {self.path!r}: {len(self)} frames, {self.description}>"

    @property
    def path(self) -> str:
        return self._native.path

    @property
    def image_topic(self) -> str:
        """A ROS bag's image topic as given ("": the bag's only one, or not a bag)."""
        return self._native.image_topic

    @property
    def rate_hz(self) -> float:
        """The frame rate given (0: the source's frame times)."""
        return self._native.rate_hz

    @property
    def sequential(self) -> bool:
        """True for a video: frames decode in order, a step back re-decodes from the start."""
        return self._native.sequential

    @property
    def timestamps_ns(self) -> np.ndarray:
        return self._native.timestamps_ns

    @property
    def camera(self) -> Optional[_native.Camera]:
        return self._native.camera

    @property
    def camera_to_body(self) -> Optional[np.ndarray]:
        return self._native.camera_to_body

    @property
    def description(self) -> str:
        return self._native.description

