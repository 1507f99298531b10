# SPDX-License-Identifier: Apache-2.0
"""inertialnet.convert (and tools/convert_checkpoint.py) on checkpoints laid out as the published
ones: NVIDIA flownet2-pytorch's {'epoch', 'state_dict', 'best_EPE'} and ptlflow's Lightning
checkpoints, in both torch formats (legacy and zip), written by tests/torch_format.py without
torch (and by torch.save as well where torch is installed). The converted networks are checked
against the original weights tensor by tensor and through `inertialnet flow`."""
import hashlib
import json
import os
import pathlib
import pickle
import re
import struct
import subprocess
import sys
import zipfile

import numpy as np
import pytest

from inertialnet import convert as cv
import torch_format as tf

REPO = pathlib.Path(__file__).resolve().parents[2]


def header(path):
    """The JSON header of a safetensors file (without reading its data)."""
    with open(path, "rb") as f:
        (n,) = struct.unpack("<Q", f.read(8))
        return json.loads(f.read(n))


def run_module(*args):
    return subprocess.run([sys.executable, "-m", "inertialnet.convert", *map(str, args)], capture_output=True, text=True)


@pytest.fixture(autouse=True)
def _remove_large_files(tmp_path):
    """Each FlowNet2-S checkpoint or weight file is 155 MB: remove them after each test, so that the
    suite does not leave gigabytes in its temporary folder."""
    yield
    for path in tmp_path.rglob("*"):
        if path.is_file() and path.stat().st_size > (1 << 20):
            path.unlink()


@pytest.fixture(scope="module")
def original(cli, tmp_path_factory):
    """The original weights: the library's synthetic FlowNet2-S, as (name, array) in state_dict order."""
    path = tmp_path_factory.mktemp("original") / "s.safetensors"
    cli("weights", "--synthetic", "FlowNet2-S", "--seed", "3", "-o", path)
    arrays, _ = cv.read_safetensors(str(path))
    return path, [(n, np.array(arrays[n])) for n in cv.expected_shapes("FlowNet2-S")]


@pytest.fixture(scope="module")
def frames(sequence):
    return sorted((sequence / "mav0" / "cam0" / "data").glob("*.png"))[:2]


def test_the_tables_are_the_librarys(cli, tmp_path):
    """Names and shapes of this module's tables equal the C++ tables (src/models/parameters.cpp):
    FlowNet2 holds C, S with 12 channels, SD and Fusion; FlowNet2-S the 6-channel S."""
    for kind in ("FlowNet2", "FlowNet2-S"):
        path = tmp_path / f"{kind}.safetensors"
        cli("weights", "--synthetic", kind, "-o", path)
        library = {k: tuple(v["shape"]) for k, v in header(path).items() if k != "__metadata__"}
        assert library == cv.expected_shapes(kind)
        path.unlink()
    # The counts of docs/model_spec.md.
    counts = {k: (len(t), sum(int(np.prod(s)) for s in t.values()))
              for k, t in ((k, cv.expected_shapes(k)) for k in cv.FLOWNET2_KINDS)}
    assert counts == {"FlowNet2": (220, 162518834), "FlowNet2-C": (48, 39175298), "FlowNet2-S": (42, 38676506),
                      "FlowNet2-SD": (60, 45371666), "FlowNet2-CS": (90, 77870620), "FlowNet2-CSS": (132, 116565942)}


# Each published layout, in the format it is published in and in the other one (a user may re-save).
LAYOUTS = [
    ("FlowNet2-S_checkpoint.pth.tar", "nvidia", "legacy", "v1"),   # torch 0.3: _rebuild_tensor
    ("FlowNet2-S_checkpoint.pth.tar", "nvidia", "legacy", "v2"),   # torch 0.4 - 1.5
    ("FlowNet2-S_checkpoint.pth.tar", "nvidia", "zip", "v2"),
    ("flownets-things-mine.ckpt", "ptlflow", "zip", "v2"),
    ("flownets-things-mine.ckpt", "ptlflow", "legacy", "v2"),
]


def write_checkpoint(path, arrays, layout, fmt, rebuild="v2"):
    stored = [(n, tf.StoredTensor.of(a, rebuild)) for n, a in arrays]
    obj = tf.nvidia_checkpoint(stored) if layout == "nvidia" else tf.ptlflow_checkpoint(stored, "flownets")
    if fmt == "legacy":
        tf.write_legacy(path, obj)
    else:
        tf.write_zip(path, obj, prefix=path.stem.split(".")[0])  # torch names the folder after the file
    return path


