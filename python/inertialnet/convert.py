# SPDX-License-Identifier: Apache-2.0
"""FlowNet2 checkpoints as users can download them, converted to safetensors without torch.

    python -m inertialnet.convert CHECKPOINT OUTPUT.safetensors [--model KIND] [--check]
    python -m inertialnet.convert --list

Reads the two layouts that are published today (docs/weights.md has the table and the links):

* NVIDIA flownet2-pytorch: ``FlowNet2_checkpoint.pth.tar`` and the -C, -S, -SD, -CS, -CSS and
  -CSS-ft-sd files, ``{'epoch', 'state_dict', 'best_EPE'}`` saved by torch 0.x in the legacy
  serialisation (not a tar archive despite the name);
* ptlflow: ``flownet2-things-d63b53a7.ckpt`` and its siblings, PyTorch Lightning checkpoints
  ``{'state_dict', 'pytorch-lightning_version', 'hyper_parameters', ...}`` in torch's zip
  serialisation.

Both torch formats are read with Python's pickle through a restricted unpickler: only tensors,
storages, OrderedDict and plain Python values are rebuilt; any other global a pickle names is
refused with a message, never imported or called, so a checkpoint cannot run code here. Tensor
data is read with numpy, lazily, one tensor at a time.

The converter checks every name and shape against the model (this module's table, the same as
src/models/parameters.cpp; the tests compare both), computes the file's SHA-256, compares it with
the checksums published for these files (ptlflow's file names carry the first 8 hex digits, the
torch.hub convention; NVIDIA published none) and records where the weights came from in the
output's metadata (the ``inertialnet.checkpoint.*`` keys), which ``inertialnet weights --info``
prints.

Exit codes: 0 success; 1 runtime failure (I/O, --check mismatch); 2 bad usage or input.
"""

from __future__ import annotations

import argparse
import codecs
import collections
import hashlib
import io
import json
import os
import pickle
import re
import struct
import sys
import tempfile
import zipfile
import zlib
from typing import Callable, Dict, Iterable, List, Optional, Tuple

import numpy as np

EXIT_OK, EXIT_RUNTIME, EXIT_INPUT = 0, 1, 2


class InputError(Exception):
    """Bad input or usage: exit code 2."""


# --------------------------------------------------------------------- the model tables ----

FLOWNET2_KINDS = ("FlowNet2", "FlowNet2-C", "FlowNet2-S", "FlowNet2-SD", "FlowNet2-CS", "FlowNet2-CSS")
FLOWNET2_PREFIXES = ("flownetc", "flownets_1", "flownets_2", "flownets_d", "flownetfusion")
HEAD_KIND = "InertialNetHead"  # detected, but converted by tools/convert_checkpoint.py (HeadConfig)


def _conv(out, name, ci, co, k):  # conv / iconv: Sequential(Conv2d, [LeakyReLU])
    out[f"{name}.0.weight"] = (co, ci, k, k)
    out[f"{name}.0.bias"] = (co,)


def _deconv(out, name, ci, co):  # Sequential(ConvTranspose2d(4, 2, 1), LeakyReLU)
    out[f"{name}.0.weight"] = (ci, co, 4, 4)
    out[f"{name}.0.bias"] = (co,)


def _pred(out, name, ci):
    out[f"{name}.weight"] = (2, ci, 3, 3)
    out[f"{name}.bias"] = (2,)


def _up(out, name, bias):
    out[f"{name}.weight"] = (2, 2, 4, 4)
    if bias:
        out[f"{name}.bias"] = (2,)


def _decoder(out, up_bias, pred_inputs=(1024, 1026, 770, 386, 194)):
    for name, ci, co in (("deconv5", 1024, 512), ("deconv4", 1026, 256), ("deconv3", 770, 128),
                         ("deconv2", 386, 64)):
        _deconv(out, name, ci, co)
    for level, ci in zip((6, 5, 4, 3, 2), pred_inputs):
        _pred(out, f"predict_flow{level}", ci)
    for level in (6, 5, 4, 3):
        _up(out, f"upsampled_flow{level}_to_{level - 1}", up_bias)


def _encoder_tail(out, first_ci):
    for name, ci, co in (("conv4", first_ci, 512), ("conv4_1", 512, 512), ("conv5", 512, 512),
                         ("conv5_1", 512, 512), ("conv6", 512, 1024), ("conv6_1", 1024, 1024)):
        _conv(out, name, ci, co, 3)


def flownetc_shapes() -> Dict[str, tuple]:
    out: Dict[str, tuple] = {}
    _conv(out, "conv1", 3, 64, 7)
    _conv(out, "conv2", 64, 128, 5)
    _conv(out, "conv3", 128, 256, 5)
    _conv(out, "conv_redir", 256, 32, 1)
    _conv(out, "conv3_1", 473, 256, 3)
    _encoder_tail(out, 256)
    _decoder(out, up_bias=True)
    return out


def flownets_shapes(in_channels: int) -> Dict[str, tuple]:
    out: Dict[str, tuple] = {}
    _conv(out, "conv1", in_channels, 64, 7)
    _conv(out, "conv2", 64, 128, 5)
    _conv(out, "conv3", 128, 256, 5)
    _conv(out, "conv3_1", 256, 256, 3)
    _encoder_tail(out, 256)
    _decoder(out, up_bias=False)
    return out


