#!/usr/bin/env bash
# Set up (if needed) and run the main job on the shipped defaults: every experiment of the thesis on
# the linear model and on the twin, written as a report folder (default ./report).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/bootstrap.sh"
cd "$ROOT"
exec trms reproduce --out "${1:-report}"
