#!/usr/bin/env bash
# Sets up (packages, build) and runs the whole test suite: unit tests, the sanitizer mutation loop, the
# glTF validator and the command-line checks. Usage: scripts/test.sh [ctest arguments]
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
ctest --test-dir build --output-on-failure -j "$(nproc)" "$@"