def flownetsd_shapes() -> Dict[str, tuple]:
    out: Dict[str, tuple] = {}
    for name, ci, co in (("conv0", 6, 64), ("conv1", 64, 64), ("conv1_1", 64, 128), ("conv2", 128, 128),
                         ("conv2_1", 128, 128), ("conv3", 128, 256), ("conv3_1", 256, 256)):
        _conv(out, name, ci, co, 3)
    _encoder_tail(out, 256)
    for name, ci, co in (("inter_conv5", 1026, 512), ("inter_conv4", 770, 256), ("inter_conv3", 386, 128),
                         ("inter_conv2", 194, 64)):
        _conv(out, name, ci, co, 3)
    _decoder(out, up_bias=True, pred_inputs=(1024, 512, 256, 128, 64))
    return out


def flownetfusion_shapes() -> Dict[str, tuple]:
    out: Dict[str, tuple] = {}
    for name, ci, co in (("conv0", 11, 64), ("conv1", 64, 64), ("conv1_1", 64, 128), ("conv2", 128, 128),
                         ("conv2_1", 128, 128)):
        _conv(out, name, ci, co, 3)
    _deconv(out, "deconv1", 128, 32)
    _deconv(out, "deconv0", 162, 16)
    _conv(out, "inter_conv1", 162, 32, 3)
    _conv(out, "inter_conv0", 82, 16, 3)
    for name, ci in (("predict_flow2", 128), ("predict_flow1", 32), ("predict_flow0", 16)):
        _pred(out, name, ci)
    _up(out, "upsampled_flow2_to_1", True)
    _up(out, "upsampled_flow1_to_0", True)
    return out


def expected_shapes(kind: str) -> Dict[str, tuple]:
    """{state_dict name: shape} of a FlowNet2-family model, as flownet2-pytorch and ptlflow name them."""
    def prefixed(prefix, table):
        return {f"{prefix}.{k}": v for k, v in table.items()}

    if kind == "FlowNet2-C":
        return flownetc_shapes()
    if kind == "FlowNet2-S":
        return flownets_shapes(6)
    if kind == "FlowNet2-SD":
        return flownetsd_shapes()
    parts = [("flownetc", flownetc_shapes()), ("flownets_1", flownets_shapes(12))]
    if kind in ("FlowNet2-CSS", "FlowNet2"):
        parts.append(("flownets_2", flownets_shapes(12)))
    if kind == "FlowNet2":
        parts += [("flownets_d", flownetsd_shapes()), ("flownetfusion", flownetfusion_shapes())]
    if kind not in FLOWNET2_KINDS:
        raise InputError(f"unknown model {kind!r}; expected one of {', '.join(FLOWNET2_KINDS)}")
    out: Dict[str, tuple] = {}
    for prefix, table in parts:
        out.update(prefixed(prefix, table))
    return out


def detect_kind(names: Iterable[str]) -> str:
    """The model a set of state_dict names belongs to: a FlowNet2 kind or HEAD_KIND (raises InputError)."""
    names = set(names)
    prefixes = {n.split(".", 1)[0] for n in names}
    if prefixes & set(FLOWNET2_PREFIXES):
        if "flownetfusion" in prefixes or "flownets_d" in prefixes:
            return "FlowNet2"
        if "flownets_2" in prefixes:
            return "FlowNet2-CSS"
        if "flownets_1" in prefixes:
            return "FlowNet2-CS"
        raise InputError("the checkpoint has only flownetc.* tensors; no FlowNet2 variant is "
                         "a FlowNetC with a prefix (pass --model to force one)")
    if "head" in prefixes or {"fc1.weight", "fc2.weight", "conv3.weight"} <= names:
        return HEAD_KIND
    if "conv_redir.0.weight" in names:
        return "FlowNet2-C"
    if "inter_conv2.0.weight" in names or "conv0.0.weight" in names:
        return "FlowNet2-SD"
    if "conv1.0.weight" in names:
        return "FlowNet2-S"
    sample = sorted(names)[:5]
    raise InputError(f"cannot tell which model the checkpoint holds (first names: {sample}); pass --model")


# --------------------------------------------------------------- published checkpoints ----

PTLFLOW_RELEASE = "https://github.com/hmorimitsu/ptlflow/releases/download/weights1/"
NVIDIA_README = "https://github.com/NVIDIA/flownet2-pytorch#converted-caffe-pre-trained-models"


class Published:
    """One checkpoint a user can download: where, which model, and the checksum published for it."""

    def __init__(self, project, name, file, model, url, sha256_prefix=None):
        self.project, self.name, self.file, self.model = project, name, file, model
        self.url, self.sha256_prefix = url, sha256_prefix

    def label(self) -> str:
        return f"{self.project} {self.name}"


