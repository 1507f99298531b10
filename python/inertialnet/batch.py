# SPDX-License-Identifier: Apache-2.0
"""Many sequences at once, on one machine or a Ray cluster (docs/batch.md).

``predict(sequences, out_dir)`` writes one rates file per sequence into ``out_dir``, the files of
``inertialnet predict SEQ... -o OUT_DIR`` to the byte (the same names, rows, sidecar and the
provenance block that records what made each file), and skips a sequence whose file is complete
and current by the CLI's own rule (the same library code decides): an interrupted batch resumes.
With ``cluster`` each sequence is one Ray task (PyPI ``ray``: ``pip install inertialnet[ray]``),
retried when its worker dies; a task that dies mid-sequence leaves only ``<name>.csv.partial``,
which is never taken as complete. ``evaluate(rates, sequences)`` prints the table of
``inertialnet eval RATES... --seq SEQ...``.
"""

from __future__ import annotations

import glob as _glob
import os
import sys
from typing import Callable, Dict, Iterable, List, Optional, Sequence as _Seq, Union

from . import _inertialnet as _native
from ._options import PredictOptions, takes_predict_options

PathLike = Union[str, "os.PathLike[str]"]

__all__ = ["predict", "evaluate", "sequences_of"]


def sequences_of(sequences: Union[PathLike, Iterable[PathLike]]) -> List[str]:
    """The sequences a batch takes: a list of paths; or one string that is a glob pattern
    (``"data/*/"``, sorted), a manifest file (``.txt``: one path a line, as ``predict --manifest``
    reads it) or a single sequence."""
    return _sequences_and_manifest(sequences)[0]


def _sequences_and_manifest(sequences: Union[PathLike, Iterable[PathLike]]):
    """sequences_of's list, and the manifest it came from ("" when none)."""
    if isinstance(sequences, (str, os.PathLike)):
        text = os.fspath(sequences)
        if any(c in text for c in "*?["):
            found = sorted(_glob.glob(text))
            if not found:
                raise ValueError(f"the pattern {text} matches no sequence")
            return found, ""
        if text.endswith(".txt") and os.path.isfile(text):
            return list(_native._read_batch_manifest(text)), text
        return [text], ""
    found = [os.fspath(s) for s in sequences]
    if not found:
        raise ValueError("no sequence given")
    return found, ""


def _import_ray():
    """Ray, or ImportError. A folder named ray on the path (Ray's own /tmp/ray, when Python runs
    from /tmp) imports as an empty namespace package: that is no Ray either."""
    import ray
    if not hasattr(ray, "init"):
        raise ImportError(f"no Ray package (found only the folder {list(getattr(ray, '__path__', []))})")
    return ray


def _device_wants_gpu(device: str) -> bool:
    """Whether the device spec (as predict's ``device=``) selects a GPU here."""
    try:
        return any(d.get("type") == "gpu" for d in _native.select_devices(device))
    except Exception:  # no OpenCL platform on the driver: the workers decide for themselves
        return False


def _predict_one(sequence: str, rates: str, weights: List[str], options: Dict[str, object],
                 task_progress: Optional[Callable[[str, int, int], object]]) -> Dict[str, object]:
    """One sequence into its rates file (skipped when complete and current): what each task runs."""
    name = os.path.splitext(os.path.basename(rates))[0]
    progress = None
    if task_progress is not None:
        def progress(done, total):
            task_progress(name, done, total)
    result = dict(_native._predict_rates_file(rates, True, sequence, weights, **dict(options, progress=progress)))
    result.update(sequence=sequence, rates=rates, name=name)
    return result


def _print_progress(name: str, done: int, total: int) -> None:
    """The default progress of a task: a line per sequence at its end (Ray forwards a worker's
    standard error to the driver)."""
    if done == total:
        print(f"inertialnet: {name}: {done} of {total} pairs", file=sys.stderr, flush=True)


# inertialnet.predict()'s keywords but keep_flow (the batch writes files) and its progress (the
# batch's own, per sequence), with a spec string for device and one lane per task.
@takes_predict_options(
    omit=("keep_flow", "progress"), defaults={"image_topic": "", "lanes": 1},
    annotations={"image_topic": "str", "device": "Optional[str]"})
