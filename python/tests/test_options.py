# SPDX-License-Identifier: Apache-2.0
"""The keywords predict(), batch.predict() and stream() share are defined once
(inertialnet/_options.py) and reach the native module by one path: the three public signatures
stay what docs/python.md documents, a keyword a function does not take is Python's TypeError, and
the native module refuses a keyword it does not know."""
import inspect
import re

import pytest

import inertialnet
import inertialnet.batch
from inertialnet import _inertialnet as _native

# The signatures as they were when each function spelled its keywords itself.
SIGNATURES = {
    inertialnet.predict: "(sequence: 'SequenceLike', weights: 'Weights' = (), *, flow: 'Optional[str]' = None, head: 'Optional[str]' = None, model: 'Optional[str]' = None, solver: 'str' = 'motion-field', fx: 'Optional[float]' = None, fy: 'Optional[float]' = None, cx: 'Optional[float]' = None, cy: 'Optional[float]' = None, calibration: 'Optional[PathLike]' = None, calibration_camera: 'str' = '', image_topic: 'Optional[str]' = None, camera_info_topic: 'str' = '', rate_hz: 'float' = 0.0, camera: 'str' = 'cam0', time_offset: 'Optional[float]' = None, readout_time: 'float' = 0.0, device: 'DeviceLike' = None, max_pairs: 'int' = 0, lanes: 'int' = 2, decode_threads: 'int' = 2, keep_flow: 'bool' = False, flow_check: 'float' = 0.5, progress: 'Optional[Callable[[int, int], object]]' = None, max_sigma: 'float' = 10.0, smooth: 'str' = 'lag:2', fuse: 'bool' = False)",
    inertialnet.batch.predict: "(sequences: 'Union[PathLike, Iterable[PathLike]]', out_dir: 'PathLike', weights: 'Union[PathLike, Iterable[PathLike]]' = (), *, cluster: 'Optional[str]' = None, max_retries: 'int' = 3, num_gpus: 'Optional[float]' = None, progress: 'Optional[Callable[[Dict[str, object]], object]]' = None, task_progress: 'Optional[Callable[[str, int, int], object]]' = <function _print_progress>, flow: 'Optional[str]' = None, head: 'Optional[str]' = None, model: 'Optional[str]' = None, solver: 'str' = 'motion-field', fx: 'Optional[float]' = None, fy: 'Optional[float]' = None, cx: 'Optional[float]' = None, cy: 'Optional[float]' = None, calibration: 'Optional[PathLike]' = None, calibration_camera: 'str' = '', image_topic: 'str' = '', camera_info_topic: 'str' = '', rate_hz: 'float' = 0.0, camera: 'str' = 'cam0', time_offset: 'Optional[float]' = None, readout_time: 'float' = 0.0, device: 'Optional[str]' = None, max_pairs: 'int' = 0, lanes: 'int' = 1, decode_threads: 'int' = 2, flow_check: 'float' = 0.5, max_sigma: 'float' = 10.0, smooth: 'str' = 'lag:2', fuse: 'bool' = False) -> 'List[Dict[str, object]]'",
    inertialnet.stream: "(sequence: 'PathLike', weights: 'Union[PathLike, Iterable[PathLike]]' = (), *, flow: 'Optional[str]' = None, head: 'Optional[str]' = None, model: 'Optional[str]' = None, solver: 'str' = 'motion-field', fx: 'Optional[float]' = None, fy: 'Optional[float]' = None, cx: 'Optional[float]' = None, cy: 'Optional[float]' = None, calibration: 'Optional[PathLike]' = None, calibration_camera: 'str' = '', rate_hz: 'float' = 0.0, camera: 'str' = 'cam0', device: 'Union[None, str, int]' = None, max_pairs: 'int' = 0, lanes: 'int' = 2, flow_check: 'float' = 0.5, max_sigma: 'float' = 10.0, smooth: 'str' = 'lag:2', fuse: 'bool' = False) -> 'Iterator[Tuple[int, np.ndarray, Union[str, Tuple[str, ...]]]]'",
}


@pytest.mark.parametrize("function", list(SIGNATURES), ids=["predict", "batch.predict", "stream"])
def test_public_signatures_are_unchanged(function):
    shown = re.sub(r" at 0x[0-9a-f]+", "", str(inspect.signature(function)))
    assert shown == SIGNATURES[function]


def test_a_keyword_a_function_does_not_take_is_a_type_error(sequence):
    with pytest.raises(TypeError, match="keep_flow"):
        inertialnet.stream(sequence, keep_flow=True)
    with pytest.raises(TypeError, match="flow_chek"):
        inertialnet.predict(sequence, flow_chek=0.5)
    with pytest.raises(TypeError):
        inertialnet.predict(sequence, sequence, sequence)  # one positional too many


def test_the_native_module_refuses_an_unknown_or_missing_keyword(sequence):
    options = inertialnet._options.PredictOptions().native()
    with pytest.raises(TypeError, match="unexpected predict keyword typo"):
        _native._predict(str(sequence), [], **options, typo=1)
    del options["fuse"]
    with pytest.raises(TypeError, match="missing predict keyword fuse"):
        _native._predict(str(sequence), [], **options)