# ptlflow: ptlflow/models/flownet/*.py, `pretrained_checkpoints` (the same URLs since 2021, commit
# a8edb86); the hex digits before `.ckpt` are the start of the file's SHA-256, which torch.hub's
# load_state_dict_from_url(check_hash=True) verifies when ptlflow downloads them.
# NVIDIA: the README of NVIDIA/flownet2-pytorch; it publishes no checksum.
PUBLISHED = [
    Published("ptlflow", "flownet2-things", "flownet2-things-d63b53a7.ckpt", "FlowNet2",
              PTLFLOW_RELEASE + "flownet2-things-d63b53a7.ckpt", "d63b53a7"),
    Published("ptlflow", "flownetc-things", "flownetc-things-cc8ac7fd.ckpt", "FlowNet2-C",
              PTLFLOW_RELEASE + "flownetc-things-cc8ac7fd.ckpt", "cc8ac7fd"),
    Published("ptlflow", "flownets-things", "flownets-things-98cde14d.ckpt", "FlowNet2-S",
              PTLFLOW_RELEASE + "flownets-things-98cde14d.ckpt", "98cde14d"),
    Published("ptlflow", "flownetsd-things", "flownetsd-things-c5f3124e.ckpt", "FlowNet2-SD",
              PTLFLOW_RELEASE + "flownetsd-things-c5f3124e.ckpt", "c5f3124e"),
    Published("ptlflow", "flownetcs-things", "flownetcs-things-4bdecffa.ckpt", "FlowNet2-CS",
              PTLFLOW_RELEASE + "flownetcs-things-4bdecffa.ckpt", "4bdecffa"),
    Published("ptlflow", "flownetcss-things", "flownetcss-things-b42e67d0.ckpt", "FlowNet2-CSS",
              PTLFLOW_RELEASE + "flownetcss-things-b42e67d0.ckpt", "b42e67d0"),
] + [
    Published("flownet2-pytorch", name, f"{name}_checkpoint.pth.tar", model, NVIDIA_README)
    for name, model in (("FlowNet2", "FlowNet2"), ("FlowNet2-C", "FlowNet2-C"), ("FlowNet2-CS", "FlowNet2-CS"),
                        ("FlowNet2-CSS", "FlowNet2-CSS"), ("FlowNet2-CSS-ft-sd", "FlowNet2-CSS"),
                        ("FlowNet2-S", "FlowNet2-S"), ("FlowNet2-SD", "FlowNet2-SD"))
]


def sha256_of(path: str) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def identify(path: str, sha256: str, layout: str, kind: str, catalogue=None) -> Dict[str, str]:
    """Which published checkpoint the file is, with how that was established (metadata values).

    A file whose SHA-256 begins with a published prefix is that checkpoint. A file named like a
    published ptlflow checkpoint whose digest does not match is refused: a damaged download."""
    catalogue = PUBLISHED if catalogue is None else catalogue
    base = os.path.basename(path)
    for p in catalogue:
        if p.sha256_prefix and sha256.startswith(p.sha256_prefix):
            if p.model != kind:
                raise InputError(f"{path}: its SHA-256 is that of {p.label()} ({p.model}) but it holds "
                                 f"{kind} tensors")
            return {"published": p.label(), "url": p.url,
                    "checksum": f"verified: SHA-256 begins with {p.sha256_prefix}, the prefix published in "
                                f"{p.project}'s file name {p.file}"}
    for p in catalogue:
        if p.sha256_prefix and base == p.file:
            raise InputError(f"{path}: SHA-256 {sha256} does not begin with {p.sha256_prefix}, the prefix "
                             f"published for {p.label()}: the download is damaged or not that file; "
                             f"download it again from {p.url}")
    for p in catalogue:
        if not p.sha256_prefix and base == p.file and p.model == kind and layout == "flownet2-pytorch":
            return {"published": p.label(), "url": p.url,
                    "checksum": f"not verified: {p.project} publishes no checksum; matched by file name and layout"}
    return {"published": "none", "url": "",
            "checksum": "no published checkpoint has this SHA-256, or this file name and layout"}


# ---------------------------------------------------------------- torch checkpoint reading ----

# torch's storage classes and the numpy types of their elements.
_STORAGE_DTYPES = {
    "FloatStorage": np.float32, "DoubleStorage": np.float64, "HalfStorage": np.float16,
    "BFloat16Storage": "bfloat16", "LongStorage": np.int64, "IntStorage": np.int32,
    "ShortStorage": np.int16, "CharStorage": np.int8, "ByteStorage": np.uint8, "BoolStorage": np.bool_,
}


class _StorageType:
    def __init__(self, name):
        self.name = name
        self.dtype = _STORAGE_DTYPES[name]

    def itemsize(self) -> int:
        return 2 if self.dtype == "bfloat16" else np.dtype(self.dtype).itemsize

    def numpy_dtype(self, big_endian: bool):
        base = np.dtype(np.uint16 if self.dtype == "bfloat16" else self.dtype)
        return base.newbyteorder(">" if big_endian else "<")


class Storage:
    """A torch storage (or a view of one): numel elements of one type at element `first` of its root.

    The root's bytes are read only when a tensor's values are asked for: `read(byte_offset, count)`
    from byte `base` on (a zip entry: 0; the legacy format: known once the pickles are read)."""

    class Root:
        def __init__(self, kind: _StorageType, numel: int, read, big_endian: bool, base: Optional[int]):
            self.kind, self.numel, self.read, self.big_endian, self.base = kind, numel, read, big_endian, base

    def __init__(self, root: "Storage.Root", first: int, numel: int):
        self.root, self.first, self.numel = root, first, numel

    @property
    def kind(self) -> _StorageType:
        return self.root.kind

    def view(self, first: int, numel: int) -> "Storage":
        return Storage(self.root, self.first + first, numel)

    def elements(self, start: int, count: int) -> np.ndarray:
        size = self.kind.itemsize()
        raw = self.root.read(self.root.base + size * (self.first + start), size * count)
        a = np.frombuffer(raw, dtype=self.kind.numpy_dtype(self.root.big_endian), count=count)
        if self.kind.dtype == "bfloat16":  # bfloat16 is the upper half of a float32
            return (a.astype(np.uint32) << 16).view(np.float32)
        return a.astype(a.dtype.newbyteorder("="), copy=False)