@pytest.mark.parametrize("name,layout,fmt,rebuild", LAYOUTS)
def test_published_layouts_convert_bit_for_bit(original, tmp_path, name, layout, fmt, rebuild):
    _, arrays = original
    src = write_checkpoint(tmp_path / name, arrays, layout, fmt, rebuild)
    out = tmp_path / "converted.safetensors"
    r = run_module(src, out, "--check")
    assert r.returncode == 0, r.stderr
    assert "FlowNet2-S, 42 tensors, 38,676,506 parameters, verified bit for bit" in r.stdout
    got, meta = cv.read_safetensors(str(out))
    assert list(got) == [n for n, _ in arrays]
    for n, a in arrays:
        assert got[n].dtype == np.float32 and np.array_equal(got[n].view(np.uint32), a.view(np.uint32)), n
    assert meta["inertialnet.model"] == "FlowNet2-S" and meta["inertialnet.synthetic"] == "false"
    assert meta["inertialnet.checkpoint.format"] == f"torch-{fmt}"
    assert meta["inertialnet.checkpoint.layout"] == {"nvidia": "flownet2-pytorch", "ptlflow": "ptlflow-lightning"}[layout]
    assert meta["inertialnet.checkpoint.sha256"] == hashlib.sha256(src.read_bytes()).hexdigest()
    # NVIDIA's file names are published (without a checksum); "flownets-things-mine" is no published name.
    expected = "flownet2-pytorch FlowNet2-S" if layout == "nvidia" else "none"
    assert meta["inertialnet.checkpoint.published"] == expected


def test_converted_network_computes_what_the_original_does(cli, original, frames, tmp_path):
    """The network through `inertialnet flow`: converted weights give the original's flow bit for bit,
    and `weights --info` names where they came from."""
    path, arrays = original
    src = write_checkpoint(tmp_path / "FlowNet2-S_checkpoint.pth.tar", arrays, "nvidia", "legacy")
    out = tmp_path / "s.safetensors"
    assert cv.main([str(src), str(out), "-q"]) == 0
    cli("flow", frames[0], frames[1], "-w", path, "-o", tmp_path / "original.flo")
    cli("flow", frames[0], frames[1], "-w", out, "-o", tmp_path / "converted.flo")
    assert (tmp_path / "original.flo").read_bytes() == (tmp_path / "converted.flo").read_bytes()
    info = cli("weights", "--info", out, stdout_only=True)
    assert "converted from FlowNet2-S_checkpoint.pth.tar (flownet2-pytorch layout, torch-legacy format, SHA-256 " in info
    assert ("published checkpoint: flownet2-pytorch FlowNet2-S (checksum: not verified: flownet2-pytorch "
            "publishes no checksum; matched by file name and layout)") in info
    # Synthetic weights have no such block.
    assert "converted from" not in cli("weights", "--info", path, stdout_only=True)


def test_torch_save_files_convert_too(original, tmp_path):
    """Where torch is installed, the reader is checked against torch.save itself."""
    pytest.importorskip("torch", reason="torch is not installed; the independent writer stands in for it")
    _, arrays = original
    for legacy in (True, False):
        src = tf.torch_save(tmp_path / f"FlowNet2-S_checkpoint-{legacy}.pth.tar", tf.nvidia_checkpoint(arrays), legacy)
        out = tmp_path / "t.safetensors"
        assert cv.main([str(src), str(out), "-q", "--check"]) == 0
        got, _ = cv.read_safetensors(str(out))
        assert all(np.array_equal(got[n], a) for n, a in arrays)


