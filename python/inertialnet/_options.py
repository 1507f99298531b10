# SPDX-License-Identifier: Apache-2.0
"""The keyword arguments that :func:`inertialnet.predict`, :func:`inertialnet.batch.predict` and
:func:`inertialnet.stream` share (the CLI's ``predict`` options), defined once: their names, types
and defaults in :class:`PredictOptions`, how each reaches the native module in
:meth:`PredictOptions.native` (read by ``python_predict_options``, python/src/bindings.cpp).

A public function takes them through :func:`takes_predict_options`, which gives it the signature
it shows (``help()``, ``inspect.signature``) and binds a call's arguments against it. A new
predict option is one field here (after the option it follows in ``predict()``), one line in
``native()`` and one key in ``python_predict_options``; each function that should not take it
names it in ``omit``."""

from __future__ import annotations

import dataclasses
import functools
import inspect
import os
from typing import Callable, Dict, Optional, Union

from ._inertialnet import Device

PathLike = Union[str, "os.PathLike[str]"]


@dataclasses.dataclass(frozen=True)
class PredictOptions:
    """In ``predict()``'s order, with its annotations and defaults (``DeviceLike`` is predict's
    name for ``None``, a device spec, an index or a :class:`Device`)."""

    flow: Optional[str] = None
    head: Optional[str] = None
    model: Optional[str] = None
    solver: str = "motion-field"
    fx: Optional[float] = None
    fy: Optional[float] = None
    cx: Optional[float] = None
    cy: Optional[float] = None
    calibration: Optional[PathLike] = None
    calibration_camera: str = ""
    image_topic: Optional[str] = None
    camera_info_topic: str = ""
    rate_hz: float = 0.0
    camera: str = "cam0"
    time_offset: Optional[float] = None
    readout_time: float = 0.0
    device: DeviceLike = None  # noqa: F821  (a name in predict()'s module: the annotation is text)
    max_pairs: int = 0
    lanes: int = 2
    decode_threads: int = 2
    keep_flow: bool = False
    flow_check: float = 0.5
    progress: Optional[Callable[[int, int], object]] = None
    max_sigma: float = 10.0
    smooth: str = "lag:2"
    fuse: bool = False

    def native(self) -> Dict[str, object]:
        """The keywords of the native ``_predict``, ``_predict_rates_file`` and ``_Stream``."""
        def number(value):
            return None if value is None else float(value)

        return dict(
            flow=self.flow or "", head=self.head or "", model=self.model or "", solver=self.solver,
            fx=number(self.fx), fy=number(self.fy), cx=number(self.cx), cy=number(self.cy),
            calibration="" if self.calibration is None else os.fspath(self.calibration),
            calibration_camera=self.calibration_camera, image_topic=self.image_topic or "",
            camera_info_topic=self.camera_info_topic, rate_hz=float(self.rate_hz), camera=self.camera,
            time_offset=number(self.time_offset), readout_time=float(self.readout_time),
            device=device_spec(self.device), max_pairs=self.max_pairs, lanes=int(self.lanes),
            decode_threads=int(self.decode_threads), keep_flow=self.keep_flow, flow_check=float(self.flow_check),
            progress=self.progress, max_sigma=float(self.max_sigma), smooth=str(self.smooth), fuse=self.fuse)


def device_spec(device) -> str:
    """``device=`` as the spec string the library takes: None, a spec, an index or a
    :class:`Device` (its global index), as the model constructors take it."""
    if device is None:
        return ""
    if isinstance(device, Device):
        return str(device.info["index"])
    if isinstance(device, bool) or not isinstance(device, (str, int)):
        raise TypeError(f"device must be None, a device spec string, an index or an inertialnet.Device, "
                        f"not {type(device).__name__}")
    return str(device)


def takes_predict_options(*, omit=(), defaults: Optional[Dict[str, object]] = None,
                          annotations: Optional[Dict[str, str]] = None):
    """Decorates ``fn(positional..., *, own keywords..., options: PredictOptions)``: the function
    shows and takes its own parameters followed by every field of :class:`PredictOptions` not in
    ``omit`` (keyword-only, with ``defaults`` and ``annotations`` replacing the field's), and
    receives them as ``options``. Unknown or missing arguments are Python's own ``TypeError``."""
    defaults = defaults or {}
    annotations = annotations or {}

    def decorate(fn):
        own = [p for p in inspect.signature(fn).parameters.values() if p.name != "options"]
        shared = [
            inspect.Parameter(f.name, inspect.Parameter.KEYWORD_ONLY, default=defaults.get(f.name, f.default),
                              annotation=annotations.get(f.name, f.type))
            for f in dataclasses.fields(PredictOptions) if f.name not in omit
        ]
        signature = inspect.signature(fn).replace(parameters=own + shared)
        names = {p.name for p in shared}

        @functools.wraps(fn)
        def call(*args, **kwargs):
            bound = signature.bind(*args, **kwargs)
            bound.apply_defaults()
            given = {k: v for k, v in bound.arguments.items() if k not in names}
            options = PredictOptions(**{k: v for k, v in bound.arguments.items() if k in names})
            return fn(**given, options=options)

        call.__signature__ = signature
        return call

    return decorate
