#!/usr/bin/env bash
# Set up (if needed) and run the main job on the shipped defaults.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/bootstrap.sh"
cd "$ROOT"
exec trms demo --out "${1:-out}"