@pytest.mark.parametrize("fmt", ["legacy", "zip"])
@pytest.mark.parametrize("layout", ["nvidia", "ptlflow"])
def test_every_model_kind_is_recognised_by_its_names(tmp_path, layout, fmt):
    """Names and nesting of every published model, full size: each tensor a stride-0 view of one
    element, so that the files stay small; the state dict is read and validated, not written."""
    one = tf.Storage(np.zeros(1, np.float32))
    for kind in cv.FLOWNET2_KINDS:
        stored = [(n, tf.StoredTensor(one, 0, s, (0,) * len(s))) for n, s in cv.expected_shapes(kind).items()]
        obj = tf.nvidia_checkpoint(stored) if layout == "nvidia" else tf.ptlflow_checkpoint(stored)
        path = tmp_path / f"{kind}.{fmt}"
        (tf.write_legacy if fmt == "legacy" else tf.write_zip)(path, obj)
        tensors, found_layout = cv.state_dict_of(cv.read_checkpoint(str(path))[0], str(path))
        assert found_layout == {"nvidia": "flownet2-pytorch", "ptlflow": "ptlflow-lightning"}[layout]
        assert cv.detect_kind(tensors) == kind
        cv.validate(tensors, cv.expected_shapes(kind), kind)


def test_published_checksums(original, tmp_path, monkeypatch):
    _, arrays = original
    # A file under a published ptlflow name whose SHA-256 does not begin with the published prefix.
    src = write_checkpoint(tmp_path / "flownets-things-98cde14d.ckpt", arrays, "ptlflow", "zip")
    r = run_module(src, tmp_path / "x.safetensors")
    assert r.returncode == 2 and not (tmp_path / "x.safetensors").exists()
    assert "does not begin with 98cde14d, the prefix published for ptlflow flownets-things" in r.stderr
    assert "releases/download/weights1/flownets-things-98cde14d.ckpt" in r.stderr
    # A file whose digest begins with a published prefix is that checkpoint, whatever its name.
    renamed = src.rename(tmp_path / "downloaded.ckpt")
    digest = hashlib.sha256(renamed.read_bytes()).hexdigest()
    published = cv.Published("ptlflow", "flownets-things", f"flownets-things-{digest[:8]}.ckpt", "FlowNet2-S",
                             cv.PTLFLOW_RELEASE + f"flownets-things-{digest[:8]}.ckpt", digest[:8])
    monkeypatch.setattr(cv, "PUBLISHED", [published])
    done = cv.convert(str(renamed), str(tmp_path / "y.safetensors"))
    assert done["metadata"]["inertialnet.checkpoint.published"] == "ptlflow flownets-things"
    assert done["metadata"]["inertialnet.checkpoint.checksum"].startswith(f"verified: SHA-256 begins with {digest[:8]}")
    # ... and must hold that checkpoint's model.
    monkeypatch.setattr(cv, "PUBLISHED", [cv.Published("ptlflow", "x", "x.ckpt", "FlowNet2", "", digest[:8])])
    with pytest.raises(cv.InputError, match="holds FlowNet2-S tensors"):
        cv.convert(str(renamed), str(tmp_path / "z.safetensors"))
    # --sha256: the user's own expected digest.
    monkeypatch.undo()
    assert cv.main([str(renamed), str(tmp_path / "w.safetensors"), "-q", "--sha256", digest[:12]]) == 0
    assert cv.main([str(renamed), str(tmp_path / "v.safetensors"), "-q", "--sha256", "0" * 8]) == 2
    assert cv.main([str(renamed), str(tmp_path / "v.safetensors"), "-q", "--sha256", "abc"]) == 2
    assert not (tmp_path / "v.safetensors").exists()


def test_list_names_the_downloads():
    r = run_module("--list")
    assert r.returncode == 0
    assert "flownet2-things-d63b53a7.ckpt" in r.stdout and "FlowNet2-CSS-ft-sd_checkpoint.pth.tar" in r.stdout
    assert cv.PTLFLOW_RELEASE + "flownet2-things-d63b53a7.ckpt" in r.stdout


class _RunsCode:
    def __init__(self, marker):
        self.marker = marker

    def __reduce__(self):
        return os.system, (f"touch {self.marker}",)


def test_pickles_that_name_other_globals_are_refused_and_never_run(tmp_path):
    marker = tmp_path / "ran"
    state = {"state_dict": {"conv1.0.weight": _RunsCode(marker)}, "epoch": 0, "best_EPE": 0.0}
    legacy = tmp_path / "evil.pth.tar"
    with open(legacy, "wb") as f:
        for value in (0x1950A86A20F9469CFC6C, 1001, {"little_endian": True}, state, []):
            pickle.dump(value, f, protocol=2)
    zipped = tmp_path / "evil.ckpt"
    with zipfile.ZipFile(zipped, "w") as z:
        z.writestr("archive/data.pkl", pickle.dumps(state, protocol=2))
    for path in (legacy, zipped):
        r = run_module(path, tmp_path / "out.safetensors")
        assert r.returncode == 2, r.stderr
        assert f"{path}: the pickle names {os.system.__module__}.system, which is not a tensor" in r.stderr
        assert "never imports or runs" in r.stderr and "Traceback" not in r.stderr
    assert not marker.exists() and not (tmp_path / "out.safetensors").exists()


