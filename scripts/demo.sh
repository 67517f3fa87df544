#!/usr/bin/env bash
# The README's first command: set up, build, and run saccade's main job.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh --program build
exec build/bin/saccade demo "$@"
