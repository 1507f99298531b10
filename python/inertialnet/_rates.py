# SPDX-License-Identifier: Apache-2.0
"""The rates of :func:`inertialnet.predict`: one row per frame pair, with what the rates CSV states.

A :class:`Rates` is what ``inertialnet predict`` writes to its CSV (schema ``inertialnet.rates/4``,
docs/data_conventions.md), in memory: the timestamps, each estimator's rates and status words, and
the metadata of its sidecar (the frame of the rates, the estimator, the camera-IMU time offset and
the readout time that predict was given). :func:`inertialnet.evaluate` reads that metadata exactly
as ``inertialnet eval`` reads the CSV's; a bare array of rates lost it, and the target and the frame
were then guessed (3.60 deg/s instead of 0.093 on the README's example).
"""

from __future__ import annotations

import os
from typing import Dict, List, Optional, Sequence as _Seq, Tuple, Union

import numpy as np

from . import _inertialnet as _native

PathLike = Union[str, "os.PathLike[str]"]


def _is_status(name: str) -> bool:
    return name == "status" or name.startswith("status_")


class Rates:
    """Angular rates of frame pairs, numpy-like.

    ``rates.timestamps_ns`` (int64 ``(N,)``, each pair's second frame), ``rates.w`` (float64
    ``(N, 3)`` rad/s, NaN where the pair has no answer), ``rates.status`` (str ``(N,)``: ``"ok"``
    or why not, e.g. ``"no_texture"``), ``rates.estimator`` (``"inter_frame"`` or ``"network"``),
    ``rates.frame`` (``"body"`` or ``"camera"``), ``rates.time_offset_s``,
    ``rates.readout_time_s`` and ``rates.metadata`` (every key of the CSV's sidecar, or of a schema-2 file's ``# key: value`` lines).

    ``np.asarray(rates)`` is ``rates.w``; ``len(rates)`` the number of pairs; ``rates["wx"]``,
    ``rates["status_geometric"]``, … a column of the CSV (``rates.columns`` lists them);
    ``rates[i]`` a row as a dict; ``rates[2:5]``, ``rates[mask]`` the selected rows as Rates with
    the same metadata. ``rates.head("geometric")`` is the second estimator of ``head="both"``.
    ``rates.to_csv(path)`` writes the CLI's rates CSV and :func:`read_rates` reads it back.
    """

    def __init__(self, timestamps_ns, columns: Dict[str, np.ndarray], metadata: Optional[Dict[str, str]] = None):
        self._t = np.asarray(timestamps_ns, dtype=np.int64).reshape(-1)
        self._columns: Dict[str, np.ndarray] = {}
        for name, values in columns.items():
            values = np.asarray(values, dtype=str if _is_status(name) else np.float64).reshape(-1)
            if len(values) != len(self._t):
                raise ValueError(f"column {name} has {len(values)} values for {len(self._t)} timestamps")
            self._columns[name] = values
        for name in ("wx", "wy", "wz"):
            if name not in self._columns:
                raise ValueError(f"rates need the columns wx, wy, wz; {name} is missing")
        if "status" not in self._columns:  # schema 1: every row answered
            self._columns["status"] = np.full(len(self._t), "ok", dtype="U16")
        self.metadata: Dict[str, str] = dict(metadata or {})

    # --- what the rates are ---------------------------------------------------------------------

    @property
    def timestamps_ns(self) -> np.ndarray:
        return self._t

    @property
    def w(self) -> np.ndarray:
        """float64 ``(N, 3)`` rad/s: wx, wy, wz; NaN on rows whose status is not ok."""
        return np.stack([self._columns["wx"], self._columns["wy"], self._columns["wz"]], axis=1)

    @property
    def sigma(self) -> np.ndarray:
        """float64 ``(N, 3)`` rad/s: each rate's standard deviation (sigma_wx, sigma_wy, sigma_wz);
        NaN where not known (the learned head, a schema-3 file, a pair without an answer)."""
        names = ("sigma_wx", "sigma_wy", "sigma_wz")
        return np.stack([self._columns.get(n, np.full(len(self._t), np.nan)) for n in names], axis=1)

    @property
    def status(self) -> np.ndarray:
        return self._columns["status"]

    @property
    def ok(self) -> np.ndarray:
        """bool ``(N,)``: the rows whose status is ok."""
        return self.status == "ok"

    @property
    def estimator(self) -> Optional[str]:
        """``"inter_frame"`` (the rotation between two frames: the rate's mean over the interval),
        ``"network"`` (InertialNet), or None where unstated."""
        return self.metadata.get("estimator")

    @property
    def frame(self) -> Optional[str]:
        """``"body"`` (the IMU's frame) or ``"camera"``, or None where unstated."""
        return self.metadata.get("frame")

    @property
    def time_offset_s(self) -> Optional[float]:
        """The camera-IMU time offset predict was given (t_imu = t_cam + offset), or None."""
        value = self.metadata.get("time_offset_s")
        return None if value is None else float(value)

    @property
    def readout_time_s(self) -> float:
        """The rolling-shutter readout time predict was given (0: global shutter)."""
        return float(self.metadata.get("readout_time_s", 0.0))

    @property
    def columns(self) -> List[str]:
        """The CSV's header: ``timestamp_ns``, ``wx``, ``wy``, ``wz``, ``status``, then any
        further group (``wx_geometric``, …, ``status_geometric``)."""
        return ["timestamp_ns", *self._columns]

    @property
    def heads(self) -> List[str]:
        """The estimators' column suffixes without ``_``: ``[""]``, or ``["", "geometric"]``."""
        return [""] + [name[3:] for name in self._columns if name.startswith("wx_")]  # not sigma_wx_…

    def head(self, name: str) -> "Rates":
        """The estimator whose columns end in ``_name`` (``"geometric"`` of ``head="both"``) as
        Rates of its own: its columns as wx, wy, wz, status, its frame and estimator."""
        if name == "":
            return self
        suffix = "_" + name
        if "wx" + suffix not in self._columns:
            raise ValueError(f"no estimator '{name}': the rates hold {', '.join(repr(h) for h in self.heads)}")
        columns = {c: self._columns[c + suffix] for c in ("wx", "wy", "wz", "status", "sigma_wx", "sigma_wy", "sigma_wz")
                   if c + suffix in self._columns}
        metadata = {k: v for k, v in self.metadata.items() if not k.endswith(tuple("_" + h for h in self.heads[1:]))}
        for key in ("frame", "estimator"):
            # The CSV's rule: frame_<name> defaults to frame; an estimator is stated per group.
            if key + suffix in self.metadata:
                metadata[key] = self.metadata[key + suffix]
            elif key == "estimator":
                metadata.pop(key, None)
        return Rates(self._t, columns, metadata)

    # --- numpy-like -----------------------------------------------------------------------------

    def __len__(self) -> int:
        return len(self._t)

    def __array__(self, dtype=None, copy=None):
        w = self.w
        return w if dtype is None else w.astype(dtype)

    def __getitem__(self, key):
        if isinstance(key, str):
            if key == "timestamp_ns":
                return self._t
            try:
                return self._columns[key]
            except KeyError:
                raise KeyError(f"no column '{key}'; the columns are {', '.join(self.columns)}") from None
        if isinstance(key, (int, np.integer)):
            row = {"timestamp_ns": int(self._t[key])}
            row.update({n: (str(c[key]) if _is_status(n) else float(c[key])) for n, c in self._columns.items()})
            return row
        # A slice, a boolean mask or indices: the rows, with the metadata.
        return Rates(self._t[key], {n: c[key] for n, c in self._columns.items()}, self.metadata)

    def __iter__(self):
        return (self[i] for i in range(len(self)))

    def __repr__(self) -> str:
        ok = int(np.count_nonzero(self.ok))
        stated = [f"{key}={self.metadata[key]}" for key in ("estimator", "frame", "time_offset_s", "readout_time_s")
                  if key in self.metadata]
        extra = [h for h in self.heads if h]
        return (f"<inertialnet.Rates {len(self)} pairs ({ok} ok)" + "".join(", " + s for s in stated) +
                (f", heads {extra}" if extra else "") + ">")

    # --- files and other forms ------------------------------------------------------------------

    def to_csv(self, path: PathLike) -> None:
        """Writes the CLI's rates CSV (atomically), metadata included: ``inertialnet eval`` and
        :func:`evaluate` read it as they read ``inertialnet predict -o``'s."""
        numeric = [n for n in self._columns if not _is_status(n)]
        status_names = [n for n in self._columns if _is_status(n)]
        values = (np.stack([self._columns[n] for n in numeric], axis=1) if len(self)
                  else np.zeros((0, len(numeric))))
        _native._write_rates_csv(os.fspath(path), numeric, self._t, values, status_names,
                                 [[str(s) for s in self._columns[n]] for n in status_names],
                                 list(self.metadata.items()))

    def to_records(self) -> np.ndarray:
        """A NumPy structured array with the CSV's columns (what predict() returned before Rates)."""
        dtype = [("timestamp_ns", np.int64)] + [(n, "U16" if _is_status(n) else np.float64) for n in self._columns]
        out = np.zeros(len(self), dtype=dtype)
        out["timestamp_ns"] = self._t
        for name, values in self._columns.items():
            out[name] = values
        return out

    def to_pandas(self):
        """A pandas DataFrame of the columns, indexed by timestamp_ns; the metadata in ``.attrs``."""
        import pandas

        frame = pandas.DataFrame(dict(self._columns), index=pandas.Index(self._t, name="timestamp_ns"))
        frame.attrs.update(self.metadata)
        return frame

    @classmethod
    def from_records(cls, records: np.ndarray, metadata: Optional[Dict[str, str]] = None) -> "Rates":
        """From a structured array with the CSV's columns (timestamp_ns first)."""
        names = list(records.dtype.names or ())
        if not names or names[0] != "timestamp_ns":
            raise ValueError("a rates array needs the fields timestamp_ns, wx, wy, wz (and status); got "
                             f"{names or records.dtype}")
        return cls(records["timestamp_ns"], {n: records[n] for n in names[1:]}, metadata)


