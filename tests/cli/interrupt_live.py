# SPDX-License-Identifier: Apache-2.0
"""Ctrl-C (SIGINT) ends `inertialnet predict` on a never-ending live source cleanly: exit 0,
every pair computed written, rows flushed one at a time while it runs (so `| tail -f` follows it),
and with -o the file put in place (docs/cli.md, "Live input").

    python3 interrupt_live.py CLI WORK
Exits 0 when all of that holds; prints what did not otherwise.
"""
import os
import re
import select
import signal
import subprocess
import sys
import time

# is-live=true: frames at the pipeline's rate for ever, as a camera gives them; the colour bars
# move sideways, so that every pair has texture and motion.
LIVE = ("gst:videotestsrc is-live=true pattern=smpte horizontal-speed=2 "
        "! video/x-raw,width=96,height=64,framerate=20/1 ! videoconvert ! appsink")
ARGS = ["predict", LIVE, "--fx", "80"]


def data_rows(text):
    return [line for line in text.split("\n") if line and not line.startswith("#") and not line.startswith("timestamp")]


def check_rows(rows, stopped, what, problems):
    for line in rows:
        if len(line.split(",")) != 8:  # timestamp_ns, wx, wy, wz, status, sigma_wx, sigma_wy, sigma_wz
            problems.append(f"{what}: a torn row {line!r}")
    if stopped is None:
        problems.append(f"{what}: no 'stopped after N pairs (Ctrl-C)' message")
    elif int(stopped) != len(rows):
        problems.append(f"{what}: {len(rows)} rows written but {stopped} pairs reported")
    stamps = [int(line.split(",")[0]) for line in rows]
    if stamps != sorted(set(stamps)):
        problems.append(f"{what}: the timestamps do not increase: {stamps}")


def stopped_count(stderr):
    found = re.search(r"stopped after (\d+) pairs \(Ctrl-C\)", stderr)
    return found.group(1) if found else None


def standard_output(cli, work, problems):
    """Rows on a pipe: three of them read while the run goes on, then Ctrl-C."""
    run = subprocess.Popen([cli] + ARGS, cwd=work, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    seen, told, deadline = b"", b"", time.monotonic() + 120
    while time.monotonic() < deadline and len(data_rows(seen.decode())) < 3:
        ready, _, _ = select.select([run.stdout, run.stderr], [], [], 0.1)
        if run.stderr in ready:
            told += os.read(run.stderr.fileno(), 65536)  # read as it comes: a full pipe would stall the run
        if run.stdout in ready:
            chunk = os.read(run.stdout.fileno(), 65536)
            if not chunk:
                break
            seen += chunk
    if len(data_rows(seen.decode())) < 3:
        run.kill()
        problems.append(f"stdout: fewer than 3 rows arrived on the pipe while the run went on: {seen!r}")
        return
    run.send_signal(signal.SIGINT)
    rest, err = run.communicate(timeout=120)
    out, err = (seen + rest).decode(), (told + err).decode()
    if run.returncode != 0:
        problems.append(f"stdout: exit {run.returncode} after Ctrl-C, expected 0: {err.strip()}")
    check_rows(data_rows(out), stopped_count(err), "stdout", problems)
    print(f"stdout: {len(data_rows(out))} rows; {err.strip().splitlines()[-1]}")


def output_file(cli, work, problems):
    """-o: the journal holds whole rows while the run goes on; Ctrl-C puts the file in place."""
    target = os.path.join(work, "interrupted.csv")
    partial = target + ".partial"
    run = subprocess.Popen([cli] + ARGS + ["-o", target], cwd=work, stdout=subprocess.DEVNULL,
                           stderr=subprocess.PIPE)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and run.poll() is None:
        if os.path.exists(partial) and len(data_rows(open(partial, encoding="utf-8").read())) >= 3:
            break
        time.sleep(0.05)
    if run.poll() is not None:
        problems.append(f"-o: predict ended (exit {run.returncode}) before Ctrl-C")
        return
    run.send_signal(signal.SIGINT)
    _, err = run.communicate(timeout=120)
    err = err.decode()
    if run.returncode != 0:
        problems.append(f"-o: exit {run.returncode} after Ctrl-C, expected 0: {err.strip()}")
    if os.path.exists(partial) or not os.path.exists(target):
        problems.append("-o: after Ctrl-C the journal was not put in place as interrupted.csv")
        return
    check_rows(data_rows(open(target, encoding="utf-8").read()), stopped_count(err), "-o", problems)


def main():
    cli, work = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    problems = []
    standard_output(cli, work, problems)
    output_file(cli, work, problems)
    for p in problems:
        print("FAILED:", p)
    print("all checks passed" if not problems else "see above")
    sys.exit(1 if problems else 0)


main()