def predict(
    sequences: Union[PathLike, Iterable[PathLike]],
    out_dir: PathLike,
    weights: Union[PathLike, Iterable[PathLike]] = (),
    *,
    cluster: Optional[str] = None,
    max_retries: int = 3,
    num_gpus: Optional[float] = None,
    progress: Optional[Callable[[Dict[str, object]], object]] = None,
    task_progress: Optional[Callable[[str, int, int], object]] = _print_progress,
    options: PredictOptions,
) -> List[Dict[str, object]]:
    """Rates of every sequence into ``out_dir/<name>.csv``, as ``inertialnet predict SEQ... -o
    OUT_DIR`` writes them; returns one dict per sequence, in order: ``name``, ``sequence``,
    ``rates`` (the file), ``status`` (``"computed"`` or ``"skipped"`` when its file was complete
    and current), ``reason`` (why it was computed), ``pairs``, ``unanswered`` (a summary of the
    pairs without an answer, "" when none).

    ``cluster``: None runs the sequences one after another in this process (no Ray needed);
    ``"auto"`` joins the Ray cluster this machine belongs to (``ray start --head`` / ``ray start
    --address``), any other string is a cluster's address (``"ray://head:10001"``); a Ray already
    initialised in this process (``ray.init(...)``) is used as it is. Each sequence is then one
    task, retried up to ``max_retries`` times when its worker dies (a bad sequence is not retried:
    its error is raised). A task asks Ray for ``num_gpus`` GPUs; None: 1 when ``device`` selects a
    GPU here, else 0.

    ``progress(result)``, if given, is called on this thread as each sequence finishes (the dict
    above). ``task_progress(name, done, total)`` runs inside each task as pairs complete (by default
    a line at each sequence's end on standard error, which Ray forwards to the driver's).

    The other arguments are :func:`inertialnet.predict`'s (the CLI's options); ``device`` is a spec
    string. Errors as :func:`inertialnet.predict`: ``ValueError`` for bad input (two sequences of
    one name, an unreadable sequence), ``RuntimeError`` for a device failure."""
    seqs, manifest = _sequences_and_manifest(sequences)
    out_dir = os.fspath(out_dir)
    if os.path.exists(out_dir) and not os.path.isdir(out_dir):
        raise ValueError(f"out_dir {out_dir}: it exists and is not a folder")
    outputs = list(_native._batch_rates_paths(seqs, out_dir))
    # As the CLI: every sequence is there before the first is computed (a manifest's by its line).
    _native._require_batch_sequences([] if manifest else seqs, manifest)
    os.makedirs(out_dir, exist_ok=True)
    if isinstance(weights, (str, os.PathLike)):
        weights = [weights]
    # What each task passes to the native module (picklable for Ray; the progress is the task's own).
    native = options.native()
    weight_files = [os.fspath(w) for w in weights]
    results: List[Dict[str, object]] = []
    if cluster is None:
        try:
            initialised = _import_ray().is_initialized()  # a Ray the caller initialised is used
        except ImportError:
            initialised = False
        if not initialised:
            for sequence, rates in zip(seqs, outputs):
                result = _predict_one(sequence, rates, weight_files, native, task_progress)
                if progress is not None:
                    progress(result)
                results.append(result)
            return results
    return _predict_on_ray(seqs, outputs, weight_files, native, cluster, max_retries, num_gpus, progress,
                           task_progress)


def _predict_on_ray(seqs, outputs, weight_files, options, cluster, max_retries, num_gpus, progress, task_progress):
    try:
        ray = _import_ray()
    except ImportError as e:  # the optional extra
        raise ImportError("inertialnet.batch.predict(cluster=...) needs Ray: pip install 'inertialnet[ray]' "
                          "(or pip install ray)") from e
    if not ray.is_initialized():
        ray.init(address=cluster, log_to_driver=True)
    gpus = num_gpus if num_gpus is not None else (1 if _device_wants_gpu(options["device"]) else 0)
    # Ray retries a task whose worker died (max_retries); an exception the task raises (bad input)
    # is not retried: it is the answer.
    task = ray.remote(num_gpus=gpus, max_retries=max_retries, retry_exceptions=False)(_predict_one)
    pending = {task.remote(s, r, weight_files, options, task_progress): i for i, (s, r) in enumerate(zip(seqs, outputs))}
    results: List[Optional[Dict[str, object]]] = [None] * len(seqs)
    waiting = list(pending)
    while waiting:
        done, waiting = ray.wait(waiting, num_returns=1)
        for ref in done:
            try:
                result = ray.get(ref)
            except ray.exceptions.RayTaskError as e:
                # The task's own exception (ValueError for bad input, …), not Ray's wrapper.
                cause = e.as_instanceof_cause()
                raise (cause.cause if getattr(cause, "cause", None) is not None else cause) from None
            results[pending[ref]] = result
            if progress is not None:
                progress(result)
    return results  # type: ignore[return-value]


def evaluate(rates: Union[PathLike, _Seq[PathLike]], sequences: _Seq[PathLike] = (), *, format: str = "text",
             plot: Optional[PathLike] = None, target: Optional[str] = None, head: Optional[str] = None) -> str:
    """The table of ``inertialnet eval RATES... --seq SEQ...`` (or ``eval FOLDER`` when
    ``sequences`` is empty: each rates file's sidecar names its sequence): one row per sequence
    (images, IMU samples, evaluated pairs, RMSE of wx, wy, wz in deg/s, the zero predictor's RMSE,
    pairs without an answer) and the total, which pools every evaluated pair. ``format``: "text",
    "csv" or "json" (schema ``inertialnet.eval_table/1``). With ``plot`` (a folder): one plot per
    sequence and ``summary.png``."""
    if isinstance(rates, (str, os.PathLike)):
        rates = [rates]
    return _native._eval_table([os.fspath(r) for r in rates], [os.fspath(s) for s in sequences], format,
                               "" if plot is None else os.fspath(plot), target or "", head or "")
