#!/usr/bin/env bash
# Creates (idempotently) the Python venv used by the Cyclone DDS interop test:
#   tests/cyclone/.venv  with  cyclonedds==$CYCLONEDDS_VERSION  (PyPI wheel, bundles libddsc).
# Needs CPython >= 3.8 with the venv module (tested: CPython 3.11.7, Debian).
# Override the interpreter with PYTHON=/path/to/python3.
set -euo pipefail

CYCLONEDDS_VERSION=11.0.1
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
venv="$here/.venv"
python="${PYTHON:-python3}"

log() { echo "[cyclone setup] $*"; }

# Serialize concurrent runs (parallel test processes) on the script itself.
if command -v flock >/dev/null 2>&1; then
    exec 9<"${BASH_SOURCE[0]}"
    flock 9
fi

installed_version() {
    "$venv/bin/python" - <<'PY' 2>/dev/null
import importlib.metadata as m
import cyclonedds.domain  # loads the bundled C library
print(m.version("cyclonedds"))
PY
}

if [ -x "$venv/bin/python" ]; then
    have="$(installed_version || true)"
    if [ "$have" = "$CYCLONEDDS_VERSION" ]; then
        log "$venv is ready (cyclonedds $have); nothing to do"
        exit 0
    fi
    log "$venv has cyclonedds '${have:-<missing or broken>}', want $CYCLONEDDS_VERSION: recreating it"
    rm -rf "$venv"
fi

if ! command -v "$python" >/dev/null 2>&1; then
    log "error: '$python' not found; install CPython 3 or set PYTHON" >&2
    exit 1
fi
log "using $("$python" -c 'import sys; print(sys.executable, sys.version.split()[0])')"
log "creating venv $venv"
if ! "$python" -m venv "$venv"; then
    rm -rf "$venv"
    log "error: '$python -m venv' failed (on Debian's system python: apt-get install python3-venv)" >&2
    exit 1
fi
log "installing cyclonedds==$CYCLONEDDS_VERSION (binary wheel) from PyPI"
if ! "$venv/bin/python" -m pip install --disable-pip-version-check --no-input --quiet \
    --only-binary cyclonedds "cyclonedds==$CYCLONEDDS_VERSION"; then
    rm -rf "$venv"
    log "error: pip install cyclonedds==$CYCLONEDDS_VERSION failed" >&2
    exit 1
fi
have="$(installed_version || true)"
if [ "$have" != "$CYCLONEDDS_VERSION" ]; then
    rm -rf "$venv"
    log "error: after installation cyclonedds does not import (version '${have}')" >&2
    exit 1
fi
log "done: $venv/bin/python has cyclonedds $have"
