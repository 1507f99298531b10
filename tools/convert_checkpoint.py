#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Convert a flownet2-pytorch checkpoint or an InertialNet head state_dict to safetensors.

Inputs:
  * flownet2-pytorch `*.pth.tar` files (torch.save of {'epoch', 'state_dict', 'best_EPE'}) of
    FlowNet2, FlowNet2-C, -S, -SD, -CS or -CSS; the kind is detected from the tensor names.
  * an InertialNet head: a torch.save'd state_dict (names `head.conv1.weight` ... or
    `conv1.weight` ...), optionally wrapped as {'state_dict': ..., 'head_config': {...}}. The
    flow size the head was trained on cannot be read off the weights: give --head-input WxH
    (or a head_config / --head-config holding input_width and input_height).

Every tensor name and shape is validated against the PyTorch reference model
(tools/reference/); all missing, unexpected and mis-shaped tensors are listed together.
The output holds float32 tensors under the flownet2-pytorch names and the metadata
  inertialnet.model      FlowNet2 | FlowNet2-C | FlowNet2-S | FlowNet2-SD | FlowNet2-CS |
                         FlowNet2-CSS | InertialNetHead
  inertialnet.synthetic  "false"
  inertialnet.head       (head only) JSON of the head's hyper-parameters incl. input H and W
  inertialnet.source     file name of the input

Exit codes: 0 success; 1 runtime failure (I/O, --check mismatch); 2 bad usage or bad input.
Needs torch, numpy and safetensors (tools/reference/requirements.txt).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "reference"))

EXIT_OK, EXIT_RUNTIME, EXIT_INPUT = 0, 1, 2
FLOWNET2_PREFIXES = ("flownetc", "flownets_1", "flownets_2", "flownets_d", "flownetfusion")
HEAD_LAYERS = ("conv1", "conv2", "conv3", "fc1", "fc2")


class InputError(Exception):
    """Bad input or usage: exit code 2."""


def _import_torch():
    import importlib

    try:
        for module in ("torch", "safetensors", "numpy"):
            importlib.import_module(module)
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise InputError(f"this tool needs torch and safetensors ({e}); run it with the "
                         "virtual environment of tools/reference/regenerate_fixtures.sh") from e


# ------------------------------------------------------------------------------- loading ----

def load_checkpoint(path: str, trust_pickle: bool):
    import torch

    if not os.path.isfile(path):
        raise InputError(f"{path}: no such file")
    try:
        obj = torch.load(path, map_location="cpu", weights_only=True)
    except Exception as e:  # noqa: BLE001 - torch raises many types for foreign files
        if not trust_pickle:
            raise InputError(
                f"{path}: cannot be read as a tensors-only torch checkpoint ({type(e).__name__}: "
                f"{str(e).splitlines()[0] if str(e) else ''}); if you trust the file, pass "
                "--trust-pickle to load arbitrary pickled objects") from e
        try:
            obj = torch.load(path, map_location="cpu", weights_only=False)
        except Exception as e2:  # noqa: BLE001
            raise InputError(f"{path}: not a torch checkpoint ({type(e2).__name__}: {e2})") from e2
    head_config = None
    if isinstance(obj, dict) and "state_dict" in obj and isinstance(obj["state_dict"], dict):
        head_config = obj.get("head_config")
        state = obj["state_dict"]
    elif isinstance(obj, dict):
        state = obj
    else:
        raise InputError(f"{path}: holds a {type(obj).__name__}, expected a dict with a "
                         "'state_dict' or a state_dict itself")
    tensors = {}
    not_tensors = []
    for k, v in state.items():
        if isinstance(v, torch.Tensor):
            tensors[str(k)] = v
        else:
            not_tensors.append(str(k))
    if not_tensors:
        raise InputError(f"{path}: state_dict entries that are not tensors: {not_tensors}")
    if not tensors:
        raise InputError(f"{path}: the state_dict holds no tensors")
    if all(k.startswith("module.") for k in tensors):  # saved from nn.DataParallel
        tensors = {k[len("module."):]: v for k, v in tensors.items()}
    return tensors, head_config


# ------------------------------------------------------------------------------ detection ---

def detect_kind(names) -> str:
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
        return "InertialNetHead"
    if "conv_redir.0.weight" in names:
        return "FlowNet2-C"
    if "inter_conv2.0.weight" in names or "conv0.0.weight" in names:
        return "FlowNet2-SD"
    if "conv1.0.weight" in names:
        return "FlowNet2-S"
    sample = sorted(names)[:5]
    raise InputError(f"cannot tell which model the checkpoint holds (first names: {sample}); "
                     "pass --model")


# --------------------------------------------------------------------------------- head -----

def parse_size(text: str):
    try:
        w, h = text.lower().split("x")
        w, h = int(w), int(h)
        if w <= 0 or h <= 0:
            raise ValueError
        return w, h
    except ValueError:
        raise InputError(f"--head-input expects WxH with positive integers, got {text!r}") from None