def test_damaged_checkpoints_are_bad_input(original, tmp_path):
    _, arrays = original
    small = [(n, a) for n, a in arrays if n.endswith("bias")][:3]
    good = write_checkpoint(tmp_path / "good.pth.tar", small, "nvidia", "legacy")
    cases = {}
    cases["truncated"] = tmp_path / "truncated.pth.tar"
    cases["truncated"].write_bytes(good.read_bytes()[:-5])
    cases["junk"] = tmp_path / "junk.pth.tar"
    cases["junk"].write_bytes(b"not a checkpoint")
    cases["missing storage"] = tmp_path / "nostorage.ckpt"
    write_checkpoint(tmp_path / "full.ckpt", small, "ptlflow", "zip")
    with zipfile.ZipFile(tmp_path / "full.ckpt") as z, zipfile.ZipFile(cases["missing storage"], "w") as out:
        for item in z.namelist():
            if not item.endswith("/data/1"):
                out.writestr(item, z.read(item))
    # A flipped bit in a storage's data: the zip's CRC catches it when the tensor is read.
    cases["bad crc"] = tmp_path / "crc.ckpt"
    data = bytearray((tmp_path / "full.ckpt").read_bytes())
    with zipfile.ZipFile(tmp_path / "full.ckpt") as z:
        info = z.getinfo("full/data/0")
    data[info.header_offset + 30 + len(info.filename) + len(info.extra) + 1] ^= 1
    cases["bad crc"].write_bytes(bytes(data))
    cases["past its storage"] = tmp_path / "strides.pth.tar"
    storage = tf.Storage(np.zeros(4, np.float32))
    tf.write_legacy(cases["past its storage"], tf.nvidia_checkpoint([("conv1.0.bias", tf.StoredTensor(storage, 2, (64,), (1,)))]))
    cases["not tensors"] = tmp_path / "values.pth.tar"
    tf.write_legacy(cases["not tensors"], {"epoch": 0, "state_dict": {"conv1.0.bias": 1.5}, "best_EPE": 0.0})
    messages = {"truncated": "truncated", "junk": "neither of torch's checkpoint formats",
                "missing storage": "which the archive lacks", "bad crc": "storage full/data/0 cannot be read (Bad CRC-32", "past its storage": "reaches past its storage of 4 elements",
                "not tensors": "state_dict entries that are not tensors: conv1.0.bias (float)"}
    for what, path in cases.items():
        with pytest.raises(cv.InputError, match=re.escape(messages[what])):
            obj, _ = cv.read_checkpoint(str(path))
            tensors, _ = cv.state_dict_of(obj, str(path))
            for t in tensors.values():
                t.numpy()
    assert run_module(tmp_path / "none.pth.tar", tmp_path / "o.safetensors").returncode == 2
    r = run_module(cases["truncated"], tmp_path / "o.safetensors")
    assert r.returncode == 2 and "Traceback" not in r.stderr and not (tmp_path / "o.safetensors").exists()


def test_mismatches_are_all_listed(original, tmp_path):
    _, arrays = original
    state = dict(arrays)
    del state["deconv3.0.bias"], state["predict_flow2.weight"]
    state["conv1.0.weight"] = np.zeros((64, 12, 7, 7), np.float32)
    state["upsampled_flow6_to_5.bias"] = np.zeros(2, np.float32)
    src = write_checkpoint(tmp_path / "bad.pth.tar", list(state.items()), "nvidia", "zip")
    r = run_module(src, tmp_path / "bad.safetensors", "--model", "FlowNet2-S")
    assert r.returncode == 2
    assert "missing 2 tensor(s): deconv3.0.bias, predict_flow2.weight" in r.stderr
    assert "1 unexpected tensor(s): upsampled_flow6_to_5.bias" in r.stderr
    assert "conv1.0.weight: file [64,12,7,7], model [64,6,7,7]" in r.stderr
    assert not (tmp_path / "bad.safetensors").exists()


