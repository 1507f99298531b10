#!/bin/bash
# SPDX-License-Identifier: Apache-2.0
# Run a command from a bundle (bundle.sh) on a machine with an NVIDIA GPU and its driver but
# without Debian's packages: unpacks the bundle, points the OpenCL ICD loader at NVIDIA's OpenCL
# library alone (no other platform, so "the first GPU" is that one) and runs the command with the
# bundle's libraries. Exits 2 on bad input (no bundle file, no command), 1 when the bundle cannot
# be unpacked or no NVIDIA OpenCL library is found, each with one message naming the file.
#
#   tools/portable/run.sh bundle.tar.xz -- inertialnet devices
#   tools/portable/run.sh bundle.tar.xz -- sh -c 'test_flownet_fixtures; tools/compare/compare.py \
#       --inertialnet "$(command -v inertialnet)" --device gpu --torch-device cuda ...'
#
# The bundle's bin/ comes first on PATH. INERTIALNET_BUNDLE_ICD names another vendor library
# (PoCL's, to try the bundle on the build machine).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
me=run.sh
source "$here/errors.sh"
usage="usage: tools/portable/run.sh BUNDLE.tar.xz -- COMMAND [ARG ...]"
[ $# -ge 1 ] || fail 2 "$usage"
bundle=$1; shift; [ "${1:-}" = "--" ] && shift
[ -f "$bundle" ] || fail 2 "no bundle $bundle"
[ $# -ge 1 ] || fail 2 "no command to run from $bundle ($usage)"
dir=${INERTIALNET_BUNDLE_DIR:-/tmp/inertialnet-bundle}
attempt "cannot create the folder $dir" mkdir -p "$dir"
attempt "cannot unpack the bundle $bundle into $dir" tar xJf "$bundle" -C "$dir"
icd=${INERTIALNET_BUNDLE_ICD:-}
[ -n "$icd" ] || icd=$(ls /usr/lib/x86_64-linux-gnu/libnvidia-opencl.so.1 /usr/local/nvidia/lib64/libnvidia-opencl.so.1 2>/dev/null | head -1 || true)
[ -n "$icd" ] || icd=$(find / -xdev -name 'libnvidia-opencl.so.1' 2>/dev/null | head -1)
[ -n "$icd" ] || fail 1 "no libnvidia-opencl.so.1 on this machine"
attempt "cannot create the folder $dir/icd" mkdir -p "$dir/icd"
{ echo "$icd" > "$dir/icd/nvidia.icd"; } 2> /dev/null || fail 1 "cannot write $dir/icd/nvidia.icd"
# The driver's own libraries (libcuda) sit beside its OpenCL library.
export PATH="$dir/bin:$PATH" OCL_ICD_VENDORS="$dir/icd" LD_LIBRARY_PATH="$dir/lib:$(dirname "$icd")${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
exec "$@"
