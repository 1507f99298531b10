#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The Python package as a user installs it: `pip install .` into a fresh virtual environment (a
# full build of the library through scikit-build-core), then the pytest suite against the
# installed package and the command line in build/.
#   bash tools/check_pip_install.sh     (after tools/build.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
venv=build/pip-install-venv
rm -rf "$venv"
python3 -m venv "$venv"
start=$(date +%s)
# With the [ray] extra, so that inertialnet.batch's Ray test runs here too (it is skipped only
# outside CI when ray is missing).
"$venv/bin/python" -m pip install -q --disable-pip-version-check ".[test,ray]"
echo "check_pip_install: pip install . took $(( $(date +%s) - start )) s"
# From outside the source tree, so that `import inertialnet` finds the installed package.
cd "$venv"
INERTIALNET_CLI="$OLDPWD/build/inertialnet" bin/python -m pytest -q -p no:cacheprovider "$OLDPWD/python/tests" \
  --basetemp="$PWD/pytest"