class Tensor:
    """A tensor of a checkpoint: shape and type now, the values (numpy, C order) on demand."""

    def __init__(self, storage: Storage, offset: int, shape, stride, where: str):
        self.storage, self.offset = storage, int(offset)
        self.shape, self.stride = tuple(int(s) for s in shape), tuple(int(s) for s in stride)
        if len(self.shape) != len(self.stride) or any(s < 0 for s in self.shape + self.stride) or self.offset < 0:
            raise InputError(f"{where}: a tensor with size {list(self.shape)}, stride {list(self.stride)}, "
                             f"offset {self.offset}")
        if self.numel() and self.offset + sum((n - 1) * s for n, s in zip(self.shape, self.stride)) >= storage.numel:
            raise InputError(f"{where}: a tensor of size {list(self.shape)} (stride {list(self.stride)}, "
                             f"offset {self.offset}) reaches past its storage of {storage.numel} elements")

    @property
    def dtype(self):
        return np.dtype(np.float32) if self.storage.kind.dtype == "bfloat16" else np.dtype(self.storage.kind.dtype)

    @property
    def type_name(self) -> str:
        return self.storage.kind.name.replace("Storage", "")

    def numel(self) -> int:
        n = 1
        for s in self.shape:
            n *= s
        return n

    def is_floating_point(self) -> bool:
        return self.storage.kind.dtype in ("bfloat16", np.float16, np.float32, np.float64)

    def numpy(self) -> np.ndarray:
        if self.numel() == 0:
            return np.zeros(self.shape, dtype=self.dtype)
        span = 1 + sum((n - 1) * s for n, s in zip(self.shape, self.stride))
        flat = self.storage.elements(self.offset, span)
        strides = tuple(s * flat.itemsize for s in self.stride)
        return np.ascontiguousarray(np.lib.stride_tricks.as_strided(flat, self.shape, strides, writeable=False))


def _rebuild_tensor(where):
    def rebuild(storage, storage_offset, size, stride, *unused):
        if not isinstance(storage, Storage):
            raise InputError(f"{where}: a tensor whose storage is a {type(storage).__name__}")
        return Tensor(storage, storage_offset, size, stride, where)
    return rebuild


def _rebuild_parameter(data, *unused):  # an nn.Parameter: its tensor is what a state dict needs
    return data


def _latin1_bytes(text, encoding="latin1"):  # how protocol 2 pickles Python 3 bytes
    if encoding not in ("latin1", "latin-1"):
        raise InputError(f"a pickled _codecs.encode with encoding {encoding!r}")
    return codecs.encode(text, "latin1")


def _allowed_globals(where) -> Dict[str, object]:
    allowed = {
        "collections.OrderedDict": collections.OrderedDict,
        "torch._utils._rebuild_tensor": _rebuild_tensor(where),
        "torch._utils._rebuild_tensor_v2": _rebuild_tensor(where),
        "torch._utils._rebuild_parameter": _rebuild_parameter,
        "torch._utils._rebuild_parameter_with_state": _rebuild_parameter,
        "torch.Size": tuple,
        "torch.device": lambda *args: ":".join(str(a) for a in args),
        "_codecs.encode": _latin1_bytes,
        "builtins.set": set, "builtins.frozenset": frozenset,
        "__builtin__.set": set, "__builtin__.frozenset": frozenset,
        "numpy.dtype": np.dtype,
    }
    # A numpy scalar (flownet2-pytorch's training loop can store best_EPE as one): rebuilt from its
    # dtype and raw bytes by numpy, which runs nothing the pickle chooses.
    scalar = _numpy_scalar()
    allowed["numpy.core.multiarray.scalar"] = allowed["numpy._core.multiarray.scalar"] = scalar
    for name in _STORAGE_DTYPES:
        allowed[f"torch.{name}"] = allowed[f"torch.cuda.{name}"] = _StorageType(name)
    return allowed


def _numpy_scalar():
    """numpy's own scalar rebuilder (numpy._core in numpy 2, numpy.core before)."""
    import importlib
    for module in ("numpy._core.multiarray", "numpy.core.multiarray"):
        try:
            return importlib.import_module(module).scalar
        except (ImportError, AttributeError):
            continue
    raise ImportError("numpy's multiarray.scalar")


class _Unpickler(pickle.Unpickler):
    """Rebuilds tensors, storages, OrderedDicts and plain values; refuses every other global."""

    def __init__(self, file, where: str, storage_for):
        super().__init__(file, encoding="utf-8")  # what torch.load passes, for Python 2 pickles
        self.where, self.storage_for, self.allowed = where, storage_for, _allowed_globals(where)

    def find_class(self, module, name):
        found = self.allowed.get(f"{module}.{name}")
        if found is None:
            raise InputError(
                f"{self.where}: the pickle names {module}.{name}, which is not a tensor, a storage or a plain "
                "value; this converter never imports or runs what a checkpoint names. If you trust the file, "
                "load it with torch and save {'state_dict': model.state_dict()} alone")
        return found

    def persistent_load(self, pid):
        if not isinstance(pid, tuple) or not pid or pid[0] not in ("storage", b"storage"):
            kind = pid[0] if isinstance(pid, tuple) and pid else type(pid).__name__
            raise InputError(f"{self.where}: a pickled {kind!r} object (a whole pickled module?); only "
                             "state dicts of tensors can be converted")
        if len(pid) < 5 or not isinstance(pid[1], _StorageType):
            raise InputError(f"{self.where}: a storage reference {pid!r} this reader does not know")
        return self.storage_for(pid)


