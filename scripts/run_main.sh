#!/usr/bin/env bash
# erodem — sets everything up and runs the main job: the Puget Sound storm experiment
# (experiments/puget_sound). Safe to run twice: the results are replaced.
# Usage: bash scripts/run_main.sh [extra erodem run options, e.g. --backend cpu]
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh build
export POCL_CACHE_DIR=${POCL_CACHE_DIR:-$PWD/build/pocl-cache}
mkdir -p out/puget_sound
./build/cli/erodem run experiments/puget_sound/config.toml --overwrite "$@"
echo "results: $PWD/out/puget_sound/puget_sound.h5 (+ .xmf for ParaView); see docs/experiments/puget_sound.md and docs/results.md"
