#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Convert a FlowNet2-family checkpoint or an InertialNet head state_dict to safetensors.

Inputs:
  * FlowNet2, FlowNet2-C, -S, -SD, -CS or -CSS checkpoints as they are published: NVIDIA
    flownet2-pytorch's `*_checkpoint.pth.tar` ({'epoch', 'state_dict', 'best_EPE'}, torch's legacy
    format) and ptlflow's Lightning `*-things-<sha256 prefix>.ckpt` (torch's zip format); the kind
    is detected from the tensor names. This part is python/inertialnet/convert.py, loaded from
    the source tree (the installed package runs it as `python -m inertialnet.convert`): numpy
    only, no torch; docs/weights.md says where to download each file.
  * an InertialNet head: a torch.save'd state_dict (names `head.conv1.weight` ... or
    `conv1.weight` ...), optionally wrapped as {'state_dict': ..., 'head_config': {...}}. The
    flow size the head was trained on cannot be read off the weights: give --head-input WxH
    (or a head_config / --head-config holding input_width and input_height). Heads need torch
    for the reference HeadConfig (tools/reference/head.py); the checkpoint itself is read
    without it.

Checkpoints are read through a restricted unpickler (tensors, storages, OrderedDict and plain
values only; nothing a pickle names is ever imported or run). Every tensor name and shape is
validated; all missing, unexpected and mis-shaped tensors are listed together. The output holds
float32 tensors under the flownet2-pytorch names and the metadata
  inertialnet.model      FlowNet2 | FlowNet2-C | FlowNet2-S | FlowNet2-SD | FlowNet2-CS |
                         FlowNet2-CSS | InertialNetHead
  inertialnet.synthetic  "false"
  inertialnet.head       (head only) JSON of the head's hyper-parameters incl. input H and W
  inertialnet.source     file name of the input
  inertialnet.checkpoint.*  file, format, layout, sha256, published, checksum, url: which
                         published checkpoint the weights came from (`inertialnet weights --info`)

Exit codes: 0 success; 1 runtime failure (I/O, --check mismatch); 2 bad usage or bad input.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "reference"))


def _load_convert_module():
    # By path, not `import inertialnet.convert`: the package's __init__ needs the built native module.
    path = os.path.join(os.path.dirname(HERE), "python", "inertialnet", "convert.py")
    spec = importlib.util.spec_from_file_location("inertialnet_convert", path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


cv = _load_convert_module()
InputError = cv.InputError
EXIT_OK, EXIT_RUNTIME, EXIT_INPUT = cv.EXIT_OK, cv.EXIT_RUNTIME, cv.EXIT_INPUT
detect_kind = cv.detect_kind
check = cv.check_written


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


def _import_head():
    try:
        import head as hd
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise InputError(f"converting a head needs torch for tools/reference/head.py ({e}); run it with the "
                         "virtual environment of tools/reference/regenerate_fixtures.sh") from e
    return hd


def head_config_for(tensors: dict, embedded, args):
    hd = _import_head()
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


def convert_head(args) -> dict:
    sha256 = cv.sha256_of(args.input) if os.path.isfile(args.input) else ""
    obj, fmt = cv.read_checkpoint(args.input)
    tensors, layout = cv.state_dict_of(obj, args.input)
    embedded = obj.get("head_config") if isinstance(obj, dict) and "state_dict" in obj else None
    tensors, cfg = head_config_for(tensors, embedded, args)
    expected = _import_head().expected_shapes(cfg)
    cv.validate(tensors, expected, cv.HEAD_KIND)
    origin = {"published": "none", "checksum": "no head checkpoint is published"}
    metadata = {"inertialnet.model": cv.HEAD_KIND, "inertialnet.synthetic": "false",
                "inertialnet.source": os.path.basename(args.input), "inertialnet.head": cfg.to_json()}
    metadata.update(cv.checkpoint_metadata(args.input, fmt, layout, sha256, origin))
    notes = []
    cv.write_safetensors(args.output, [(n, expected[n], cv._as_float32(n, tensors[n], notes)) for n in expected],
                         metadata)
    problems = check(args.output, {n: tensors[n] for n in expected}, metadata) if args.check else []
    return {"kind": cv.HEAD_KIND, "tensors": len(expected), "notes": notes, "problems": problems,
            "parameters": sum(int(cv.np.prod(s, dtype=cv.np.int64)) for s in expected.values())}


# ---------------------------------------------------------------------------------- main ----

MODEL_CHOICES = cv.FLOWNET2_KINDS + (cv.HEAD_KIND,)


def build_parser():
    ap = argparse.ArgumentParser(
        prog="convert_checkpoint.py",
        description="Convert a FlowNet2-family checkpoint (flownet2-pytorch .pth.tar, ptlflow .ckpt) or an "
                    "InertialNet head state_dict to a validated float32 safetensors file.",
        epilog=cv.EXIT_CODES_EPILOG)
    cv.add_checkpoint_arguments(ap, MODEL_CHOICES)
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
    head_options = args.head_input or args.head_config or args.head_dropout is not None \
        or args.head_flow_scale is not None
    kind = args.model
    if kind is None:
        obj, _ = cv.read_checkpoint(args.input)
        kind = cv.detect_kind(cv.state_dict_of(obj, args.input)[0])
    if kind == cv.HEAD_KIND:
        if args.sha256:
            raise InputError("--sha256 applies to published FlowNet2 checkpoints, not heads")
        done = convert_head(args)
    else:
        if head_options:
            raise InputError(f"--head-* options apply to InertialNetHead, not {kind}")
        done = cv.convert(args.input, args.output, kind, args.check, args.sha256)
    code = cv.report(done, args.output, args.check, args.quiet, note="note: ", error="error: ")
    if code == EXIT_OK and not args.quiet:
        meta = done.get("metadata")
        if meta:
            print(f"  published checkpoint: {meta['inertialnet.checkpoint.published']} (checksum: "
                  f"{meta['inertialnet.checkpoint.checksum']})")
    return code


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    return cv.exit_code(lambda: run(args), "error: ")


if __name__ == "__main__":
    sys.exit(main())