def _unpickle(data: bytes, where: str, storage_for):
    try:
        return _Unpickler(io.BytesIO(data) if isinstance(data, (bytes, bytearray)) else data, where,
                          storage_for).load()
    except InputError:
        raise
    except (pickle.UnpicklingError, EOFError, ValueError, TypeError, KeyError, IndexError, AttributeError,
            UnicodeDecodeError, struct.error, OverflowError, RecursionError) as e:
        raise InputError(f"{where}: not a readable torch pickle ({type(e).__name__}: {e})") from None


def _read_zip(path: str):
    try:
        archive = zipfile.ZipFile(path)
    except (zipfile.BadZipFile, OSError) as e:
        raise InputError(f"{path}: not a readable zip archive ({e})") from None
    pickles = [n for n in archive.namelist() if n.endswith("/data.pkl") and n.count("/") == 1]
    if len(pickles) != 1:
        raise InputError(f"{path}: a zip archive without the one <name>/data.pkl of torch's format "
                         f"(found {len(pickles)})")
    prefix = pickles[0][: -len("data.pkl")]
    names = set(archive.namelist())
    big_endian = False
    if prefix + "byteorder" in names:
        big_endian = archive.read(prefix + "byteorder").strip() == b"big"
    cache = {}

    def storage_for(pid):
        _, kind, key, _location, numel = pid[:5]
        entry = f"{prefix}data/{key}"
        if entry not in names:
            raise InputError(f"{path}: the pickle refers to storage {key}, which the archive lacks ({entry})")
        size = archive.getinfo(entry).file_size
        if size != int(numel) * kind.itemsize():
            raise InputError(f"{path}: storage {entry} holds {size} bytes, {numel} {kind.name} elements need "
                             f"{int(numel) * kind.itemsize()}")

        def read(start, count, entry=entry):
            if entry not in cache:
                cache.clear()  # one storage at a time: a state dict's tensors rarely share one
                try:
                    cache[entry] = archive.read(entry)
                except (zipfile.BadZipFile, zlib.error, EOFError, NotImplementedError) as e:
                    raise InputError(f"{path}: storage {entry} cannot be read ({e}); damaged download?") from None
            return cache[entry][start:start + count]
        return Storage(Storage.Root(kind, int(numel), read, big_endian, 0), 0, int(numel))

    try:
        return _unpickle(archive.read(pickles[0]), path, storage_for), "torch-zip"
    except zipfile.BadZipFile as e:
        raise InputError(f"{path}: damaged zip archive ({e})") from None


_LEGACY_MAGIC = 0x1950A86A20F9469CFC6C


def _read_legacy(path: str):
    """torch.save before 1.6 (and _use_new_zipfile_serialization=False): five pickles, then raw data."""
    with open(path, "rb") as f:
        def plain(what):
            try:
                return _Unpickler(f, f"{path} ({what})", lambda pid: None).load()
            except InputError:
                raise
            except Exception as e:  # noqa: BLE001 - anything else means "not this format"
                raise InputError(f"{path}: not a torch checkpoint (its {what} does not unpickle: "
                                 f"{type(e).__name__})") from None

        if plain("magic number") != _LEGACY_MAGIC:
            raise InputError(f"{path}: not a torch checkpoint (no torch magic number)")
        protocol = plain("protocol version")
        if protocol != 1001:
            raise InputError(f"{path}: torch legacy protocol {protocol!r}; this reader knows 1001")
        info = plain("system information")
        big_endian = isinstance(info, dict) and info.get("little_endian") is False
        roots: Dict[str, Storage.Root] = {}
        file_size = os.fstat(f.fileno()).st_size

        def read(start, count):
            with open(path, "rb") as g:
                g.seek(start)
                data = g.read(count)
            if len(data) != count:
                raise InputError(f"{path}: the file ends inside a tensor's data (truncated download?)")
            return data

        def storage_for(pid):
            _, kind, key, _location, numel = pid[:5]
            view = pid[5] if len(pid) > 5 else None
            key = key.decode() if isinstance(key, bytes) else str(key)
            if key not in roots:
                roots[key] = Storage.Root(kind, int(numel), read, big_endian, None)
            root = Storage(roots[key], 0, roots[key].numel)
            if view is None:
                return root
            _view_key, offset, size = view
            if int(offset) < 0 or int(offset) + int(size) > root.numel:
                raise InputError(f"{path}: a view of storage {key} reaches past its end")
            return root.view(int(offset), int(size))

        obj = _unpickle(f, path, storage_for)
        keys = _unpickle(f, f"{path} (storage keys)", lambda pid: None)
        if not isinstance(keys, list):
            raise InputError(f"{path}: the storage key list is a {type(keys).__name__}")
        position = f.tell()
        # Then each storage in that order: its element count (int64), then its elements.
        for key in keys:
            key = key.decode() if isinstance(key, bytes) else str(key)
            if key not in roots:
                raise InputError(f"{path}: data for storage {key}, which no tensor uses")
            f.seek(position)
            head = f.read(8)
            if len(head) != 8:
                raise InputError(f"{path}: the file ends before the data of storage {key} (truncated download?)")
            (numel,) = struct.unpack(">q" if big_endian else "<q", head)
            root = roots[key]
            if numel != root.numel:
                raise InputError(f"{path}: storage {key} has {numel} elements in the data, {root.numel} in the pickle")
            root.base = position + 8
            position = root.base + numel * root.kind.itemsize()
            if position > file_size:
                raise InputError(f"{path}: the file ends inside the data of storage {key} (truncated download?)")
        missing = sorted(k for k, r in roots.items() if r.base is None)
        if missing:
            raise InputError(f"{path}: no data for storage(s) {', '.join(missing[:5])} (truncated file?)")
    return obj, "torch-legacy"


