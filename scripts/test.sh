#!/usr/bin/env bash
# Set up (if needed) and run the test suite.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/bootstrap.sh"
cd "$ROOT"
exec python -m pytest -q "$@"
