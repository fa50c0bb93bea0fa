#!/usr/bin/env bash
# Create or refresh the project's virtual environment and the system library it needs.
# Sourced by scripts/main.sh and scripts/test.sh; safe to run again (it only installs what is missing).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
VENV="${TRMS_VENV:-$ROOT/.venv}"
PY="${PYTHON:-python3}"

# OSMesa for offscreen rendering (Debian package libosmesa6), installed when root and missing.
if ! ldconfig -p 2>/dev/null | grep -q 'libOSMesa\.so'; then
  if [ "$(id -u)" = "0" ] && command -v apt-get >/dev/null 2>&1; then
    echo "[bootstrap] installing libosmesa6" >&2
    apt-get update -qq >/dev/null && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq libosmesa6 >/dev/null
  else
    echo "[bootstrap] warning: libOSMesa not found and not root; offscreen rendering will fail" >&2
  fi
fi

if [ ! -x "$VENV/bin/python" ]; then
  echo "[bootstrap] creating virtual environment in $VENV" >&2
  "$PY" -m venv "$VENV"
fi

# Reinstall only when the dependency pins change.
STAMP="$VENV/.trms-installed"
WANT="$(sha256sum "$ROOT/pyproject.toml" | cut -d' ' -f1)"
if [ ! -f "$STAMP" ] || [ "$(cat "$STAMP")" != "$WANT" ] || ! "$VENV/bin/python" -c "import trms" 2>/dev/null; then
  echo "[bootstrap] installing trms and its pinned dependencies" >&2
  "$VENV/bin/python" -m pip install -q --disable-pip-version-check -e "$ROOT[test,sysid,video,mjx,docs,lint,control]" 2>&1 | grep -v "is ignored: it is neither" >&2 || true
  "$VENV/bin/python" -c "import trms, mujoco, mujoco.sysid, imageio_ffmpeg, dm_control, control, dask.distributed, jax, mujoco.mjx, gymnasium, mkdocs, osqp, slycot" >/dev/null
  echo "$WANT" > "$STAMP"
fi

export MUJOCO_GL="${MUJOCO_GL:-osmesa}"
export PYOPENGL_PLATFORM="${PYOPENGL_PLATFORM:-osmesa}"
export PATH="$VENV/bin:$PATH"
