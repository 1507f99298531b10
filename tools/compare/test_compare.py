# SPDX-License-Identifier: Apache-2.0
"""compare.py's bookkeeping with stand-ins for inertialnet and PyTorch (needs neither torch nor a build):
each plan's figures land on its own row, and a run whose figures cannot be its plan's is flagged.

    python -m pytest -q -p no:cacheprovider tools/compare/test_compare.py
"""

import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))

# A stand-in for `inertialnet bench --json`: seconds per plan, and the backends its layers ran on;
# STUCK_PLAN makes every plan report that plan's run (a binary that ignores --plan).
FAKE_INERTIALNET = r'''#!/usr/bin/env python3
import json, os, sys
plan = sys.argv[sys.argv.index("--plan") + 1] if "--plan" in sys.argv else "packed"
plan = os.environ.get("STUCK_PLAN", plan)
flow = {"packed": 1.086, "winograd": 0.881}[plan]
backends = {"packed": ["packed"], "winograd": ["packed", "winograd"]}[plan]
print(json.dumps({"results": [{"device": "stand-in", "stages": {"flow": flow}, "seconds_per_pair": flow + 0.013,
                               "profile": {"kinds": [{"kind": "conv 3x3 s1", "backends": backends}]}}]}))
'''

FAKE_PYTHON = r'''#!/usr/bin/env python3
import json, sys
print(json.dumps({"torch": "stand-in", "torch_device": "cpu", "seconds_per_pair": 1.285 if "--tf32" not in sys.argv else 0.9,
                  "tf32": "--tf32" in sys.argv}))
'''


def run_compare(tmp_path, extra_env=None, extra_args=(), json_output=True):
    binary = tmp_path / "inertialnet"
    binary.write_text(FAKE_INERTIALNET)
    binary.chmod(0o755)
    (tmp_path / "venv" / "bin").mkdir(parents=True, exist_ok=True)
    python = tmp_path / "venv" / "bin" / "python"
    python.write_text(FAKE_PYTHON)
    python.chmod(0o755)
    env = dict(os.environ, **(extra_env or {}))
    done = subprocess.run([sys.executable, os.path.join(HERE, "compare.py"), "--venv", str(tmp_path / "venv"),
                           "--inertialnet", str(binary), "--models", "FlowNet2", "--rounds", "2",
                           "--plan", "packed,winograd", *extra_args] + (["--json"] if json_output else []),
                          env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, check=True)
    return (json.loads(done.stdout) if json_output else done.stdout), done.stderr


def test_each_plan_gets_its_own_figures(tmp_path):
    result, log = run_compare(tmp_path)
    by_plan = {r["plan"]: r for r in result["results"]}
    assert by_plan["packed"]["runs"]["ours"] == [1.086, 1.086]
    assert by_plan["winograd"]["runs"]["ours"] == [0.881, 0.881]
    assert "WARNING" not in log


def test_a_run_that_cannot_be_its_plan_is_flagged(tmp_path):
    result, log = run_compare(tmp_path, {"STUCK_PLAN": "packed"})
    winograd_lines = [line for line in log.splitlines() if "--plan winograd" in line]
    assert len(winograd_lines) == 2
    for line in winograd_lines:
        assert "WARNING: no layer ran on plan winograd (the profile shows packed)" in line
        assert "figures identical to --plan packed's run: suspect" in line
    by_plan = {r["plan"]: r for r in result["results"]}
    assert all(by_plan["winograd"]["runs"]["notes"])
    assert not any(by_plan["packed"]["runs"]["notes"])


def test_pytorch_computes_in_float32_unless_tf32_is_asked_for(tmp_path):
    # PyTorch's GPU default runs float32 convolutions on TF32 tensor cores; ours are float32, so
    # --tf32 is passed on only when asked, and the result says which comparison it is.
    result, _ = run_compare(tmp_path)
    assert result["torch_tf32"] is False
    assert all(r["torch_seconds_per_pair"] == 1.285 for r in result["results"])
    result, _ = run_compare(tmp_path, extra_args=["--tf32"])
    assert result["torch_tf32"] is True
    assert all(r["torch_seconds_per_pair"] == 0.9 for r in result["results"])
    table, _ = run_compare(tmp_path, extra_args=["--tf32"], json_output=False)
    assert "float32 (PyTorch: TF32 allowed)" in table.splitlines()[0]
