#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Runs a command on a pseudo-terminal, as a person at a terminal would, and prints what it wrote.

    pty_run.py [--interrupt-after REGEX] [--timeout SECONDS] -- COMMAND [ARG...]

stdin, stdout and stderr of COMMAND are the terminal, so `isatty` is true and a progress line is
drawn. With --interrupt-after, Ctrl-C is typed (the terminal's interrupt character, so the kernel
sends SIGINT to the command's process group) as soon as the output matches REGEX. The output is
printed with the terminal's CR LF turned into LF (a lone CR, a progress redraw, is kept); the exit
status is the command's (128 + signal when a signal ended it)."""
import os
import pty
import re
import select
import sys
import time


def main():
    args = sys.argv[1:]
    interrupt_after, timeout = None, 300.0
    while args and args[0] != "--":
        if args[0] == "--interrupt-after":
            interrupt_after = re.compile(args[1])
            args = args[2:]
        elif args[0] == "--timeout":
            timeout = float(args[1])
            args = args[2:]
        else:
            sys.exit("pty_run.py: unknown argument " + args[0])
    command = args[1:]
    pid, fd = pty.fork()
    if pid == 0:
        os.execvp(command[0], command)
    output = b""
    interrupted = False
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        ready, _, _ = select.select([fd], [], [], 0.05)
        if ready:
            try:
                chunk = os.read(fd, 65536)
            except OSError:  # EIO: the command closed the terminal (it exited)
                break
            if not chunk:
                break
            output += chunk
        if interrupt_after and not interrupted and interrupt_after.search(output.decode("utf-8", "replace")):
            os.write(fd, b"\x03")
            interrupted = True
    else:
        os.kill(pid, 9)
        print("pty_run.py: timed out", file=sys.stderr)
    _, status = os.waitpid(pid, 0)
    sys.stdout.write(output.decode("utf-8", "replace").replace("\r\n", "\n"))
    if interrupt_after and not interrupted:
        print("pty_run.py: the output never matched the interrupt pattern", file=sys.stderr)
        sys.exit(3)
    sys.exit(os.WEXITSTATUS(status) if os.WIFEXITED(status) else 128 + os.WTERMSIG(status))


if __name__ == "__main__":
    main()
