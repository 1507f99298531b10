# SPDX-License-Identifier: Apache-2.0
# Sourced by bundle.sh and run.sh (which set $me to their name): the project's exit codes, each
# failure as one message naming the file (2: bad input, 1: a runtime failure).
#
#   fail STATUS MESSAGE         prints "$me: MESSAGE" on stderr and exits STATUS
#   attempt WHAT COMMAND [ARG ...]
#                               runs COMMAND; where it fails, exits 1 saying WHAT failed with the
#                               first reason the command gave ("No space left on device") in place
#                               of its own lines
fail() { echo "$me: $2" >&2; exit "$1"; }
attempt() {
  local what=$1 err; shift
  err=$("$@" 2>&1) && return
  err=${err%%$'\n'*}; err=${err##*: }
  fail 1 "$what${err:+ ($err)}"
}
