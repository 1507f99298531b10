"""`kill -9` in the middle of `inertialnet predict -o r.csv`: the rows so far are in r.csv.partial
(whole rows, a valid rates CSV), an earlier complete r.csv is untouched, and nothing else is left
beside it (docs/cli.md, "When a run fails or is killed").

    python3 kill_during_predict.py CLI WORK SEQUENCE
Exits 0 when all of that holds; prints what did not otherwise.
"""
import os
import signal
import subprocess
import sys
import time


def rows(path):
    with open(path, encoding="utf-8") as f:
        return [line for line in f.read().split("\n")[:-1] if line and not line.startswith("#")]


def main():
    cli, work, sequence = sys.argv[1:4]
    target = os.path.join(work, "r.csv")
    partial = target + ".partial"
    earlier = "# schema: inertialnet.rates/2\ntimestamp_ns,wx,wy,wz,status\n1,0,0,0,ok\n"
    with open(target, "w", encoding="utf-8") as f:
        f.write(earlier)
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
    got = rows(partial)
    if got[0] != "timestamp_ns,wx,wy,wz,status" or len(got) < 4:
        problems.append(f"r.csv.partial holds {got[:2]}…, expected the header and at least 3 rows")
    for line in got[1:]:
        if len(line.split(",")) != 5:
            problems.append(f"a torn row in r.csv.partial: {line!r}")
    left = set(os.listdir(work)) - before
    if left != {"r.csv.partial"}:
        problems.append(f"the killed run left {sorted(left)}, expected r.csv.partial only")
    # eval reads the rows so far; a rerun completes and takes its place.
    check = subprocess.run([cli, "-q", "eval", partial, sequence], cwd=work, capture_output=True, text=True)
    if check.returncode != 0:
        problems.append(f"eval of r.csv.partial failed: {check.stderr.strip()}")
    rerun = subprocess.run([cli, "-q", "predict", sequence, "-o", target, "--max-pairs", "3"], cwd=work,
                           capture_output=True, text=True)
    if rerun.returncode != 0 or os.path.exists(partial) or len(rows(target)) != 4:
        problems.append(f"the rerun did not replace r.csv cleanly (exit {rerun.returncode}: {rerun.stderr.strip()})")
    for p in problems:
        print("FAILED:", p)
    print(f"killed after {len(got) - 1} rows; " + ("all checks passed" if not problems else "see above"))
    sys.exit(1 if problems else 0)


main()
