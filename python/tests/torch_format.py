# SPDX-License-Identifier: Apache-2.0
"""An independent writer of torch checkpoints, for the converter's tests, without torch.

It writes what torch.save writes (torch/serialization.py), from numpy arrays:

* the zip format (torch >= 1.6): ``<prefix>/data.pkl`` (pickle protocol 2; each storage a
  persistent id ``('storage', torch.FloatStorage, key, location, numel)``), ``<prefix>/byteorder``,
  ``<prefix>/data/<key>`` (raw little-endian elements) and ``<prefix>/version``;
* the legacy format (torch < 1.6, and ``_use_new_zipfile_serialization=False``): the pickles of
  the magic number, the protocol version 1001 and the system information, the object pickle
  (persistent ids ``('storage', torch.FloatStorage, key, location, numel, None)``), the sorted
  storage keys, then per storage its element count (int64) and its elements.

Tensors are pickled as torch pickles them: ``torch._utils._rebuild_tensor_v2(storage, offset,
size, stride, requires_grad, OrderedDict())`` (torch >= 0.4), or ``_rebuild_tensor(storage,
offset, size, stride)`` (torch 0.3, ``rebuild="v1"``). Python's pickler can only name a global
it can import, so stand-in ``torch`` and ``torch._utils`` modules are installed in sys.modules
while pickling, and the previous entries (a real torch among them) are put back afterwards.

When torch itself is importable, ``torch_save`` writes with the real torch.save instead, so that
the tests check the reader against torch too.
"""

import collections
import contextlib
import io
import pickle
import struct
import sys
import types
import zipfile

import numpy as np

STORAGE_OF = {np.dtype(np.float32): "FloatStorage", np.dtype(np.float64): "DoubleStorage",
              np.dtype(np.float16): "HalfStorage", np.dtype(np.int64): "LongStorage"}