def head_config_for(tensors: dict, embedded, args):
    import head as hd

    # Accept bare layer names (a head module saved on its own) as well as head.*.
    if not any(k.startswith("head.") for k in tensors):
        tensors = {f"head.{k}": v for k, v in tensors.items()}
    cfg = {}
    if embedded is not None:
        if not isinstance(embedded, dict):
            raise InputError("the checkpoint's head_config is not a dict")
        cfg.update(embedded)
    if args.head_config:
        text = args.head_config
        if os.path.isfile(text):
            with open(text, encoding="utf-8") as f:
                text = f.read()
        try:
            cfg.update(json.loads(text))
        except json.JSONDecodeError as e:
            raise InputError(f"--head-config is neither a JSON file nor JSON text ({e})") from e
    if args.head_input:
        cfg["input_width"], cfg["input_height"] = parse_size(args.head_input)
    if args.head_dropout is not None:
        cfg["dropout"] = args.head_dropout
    if args.head_flow_scale is not None:
        cfg["flow_scale"] = args.head_flow_scale
    if "input_width" not in cfg or "input_height" not in cfg:
        raise InputError("the head's input flow size is not stored in its weights; pass "
                         "--head-input WxH (e.g. 752x480)")
    # Layer sizes come from the weights unless given explicitly.
    shapes = {k: tuple(v.shape) for k, v in tensors.items()}

    def take(key, name, dim):
        if key not in cfg and name in shapes and len(shapes[name]) > dim:
            cfg[key] = int(shapes[name][dim])

    take("in_channels", "head.conv1.weight", 1)
    take("conv1_channels", "head.conv1.weight", 0)
    take("conv1_kernel", "head.conv1.weight", 2)
    take("conv2_channels", "head.conv2.weight", 0)
    take("conv2_kernel", "head.conv2.weight", 2)
    take("conv3_channels", "head.conv3.weight", 0)
    take("conv3_kernel", "head.conv3.weight", 2)
    take("fc1_units", "head.fc1.weight", 0)
    take("outputs", "head.fc2.weight", 0)
    try:
        config = hd.HeadConfig.from_dict(cfg)
    except (TypeError, ValueError) as e:
        raise InputError(f"invalid head hyper-parameters: {e}") from e
    return tensors, config


# ----------------------------------------------------------------------------- validation ---

def _fmt(shape) -> str:
    return "[" + ",".join(str(int(s)) for s in shape) + "]"


def validate(tensors: dict, expected: dict, model: str):
    import torch

    missing = [n for n in expected if n not in tensors]
    extra = sorted(n for n in tensors if n not in expected)
    wrong = [f"{n}: file {_fmt(tensors[n].shape)}, model {_fmt(expected[n])}"
             for n in expected if n in tensors and tuple(tensors[n].shape) != tuple(expected[n])]
    bad_dtype = [f"{n}: {tensors[n].dtype}" for n in expected
                 if n in tensors and not tensors[n].is_floating_point()]
    problems = []
    if missing:
        problems.append(f"missing {len(missing)} tensor(s): " + ", ".join(missing))
    if extra:
        problems.append(f"{len(extra)} unexpected tensor(s): " + ", ".join(extra))
    if wrong:
        problems.append(f"{len(wrong)} with the wrong shape: " + "; ".join(wrong))
    if bad_dtype:
        problems.append(f"{len(bad_dtype)} not floating point: " + "; ".join(bad_dtype))
    if problems:
        n_file = sum(int(t.numel()) for t in tensors.values())
        n_model = sum(int(torch.Size(s).numel()) for s in expected.values())
        raise InputError(f"the checkpoint does not fit {model} ({len(tensors)} tensors, "
                         f"{n_file:,} parameters; the model has {len(expected)} tensors, "
                         f"{n_model:,} parameters):\n  " + "\n  ".join(problems))


# ------------------------------------------------------------------------------- writing ----

def to_float32(tensors: dict, order, quiet: bool) -> dict:
    import torch

    out = {}
    for n in order:
        t = tensors[n].detach().cpu()
        if t.dtype != torch.float32:
            if not quiet:
                print(f"note: {n} is {t.dtype}, stored as float32", file=sys.stderr)
            t = t.to(torch.float32)
        out[n] = t.contiguous()
    return out