def test_half_precision_and_prefixes(original, tmp_path):
    """float16 tensors are widened (with a note); DataParallel's module. prefix is dropped."""
    _, arrays = original
    half = [("module." + n, a.astype(np.float16)) for n, a in arrays]
    src = write_checkpoint(tmp_path / "half.pth.tar", half, "nvidia", "legacy")
    done = cv.convert(str(src), str(tmp_path / "h.safetensors"), check=True)
    assert done["problems"] == [] and done["notes"][0] == "conv1.0.weight is Half, stored as float32"
    got, meta = cv.read_safetensors(str(tmp_path / "h.safetensors"))
    assert meta["inertialnet.checkpoint.published"] == "none"
    for n, a in arrays:
        assert np.array_equal(got[n], a.astype(np.float16).astype(np.float32)), n


def test_the_source_tree_tool_converts_without_torch(original, tmp_path):
    """tools/convert_checkpoint.py runs from a clone with numpy alone for FlowNet2 checkpoints."""
    tool = REPO / "tools" / "convert_checkpoint.py"
    if not tool.exists():
        pytest.skip(f"no source tree beside the tests ({tool})")
    _, arrays = original
    src = write_checkpoint(tmp_path / "flownets-things-mine.ckpt", arrays, "ptlflow", "zip")
    out = tmp_path / "t.safetensors"
    r = subprocess.run([sys.executable, str(tool), str(src), str(out), "--check"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert "FlowNet2-S, 42 tensors, 38,676,506 parameters, verified bit for bit" in r.stdout
    assert cv.read_safetensors(str(out))[1]["inertialnet.checkpoint.layout"] == "ptlflow-lightning"


def test_numpy_scalars_beside_the_state_dict(original, tmp_path):
    """A training run of flownet2-pytorch can store best_EPE as a numpy scalar: numpy rebuilds it."""
    _, arrays = original
    small = [(n, a) for n, a in arrays if n.startswith("conv1.")]
    obj = tf.nvidia_checkpoint([(n, tf.StoredTensor.of(a)) for n, a in small])
    obj["best_EPE"] = np.float64(2.5)
    path = tmp_path / "trained.pth.tar"
    tf.write_legacy(path, obj)
    loaded, fmt = cv.read_checkpoint(str(path))
    assert fmt == "torch-legacy" and loaded["best_EPE"] == 2.5 and type(loaded["best_EPE"]) is np.float64
    tensors, layout = cv.state_dict_of(loaded, str(path))
    assert layout == "flownet2-pytorch" and np.array_equal(tensors["conv1.0.weight"].numpy(), small[0][1])


def test_a_head_needs_torch_only_for_its_configuration(tmp_path):
    """The tool detects an InertialNet head; without torch it says what is missing (exit 2), and
    the torch-free module points to the tool."""
    tool = REPO / "tools" / "convert_checkpoint.py"
    if not tool.exists():
        pytest.skip(f"no source tree beside the tests ({tool})")
    rng = np.random.default_rng(0)
    shapes = {"conv1.weight": (16, 2, 3, 3), "conv1.bias": (16,), "conv2.weight": (32, 16, 3, 3), "conv2.bias": (32,),
              "conv3.weight": (8, 32, 1, 1), "conv3.bias": (8,), "fc1.weight": (128, 8 * 6 * 8), "fc1.bias": (128,),
              "fc2.weight": (3, 128), "fc2.bias": (3,)}
    src = tmp_path / "head.pth"
    tf.write_zip(src, tf.state_dict([(n, rng.standard_normal(s).astype(np.float32)) for n, s in shapes.items()]))
    with pytest.raises(cv.InputError, match="holds an InertialNet head; convert heads with tools/convert_checkpoint.py"):
        cv.convert(str(src), str(tmp_path / "m.safetensors"))
    r = subprocess.run([sys.executable, str(tool), str(src), str(tmp_path / "h.safetensors"), "--head-input", "32x24"],
                       capture_output=True, text=True)
    try:
        import torch  # noqa: F401
    except ImportError:
        assert r.returncode == 2 and "converting a head needs torch for tools/reference/head.py" in r.stderr, r.stderr
    else:
        assert r.returncode == 0, r.stderr
        assert json.loads(cv.read_safetensors(str(tmp_path / "h.safetensors"))[1]["inertialnet.head"])["input_width"] == 32