class StoredTensor:
    """A tensor to write: a view (offset, shape, stride in elements) of a storage's elements."""

    def __init__(self, storage, offset, shape, stride, rebuild="v2"):
        self.storage, self.offset, self.shape, self.stride, self.rebuild = storage, offset, tuple(shape), tuple(stride), rebuild

    @staticmethod
    def of(array, rebuild="v2"):
        a = np.ascontiguousarray(array)
        strides = tuple(s // a.itemsize for s in a.strides)
        return StoredTensor(Storage(a.reshape(-1)), 0, a.shape, strides, rebuild)


class Storage:
    def __init__(self, elements):
        self.elements = np.ascontiguousarray(elements).reshape(-1)


@contextlib.contextmanager
def _stand_in_torch():
    torch = types.ModuleType("torch")
    utils = types.ModuleType("torch._utils")

    def _rebuild_tensor_v2(*args):  # never called: only its name is pickled
        raise AssertionError

    def _rebuild_tensor(*args):
        raise AssertionError

    for f in (_rebuild_tensor_v2, _rebuild_tensor):
        f.__module__, f.__qualname__ = "torch._utils", f.__name__
        setattr(utils, f.__name__, f)
    torch._utils = utils
    for name in STORAGE_OF.values():
        cls = type(name, (), {"__module__": "torch"})
        setattr(torch, name, cls)
    saved = {k: sys.modules.get(k) for k in ("torch", "torch._utils")}
    sys.modules["torch"], sys.modules["torch._utils"] = torch, utils
    try:
        yield torch
    finally:
        for k, v in saved.items():
            if v is None:
                sys.modules.pop(k, None)
            else:
                sys.modules[k] = v


class _Pickler(pickle.Pickler):
    def __init__(self, file, torch, legacy, location):
        super().__init__(file, protocol=2)
        self.torch, self.legacy, self.location = torch, legacy, location
        self.storages = {}  # key -> Storage, in the order met

    def persistent_id(self, obj):
        if not isinstance(obj, Storage):
            return None
        key = next((k for k, s in self.storages.items() if s is obj), None)
        if key is None:
            key = str(len(self.storages))
            self.storages[key] = obj
        kind = getattr(self.torch, STORAGE_OF[obj.elements.dtype])
        pid = ("storage", kind, key, self.location, int(obj.elements.size))
        return pid + (None,) if self.legacy else pid

    def reducer_override(self, obj):
        if isinstance(obj, StoredTensor):
            if obj.rebuild == "v1":
                return self.torch._utils._rebuild_tensor, (obj.storage, obj.offset, obj.shape, obj.stride)
            return (self.torch._utils._rebuild_tensor_v2,
                    (obj.storage, obj.offset, obj.shape, obj.stride, False, collections.OrderedDict()))
        return NotImplemented


def _as_stored(obj):
    """Replaces numpy arrays by StoredTensor, recursively through dicts, lists and tuples."""
    if isinstance(obj, np.ndarray):
        return StoredTensor.of(obj)
    if isinstance(obj, collections.OrderedDict):
        out = collections.OrderedDict((k, _as_stored(v)) for k, v in obj.items())
        out.__dict__.update(obj.__dict__)  # a state dict's _metadata
        return out
    if isinstance(obj, dict):
        return {k: _as_stored(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return type(obj)(_as_stored(v) for v in obj)
    return obj


def write_zip(path, obj, prefix="archive", location="cpu"):
    """torch.save(obj, path) in the zip format."""
    with _stand_in_torch() as torch:
        buffer = io.BytesIO()
        pickler = _Pickler(buffer, torch, legacy=False, location=location)
        pickler.dump(_as_stored(obj))
    with zipfile.ZipFile(path, "w", zipfile.ZIP_STORED) as z:
        z.writestr(f"{prefix}/data.pkl", buffer.getvalue())
        z.writestr(f"{prefix}/byteorder", "little")
        for key, storage in pickler.storages.items():
            z.writestr(f"{prefix}/data/{key}", storage.elements.astype(storage.elements.dtype.newbyteorder("<")).tobytes())
        z.writestr(f"{prefix}/version", "3\n")


def write_legacy(path, obj, location="cuda:0"):
    """torch.save(obj, path, _use_new_zipfile_serialization=False), as torch 0.4 - 1.5 wrote it."""
    with open(path, "wb") as f:
        pickle.dump(0x1950A86A20F9469CFC6C, f, protocol=2)
        pickle.dump(1001, f, protocol=2)
        pickle.dump({"protocol_version": 1001, "little_endian": True,
                     "type_sizes": {"short": 2, "int": 4, "long": 4}}, f, protocol=2)
        with _stand_in_torch() as torch:
            pickler = _Pickler(f, torch, legacy=True, location=location)
            pickler.dump(_as_stored(obj))
        keys = sorted(pickler.storages)
        pickle.dump(keys, f, protocol=2)
        for key in keys:
            elements = pickler.storages[key].elements
            f.write(struct.pack("<q", elements.size))
            f.write(elements.astype(elements.dtype.newbyteorder("<")).tobytes())


def state_dict(arrays, metadata=True):
    """An OrderedDict as nn.Module.state_dict() returns it (torch >= 0.4 adds _metadata)."""
    out = collections.OrderedDict(arrays)
    if metadata:
        modules = sorted({name.rsplit(".", 1)[0] for name in out})
        out._metadata = collections.OrderedDict([("", {"version": 1})] + [(m, {"version": 1}) for m in modules])
    return out


def nvidia_checkpoint(arrays):
    """What flownet2-pytorch's convert.py saved: {'epoch': 0, 'state_dict': ..., 'best_EPE': 1e10}."""
    return {"epoch": 0, "state_dict": state_dict(arrays), "best_EPE": 1e10}


def ptlflow_checkpoint(arrays, model="flownet2"):
    """A PyTorch Lightning checkpoint as ptlflow publishes them: the state dict beside Lightning's keys."""
    return {"epoch": 0, "global_step": 0, "pytorch-lightning_version": "1.3.8",
            "state_dict": state_dict(arrays), "callbacks": {}, "optimizer_states": [], "lr_schedulers": [],
            "hparams_name": "kwargs",
            "hyper_parameters": {"div_flow": 20.0, "input_channels": 12 if model == "flownet2" else 6,
                                 "batch_norm": False, "loss_norm": "L2", "train_size": [384, 448]}}


def torch_save(path, obj, legacy):
    """With real torch when it is importable (None otherwise): torch.save of the same object."""
    try:
        import torch
    except ImportError:
        return None

    def to_torch(o):
        if isinstance(o, np.ndarray):
            return torch.from_numpy(np.ascontiguousarray(o))
        if isinstance(o, collections.OrderedDict):
            out = collections.OrderedDict((k, to_torch(v)) for k, v in o.items())
            out.__dict__.update(o.__dict__)
            return out
        if isinstance(o, dict):
            return {k: to_torch(v) for k, v in o.items()}
        return o

    torch.save(to_torch(obj), path, _use_new_zipfile_serialization=not legacy)
    return path