def write(path: str, tensors: dict, metadata: dict) -> None:
    from safetensors.torch import save_file

    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        raise InputError(f"{path}: the folder {folder} does not exist")
    fd, tmp = tempfile.mkstemp(prefix=".convert-", suffix=".safetensors", dir=folder)
    os.close(fd)
    try:
        save_file(tensors, tmp, metadata=metadata)
        os.replace(tmp, path)  # never leave a half-written file under the final name
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def check(path: str, tensors: dict, metadata: dict) -> list:
    """Reloads `path` and compares names, shapes, dtypes, bits and metadata."""
    import torch
    from safetensors import safe_open

    problems = []
    with safe_open(path, framework="pt") as f:
        names = set(f.keys())
        if names != set(tensors):
            problems.append(f"names differ: missing {sorted(set(tensors) - names)}, "
                            f"extra {sorted(names - set(tensors))}")
        for n in sorted(names & set(tensors)):
            got = f.get_tensor(n)
            want = tensors[n]
            if got.dtype != torch.float32 or got.shape != want.shape:
                problems.append(f"{n}: reloaded {got.dtype} {_fmt(got.shape)}, "
                                f"wrote {want.dtype} {_fmt(want.shape)}")
            elif not torch.equal(got.view(torch.int32), want.view(torch.int32)):
                diff = int((got.view(torch.int32) != want.view(torch.int32)).sum())
                problems.append(f"{n}: {diff} element(s) differ bitwise")
        meta = f.metadata() or {}
        for k, v in metadata.items():
            if meta.get(k) != v:
                problems.append(f"metadata {k}: reloaded {meta.get(k)!r}, wrote {v!r}")
    return problems


# ---------------------------------------------------------------------------------- main ----

MODEL_CHOICES = ("FlowNet2", "FlowNet2-C", "FlowNet2-S", "FlowNet2-SD", "FlowNet2-CS",
                 "FlowNet2-CSS", "InertialNetHead")


def build_parser():
    ap = argparse.ArgumentParser(
        prog="convert_checkpoint.py",
        description="Convert a flownet2-pytorch .pth.tar checkpoint or an InertialNet head "
                    "state_dict to a validated float32 safetensors file.",
        epilog="Exit codes: 0 success, 1 runtime failure (I/O, --check mismatch), 2 bad usage "
               "or input (unreadable checkpoint, unknown model, missing/extra/mis-shaped "
               "tensors).")
    ap.add_argument("input", help="checkpoint (.pth.tar / .pth / .pt)")
    ap.add_argument("output", help="safetensors file to write")
    ap.add_argument("--model", choices=MODEL_CHOICES,
                    help="model kind; detected from the tensor names when omitted")
    ap.add_argument("--check", action="store_true",
                    help="reload the written file and compare every tensor bit for bit")
    ap.add_argument("--trust-pickle", action="store_true",
                    help="allow arbitrary pickled objects in the checkpoint (only for files "
                         "you trust; needed for checkpoints holding non-tensor objects)")
    ap.add_argument("--head-input", metavar="WxH",
                    help="head only: width x height of the flow the head takes, e.g. 752x480")
    ap.add_argument("--head-config", metavar="JSON",
                    help="head only: JSON text or file with HeadConfig fields (input_width, "
                         "input_height, conv1_channels, ..., dropout, flow_scale)")
    ap.add_argument("--head-dropout", type=float, help="head only: dropout rate (default 0.3)")
    ap.add_argument("--head-flow-scale", type=float,
                    help="head only: factor applied to the flow before conv1 (default 1)")
    ap.add_argument("-q", "--quiet", action="store_true", help="print nothing on success")
    return ap


def run(args) -> int:
    _import_torch()
    import flownet2 as fn
    import head as hd

    tensors, embedded_head = load_checkpoint(args.input, args.trust_pickle)
    kind = args.model or detect_kind(tensors)
    metadata = {"inertialnet.model": kind, "inertialnet.synthetic": "false",
                "inertialnet.source": os.path.basename(args.input)}
    if kind == "InertialNetHead":
        tensors, cfg = head_config_for(tensors, embedded_head, args)
        expected = hd.expected_shapes(cfg)
        metadata["inertialnet.head"] = cfg.to_json()
    else:
        if args.head_input or args.head_config or args.head_dropout is not None \
                or args.head_flow_scale is not None:
            raise InputError(f"--head-* options apply to InertialNetHead, not {kind}")
        expected = fn.expected_shapes(kind)
    validate(tensors, expected, kind)
    out = to_float32(tensors, list(expected), args.quiet)
    write(args.output, out, metadata)
    if args.check:
        problems = check(args.output, out, metadata)
        if problems:
            print(f"error: {args.output} does not read back as written:\n  " + "\n  ".join(problems),
                  file=sys.stderr)
            return EXIT_RUNTIME
    if not args.quiet:
        n = sum(int(t.numel()) for t in out.values())
        print(f"{args.output}: {kind}, {len(out)} tensors, {n:,} parameters"
              + (", verified bit for bit" if args.check else ""))
    return EXIT_OK


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return run(args)
    except InputError as e:
        print(f"error: {e}", file=sys.stderr)
        return EXIT_INPUT
    except OSError as e:
        print(f"error: {e}", file=sys.stderr)
        return EXIT_RUNTIME


if __name__ == "__main__":
    sys.exit(main())