def read_rates(path: PathLike) -> Rates:
    """A rates CSV (``inertialnet predict -o``'s, or :meth:`Rates.to_csv`'s) as :class:`Rates`,
    with its metadata; checked as ``inertialnet eval`` checks it."""
    numeric, t, values, status_names, statuses, metadata = _native._read_rates_csv(os.fspath(path))
    columns: Dict[str, np.ndarray] = {}
    # The CSV's order: each group's wx, wy, wz, then its status column.
    for i, name in enumerate(numeric):
        columns[name] = values[:, i]
        status = "status" + name[2:] if name.startswith("wz") else None
        if status in status_names:
            columns[status] = np.asarray(statuses[status_names.index(status)], dtype=str)
    for name, words in zip(status_names, statuses):
        columns.setdefault(name, np.asarray(words, dtype=str))
    return Rates(t, columns, dict(metadata))


def _rates_of_predict(names: _Seq[str], t_ns, values, statuses, metadata: _Seq[Tuple[str, str]], sigmas=None) -> Rates:
    """predict()'s native result (estimator columns wx,wy,wz[,wx_geometric,…], status words rows ×
    estimators, the metadata the CLI's CSV states, each rate's σ) as Rates, in the CSV's column order."""
    columns: Dict[str, np.ndarray] = {}
    for e in range(len(names) // 3):
        for i in range(3 * e, 3 * e + 3):
            columns[names[i]] = values[:, i]
        columns["status" + names[3 * e][2:]] = np.asarray([row[e] for row in statuses], dtype=str).reshape(-1)
        for i in range(3 * e, 3 * e + 3):
            columns["sigma_" + names[i]] = (sigmas[:, i] if sigmas is not None
                                            else np.full(len(columns[names[i]]), np.nan))
    return Rates(t_ns, columns, dict(metadata))
