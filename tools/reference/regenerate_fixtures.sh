#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Regenerates every fixture of tests/data/fixtures/ with the PyTorch reference, in one command:
#   tools/reference/regenerate_fixtures.sh
# Creates the ignored virtual environment .venv-reference (override with INERTIALNET_REFERENCE_VENV)
# when missing, installs the pinned requirements (PyPI; torch is large), self-tests the reference,
# writes the fixtures and checks them. Only needed after a change to the reference or the spec;
# CI never runs this.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
VENV="${INERTIALNET_REFERENCE_VENV:-$ROOT/.venv-reference}"
PY="$VENV/bin/python"
if [ ! -x "$PY" ]; then
  python3 -m venv "$VENV"
fi
"$PY" -m pip install --quiet --disable-pip-version-check -r "$ROOT/tools/reference/requirements.txt"
export PYTHONDONTWRITEBYTECODE=1
# The reference itself first (ops against the spec's loops, parameter counts, names, converter).
"$PY" -m pytest -q -p no:cacheprovider --ignore="$ROOT/tools/reference/tests/test_fixtures.py" \
  "$ROOT/tools/reference/tests"
"$PY" "$ROOT/tools/reference/make_fixtures.py" "$@"
"$PY" "$ROOT/tools/reference/make_head_gradient_fixture.py"
# Then the written fixtures against a fresh run.
"$PY" -m pytest -q -p no:cacheprovider "$ROOT/tools/reference/tests/test_fixtures.py"