def read_checkpoint(path: str):
    """The unpickled top-level object of a torch checkpoint (tensors as `Tensor`) and its format."""
    if not os.path.isfile(path):
        raise InputError(f"{path}: no such file")
    with open(path, "rb") as f:
        start = f.read(512)
    if start[:4] == b"PK\x03\x04":
        return _read_zip(path)
    if len(start) >= 262 and start[257:262] == b"ustar":
        raise InputError(f"{path}: a tar archive; torch's pre-0.1.10 tar checkpoints are not supported "
                         "(flownet2-pytorch's .pth.tar files are not tar archives)")
    if start[:1] == b"\x80":
        return _read_legacy(path)
    raise InputError(f"{path}: neither of torch's checkpoint formats (zip or legacy pickle)")


# ------------------------------------------------------------------------- the state dict ----

LIGHTNING_KEYS = ("pytorch-lightning_version", "hyper_parameters", "global_step", "optimizer_states",
                  "lr_schedulers", "loops", "callbacks")


def state_dict_of(obj, path: str) -> Tuple[Dict[str, Tensor], str]:
    """The tensors of a checkpoint's state dict, under the names the model uses, and its layout:
    'ptlflow-lightning' (a Lightning checkpoint), 'flownet2-pytorch' ({'epoch', 'state_dict',
    'best_EPE'}), or 'state_dict' (a bare state dict or another wrapper)."""
    if not isinstance(obj, dict):
        raise InputError(f"{path}: holds a {type(obj).__name__}, expected a dict with a 'state_dict' "
                         "or a state dict itself")
    if isinstance(obj.get("state_dict"), dict):
        state = obj["state_dict"]
        if any(k in obj for k in LIGHTNING_KEYS):
            layout = "ptlflow-lightning"
        elif "epoch" in obj and "best_EPE" in obj:
            layout = "flownet2-pytorch"
        else:
            layout = "state_dict"
    else:
        state, layout = obj, "state_dict"
    tensors, not_tensors = {}, []
    for k, v in state.items():
        if isinstance(v, Tensor):
            tensors[str(k)] = v
        else:
            not_tensors.append(f"{k} ({type(v).__name__})")
    if not_tensors:
        raise InputError(f"{path}: state_dict entries that are not tensors: {', '.join(not_tensors[:10])}")
    if not tensors:
        raise InputError(f"{path}: the state_dict holds no tensors")
    # nn.DataParallel saves module.*; a Lightning module that wraps its network as `model` saves model.*.
    for prefix in ("module.", "model."):
        if all(k.startswith(prefix) for k in tensors):
            tensors = {k[len(prefix):]: v for k, v in tensors.items()}
    return tensors, layout


def _fmt(shape) -> str:
    return "[" + ",".join(str(int(s)) for s in shape) + "]"


def validate(tensors: dict, expected: dict, model: str) -> None:
    """Every name and shape as the model has them; lists all problems in one InputError."""
    missing = [n for n in expected if n not in tensors]
    extra = sorted(n for n in tensors if n not in expected)
    wrong = [f"{n}: file {_fmt(tensors[n].shape)}, model {_fmt(expected[n])}"
             for n in expected if n in tensors and tuple(tensors[n].shape) != tuple(expected[n])]
    not_float = [f"{n}: {tensors[n].type_name}" for n in expected
                 if n in tensors and not tensors[n].is_floating_point()]
    problems = []
    if missing:
        problems.append(f"missing {len(missing)} tensor(s): " + ", ".join(missing))
    if extra:
        problems.append(f"{len(extra)} unexpected tensor(s): " + ", ".join(extra))
    if wrong:
        problems.append(f"{len(wrong)} with the wrong shape: " + "; ".join(wrong))
    if not_float:
        problems.append(f"{len(not_float)} not floating point: " + "; ".join(not_float))
    if problems:
        n_file = sum(int(np.prod(t.shape, dtype=np.int64)) for t in tensors.values())
        n_model = sum(int(np.prod(s, dtype=np.int64)) for s in expected.values())
        raise InputError(f"the checkpoint does not fit {model} ({len(tensors)} tensors, {n_file:,} parameters; "
                         f"the model has {len(expected)} tensors, {n_model:,} parameters):\n  "
                         + "\n  ".join(problems))


# ---------------------------------------------------------------------------- safetensors ----

_SAFETENSORS_DTYPES = {"F32": np.float32, "F16": np.float16, "F64": np.float64, "I64": np.int64,
                       "I32": np.int32, "I16": np.int16, "I8": np.int8, "U8": np.uint8, "BOOL": np.bool_}


