#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Build a stand-in for a shared library: the same soname, version nodes and exported symbols as
the real one, every function printing its name and aborting.

Why: Debian's OpenCV pulls in GDAL, FFmpeg, GStreamer and their trees (≈ 300 MB), which a machine
without Debian's packages (a lent GPU machine) lacks and which the benchmarks and network tests
never call. Its libraries are linked with -z now, so every symbol they import must resolve when
they load; a stand-in answers for the real library and fails loudly if its code is ever reached.

    stub_library.py /lib/x86_64-linux-gnu/libgdal.so.32 OUTDIR
"""
import collections
import os
import re
import subprocess
import sys


def main() -> int:
    real, outdir = sys.argv[1], sys.argv[2]
    dynamic = subprocess.run(["readelf", "-d", real], capture_output=True, text=True, check=True).stdout
    soname = re.search(r"\(SONAME\).*\[(.*)\]", dynamic).group(1)
    table = subprocess.run(["objdump", "-T", real], capture_output=True, text=True, check=True).stdout
    nodes = collections.OrderedDict()  # version node -> symbol names ("" for unversioned)
    source = ["#include <stdio.h>", "#include <stdlib.h>"]
    seen = set()
    # objdump -T: address, flags (7 columns), section, size, [version], name.
    pattern = re.compile(r"^[0-9a-f]{16} (.{7}) (\S+)\s+([0-9a-f]{16})\s+(?:(\S+)\s+)?(\S+)$")
    for line in table.splitlines():
        match = pattern.match(line)
        if not match:
            continue
        flags, section, size, version, name = match.groups()
        if section in ("*UND*", "*ABS*") or name in seen:
            continue
        seen.add(name)
        version = (version or "").strip("()")
        nodes.setdefault("" if "Base" in version else version, []).append(name)
        n = len(seen)
        if "O" in flags:  # data: an object of the same size (its contents are never read)
            tls = "__thread " if section in (".tbss", ".tdata") else ""
            source.append(f'{tls}char object{n}[{max(int(size, 16), 1)}] __asm__("{name}");')
        else:
            source.append(f'void function{n}(void) __asm__("{name}");')
            source.append(f'void function{n}(void) {{ fputs("stand-in {soname}: {name} called\\n", stderr); abort(); }}')
    c_file = os.path.join(outdir, soname + ".c")
    with open(c_file, "w") as out:
        out.write("\n".join(source) + "\n")
    command = ["cc", "-shared", "-fPIC", "-w", "-o", os.path.join(outdir, soname), c_file, "-Wl,-soname," + soname]
    named = [v for v in nodes if v]
    if named:  # one node per version the real library defines; unversioned names go to the first
        script = c_file + ".map"
        with open(script, "w") as out:
            for i, version in enumerate(named):
                names = nodes[version] + (nodes.get("", []) if i == 0 else [])
                out.write(version + " {\n  global:\n" + "".join(f'    "{n}";\n' for n in names)
                          + ("  local: *;\n" if i == 0 else "") + "};\n")
        command.append("-Wl,--version-script=" + script)
    subprocess.run(command, check=True)
    for leftover in (c_file, c_file + ".map"):
        if os.path.exists(leftover):
            os.remove(leftover)
    print(f"{soname}: {len(seen)} symbols, {len(named)} version nodes")
    return 0


if __name__ == "__main__":
    sys.exit(main())
