# SPDX-License-Identifier: Apache-2.0
"""`kill -9` in the middle of `inertialnet predict -o r.csv`: the rows so far are in r.csv.partial
(whole rows, a valid rates CSV) with its sidecar r.csv.partial.json, an earlier complete r.csv and
its sidecar r.csv.json are untouched, and nothing else is left beside them (docs/cli.md, "When a
run fails or is killed"). The sidecar's row count and FNV-1a hash are computed here anew.

    python3 kill_during_predict.py CLI WORK SEQUENCE
Exits 0 when all of that holds; prints what did not otherwise.
"""
import json
import os
import signal
import subprocess
import sys
import time


def rows(path):
    with open(path, encoding="utf-8") as f:
        return [line for line in f.read().split("\n")[:-1] if line and not line.startswith("#")]


def fnv1a64(data):
    """FNV-1a, 64 bit, of the bytes (docs/data_conventions.md, "Rates CSV")."""
    h = 0xcbf29ce484222325
    for byte in data:
        h = ((h ^ byte) * 0x100000001b3) & 0xFFFFFFFFFFFFFFFF
    return "%016x" % h


def sidecar(rows_, data, frame):
    return json.dumps({"schema": "inertialnet.rates/3", "rows": rows_, "fnv1a64": fnv1a64(data),
                       "metadata": {"frame": frame}})


def main():
    cli, work, sequence = sys.argv[1:4]
    target = os.path.join(work, "r.csv")
    partial = target + ".partial"
    earlier = "timestamp_ns,wx,wy,wz,status\n1,0,0,0,ok\n"
    earlier_sidecar = sidecar(1, earlier.encode(), "camera")
    with open(target, "w", encoding="utf-8") as f:
        f.write(earlier)
    with open(target + ".json", "w", encoding="utf-8") as f:
        f.write(earlier_sidecar)
    before = set(os.listdir(work))
    run = subprocess.Popen([cli, "-q", "predict", sequence, "-o", target], cwd=work,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 240
    # Killed once a few rows are on the disk, well before the end of the sequence.
    while time.monotonic() < deadline and run.poll() is None:
        if os.path.exists(partial) and len(rows(partial)) >= 4:
            break
        time.sleep(0.05)
    if run.poll() is not None:
        sys.exit(f"predict ended (exit {run.returncode}) before it could be killed; use a longer sequence")
    run.send_signal(signal.SIGKILL)
    run.wait()
    problems = []
    with open(target, encoding="utf-8") as f:
        if f.read() != earlier:
            problems.append("the earlier r.csv was changed")
    with open(target + ".json", encoding="utf-8") as f:
        if f.read() != earlier_sidecar:
            problems.append("the earlier r.csv.json was changed")
    got = rows(partial)
    if got[0] != "timestamp_ns,wx,wy,wz,status,sigma_wx,sigma_wy,sigma_wz" or len(got) < 4:
        problems.append(f"r.csv.partial holds {got[:2]}…, expected the header and at least 3 rows")
    for line in got[1:]:
        if len(line.split(",")) != 8:
            problems.append(f"a torn row in r.csv.partial: {line!r}")
    left = set(os.listdir(work)) - before
    if left != {"r.csv.partial", "r.csv.partial.json"}:
        problems.append(f"the killed run left {sorted(left)}, expected r.csv.partial and its sidecar only")
    # eval reads the rows so far; a rerun completes and takes its place.
    check = subprocess.run([cli, "-q", "eval", partial, sequence], cwd=work, capture_output=True, text=True)
    if check.returncode != 0:
        problems.append(f"eval of r.csv.partial failed: {check.stderr.strip()}")
    elif "does not state its frame" in check.stdout + check.stderr:
        problems.append("eval of r.csv.partial did not find the journal's sidecar")
    rerun = subprocess.run([cli, "-q", "predict", sequence, "-o", target, "--max-pairs", "3"], cwd=work,
                           capture_output=True, text=True)
    if rerun.returncode != 0 or os.path.exists(partial) or len(rows(target)) != 4:
        problems.append(f"the rerun did not replace r.csv cleanly (exit {rerun.returncode}: {rerun.stderr.strip()})")
    with open(target, "rb") as f:
        data = f.read()
    with open(target + ".json", encoding="utf-8") as f:
        doc = json.load(f)
    if doc.get("rows") != 3 or doc.get("fnv1a64") != fnv1a64(data) or doc["metadata"].get("frame") != "body":
        problems.append(f"r.csv.json does not describe the rerun's r.csv: {doc}")
    if os.path.exists(partial + ".json"):
        problems.append("the rerun left r.csv.partial.json")
    for p in problems:
        print("FAILED:", p)
    print(f"killed after {len(got) - 1} rows; " + ("all checks passed" if not problems else "see above"))
    sys.exit(1 if problems else 0)


main()