def write_safetensors(path: str, arrays, metadata: Dict[str, str]) -> None:
    """Writes float32 tensors, in the order given, to `path` (through a temporary file, replaced at
    the end, so that a failure never leaves a half-written file under the final name).

    `arrays`: (name, shape, producer) with producer() giving the values; one tensor is in memory at a time."""
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        raise InputError(f"{path}: the folder {folder} does not exist")
    header: Dict[str, object] = {"__metadata__": dict(metadata)}
    offset = 0
    for name, shape, _ in arrays:
        size = 4 * int(np.prod(shape, dtype=np.int64))
        header[name] = {"dtype": "F32", "shape": [int(s) for s in shape], "data_offsets": [offset, offset + size]}
        offset += size
    text = json.dumps(header, separators=(",", ":")).encode("utf-8")
    text += b" " * (-len(text) % 8)  # the data starts 8-byte aligned, as the safetensors library writes it
    fd, tmp = tempfile.mkstemp(prefix=".convert-", suffix=".safetensors", dir=folder)
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(struct.pack("<Q", len(text)))
            f.write(text)
            for name, shape, produce in arrays:
                values = np.ascontiguousarray(produce(), dtype="<f4")
                if values.shape != tuple(shape):
                    raise InputError(f"{name}: values of shape {_fmt(values.shape)} for {_fmt(shape)}")
                f.write(values.tobytes())
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def read_safetensors(path: str) -> Tuple[Dict[str, np.ndarray], Dict[str, str]]:
    """All tensors (numpy) and the metadata of a safetensors file."""
    with open(path, "rb") as f:
        data = f.read()
    if len(data) < 8:
        raise InputError(f"{path}: not a safetensors file (shorter than 8 bytes)")
    (n,) = struct.unpack("<Q", data[:8])
    try:
        header = json.loads(data[8:8 + n].decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as e:
        raise InputError(f"{path}: not a safetensors file ({e})") from None
    metadata = header.pop("__metadata__", {}) or {}
    out = {}
    for name, info in header.items():
        begin, end = info["data_offsets"]
        dtype = np.dtype(_SAFETENSORS_DTYPES[info["dtype"]]).newbyteorder("<")
        out[name] = np.frombuffer(data, dtype=dtype, count=(end - begin) // dtype.itemsize,
                                  offset=8 + n + begin).reshape(info["shape"])
    return out, metadata


# ------------------------------------------------------------------------------ converting ----

def _as_float32(name: str, tensor: Tensor, notes: List[str]):
    def produce():
        values = tensor.numpy()
        if values.dtype != np.float32:
            notes.append(f"{name} is {tensor.type_name}, stored as float32")
            values = values.astype(np.float32)
        return values
    return produce


def check_written(path: str, tensors: Dict[str, Tensor], metadata: Dict[str, str]) -> List[str]:
    """Reloads `path` and compares names, shapes, bits and metadata with the checkpoint's tensors."""
    got, meta = read_safetensors(path)
    problems = []
    if set(got) != set(tensors):
        problems.append(f"names differ: missing {sorted(set(tensors) - set(got))}, extra {sorted(set(got) - set(tensors))}")
    for name in sorted(set(got) & set(tensors)):
        want = np.asarray(tensors[name].numpy(), dtype=np.float32)  # a Tensor here, or a torch tensor
        if got[name].shape != want.shape:
            problems.append(f"{name}: reloaded {_fmt(got[name].shape)}, wrote {_fmt(want.shape)}")
        elif not np.array_equal(got[name].view(np.uint32), want.view(np.uint32)):
            problems.append(f"{name}: {int((got[name].view(np.uint32) != want.view(np.uint32)).sum())} "
                            "element(s) differ bitwise")
    for k, v in metadata.items():
        if meta.get(k) != v:
            problems.append(f"metadata {k}: reloaded {meta.get(k)!r}, wrote {v!r}")
    return problems


def checkpoint_metadata(path: str, fmt: str, layout: str, sha256: str, origin: Dict[str, str]) -> Dict[str, str]:
    """The inertialnet.checkpoint.* block: where converted weights came from (weights --info prints it)."""
    meta = {"inertialnet.checkpoint.file": os.path.basename(path),
            "inertialnet.checkpoint.format": fmt,
            "inertialnet.checkpoint.layout": layout,
            "inertialnet.checkpoint.sha256": sha256,
            "inertialnet.checkpoint.published": origin["published"],
            "inertialnet.checkpoint.checksum": origin["checksum"]}
    if origin.get("url"):
        meta["inertialnet.checkpoint.url"] = origin["url"]
    return meta


def convert(source: str, output: str, model: Optional[str] = None, check: bool = False,
            expect_sha256: Optional[str] = None, catalogue=None) -> Dict[str, object]:
    """Converts a FlowNet2-family checkpoint; returns what it did (kind, tensors, parameters,
    metadata, notes). Raises InputError for bad input, OSError for I/O failures."""
    sha256 = sha256_of(source) if os.path.isfile(source) else ""
    if expect_sha256 is not None:
        want = expect_sha256.strip().lower()
        if len(want) < 8 or not re.fullmatch(r"[0-9a-f]+", want):
            raise InputError(f"--sha256 expects at least 8 hex digits, got {expect_sha256!r}")
        if sha256 and not sha256.startswith(want):
            raise InputError(f"{source}: SHA-256 {sha256} does not begin with the expected {want}")
    obj, fmt = read_checkpoint(source)
    tensors, layout = state_dict_of(obj, source)
    kind = model or detect_kind(tensors)
    if kind == HEAD_KIND:
        raise InputError(f"{source}: holds an InertialNet head; convert heads with tools/convert_checkpoint.py "
                         "--head-input WxH (the head's input size is not in its weights)")
    expected = expected_shapes(kind)
    validate(tensors, expected, kind)
    origin = identify(source, sha256, layout, kind, catalogue)
    metadata = {"inertialnet.model": kind, "inertialnet.synthetic": "false",
                "inertialnet.source": os.path.basename(source)}
    metadata.update(checkpoint_metadata(source, fmt, layout, sha256, origin))
    notes: List[str] = []
    write_safetensors(output, [(n, expected[n], _as_float32(n, tensors[n], notes)) for n in expected], metadata)
    problems = check_written(output, {n: tensors[n] for n in expected}, metadata) if check else []
    return {"kind": kind, "tensors": len(expected), "metadata": metadata, "notes": notes, "problems": problems,
            "parameters": sum(int(np.prod(s, dtype=np.int64)) for s in expected.values())}


def list_published() -> str:
    lines = [f"{'checkpoint':38} {'model':13} {'SHA-256 begins':17} where"]
    for p in PUBLISHED:
        lines.append(f"{p.file:38} {p.model:13} {p.sha256_prefix or '(none published)':17} {p.url}")
    return "\n".join(lines)


# What `python -m inertialnet.convert` and tools/convert_checkpoint.py (which adds heads) share:
# the arguments, the exit codes and what a conversion prints.
EXIT_CODES_EPILOG = ("Exit codes: 0 success, 1 runtime failure (I/O, --check mismatch), 2 bad usage or input "
                     "(unreadable checkpoint, unknown model, missing/extra/mis-shaped tensors, checksum mismatch). "
                     "docs/weights.md lists where to download each checkpoint.")


def add_checkpoint_arguments(ap: argparse.ArgumentParser, models, *, optional: bool = False) -> None:
    """CHECKPOINT OUTPUT --model --check --sha256 (``optional``: the two paths may be left out)."""
    nargs = "?" if optional else None
    ap.add_argument("input", nargs=nargs, help="checkpoint (.pth.tar, .ckpt, .pth, .pt)")
    ap.add_argument("output", nargs=nargs, help="safetensors file to write")
    ap.add_argument("--model", choices=models, help="model kind; detected from the tensor names when omitted")
    ap.add_argument("--check", action="store_true", help="reload the written file and compare every tensor bit for bit")
    ap.add_argument("--sha256", metavar="HEX", help="refuse the checkpoint unless its SHA-256 begins with HEX "
                                                    "(8 or more hex digits)")


def exit_code(work: Callable[[], int], prefix: str) -> int:
    """``work()``'s exit code; bad input is exit 2 and an I/O failure exit 1, the message on standard
    error after ``prefix``."""
    try:
        return work()
    except InputError as e:
        print(f"{prefix}{e}", file=sys.stderr)
        return EXIT_INPUT
    except OSError as e:
        print(f"{prefix}{e}", file=sys.stderr)
        return EXIT_RUNTIME


def report(done: Dict[str, object], output: str, check: bool, quiet: bool, *, note: str, error: str) -> int:
    """A conversion's notes (each after ``note``), problems (after ``error``; exit 1) and first
    summary line; EXIT_OK when it read back."""
    if not quiet:
        for text in done["notes"]:
            print(f"{note}{text}", file=sys.stderr)
    if done["problems"]:
        print(f"{error}{output} does not read back as written:\n  " + "\n  ".join(done["problems"]),
              file=sys.stderr)
        return EXIT_RUNTIME
    if not quiet:
        print(f"{output}: {done['kind']}, {done['tensors']} tensors, {done['parameters']:,} parameters"
              + (", verified bit for bit" if check else ""))
    return EXIT_OK


def build_parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(
        prog="python -m inertialnet.convert",
        description="Convert a FlowNet2-family checkpoint (NVIDIA flownet2-pytorch .pth.tar or ptlflow "
                    "Lightning .ckpt) to the safetensors file `inertialnet -w` loads, without torch.",
        epilog=EXIT_CODES_EPILOG)
    add_checkpoint_arguments(ap, FLOWNET2_KINDS, optional=True)
    ap.add_argument("--list", action="store_true", help="list the published checkpoints this tool knows and exit")
    ap.add_argument("-q", "--quiet", action="store_true", help="print nothing on success")
    return ap


def main(argv=None) -> int:
    ap = build_parser()
    args = ap.parse_args(argv)
    if args.list:
        print(list_published())
        return EXIT_OK
    if not args.input or not args.output:
        ap.print_usage(sys.stderr)
        print("inertialnet: convert needs CHECKPOINT and OUTPUT (or --list)", file=sys.stderr)
        return EXIT_INPUT

    def work() -> int:
        done = convert(args.input, args.output, args.model, args.check, args.sha256)
        code = report(done, args.output, args.check, args.quiet, note="inertialnet: note: ",
                      error="inertialnet: ")
        if code == EXIT_OK and not args.quiet:
            meta = done["metadata"]
            print(f"  from a {meta['inertialnet.checkpoint.layout']} checkpoint "
                  f"({meta['inertialnet.checkpoint.format']}); published checkpoint: "
                  f"{meta['inertialnet.checkpoint.published']} (checksum: {meta['inertialnet.checkpoint.checksum']})")
        return code

    return exit_code(work, "inertialnet: ")


if __name__ == "__main__":
    sys.exit(main())
