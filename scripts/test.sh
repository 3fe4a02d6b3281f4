#!/usr/bin/env bash
# Sets up (packages, build) and runs the whole test suite: unit tests, the sanitizer mutation loop, the
# glTF validator, the command-line checks and the golden images (ctest), then every reader's libFuzzer
# target for 60 s (scripts/fuzz.sh). Usage: scripts/test.sh [ctest arguments]
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
ctest --test-dir build --output-on-failure -j "$(nproc)" "$@"
bash scripts/fuzz.sh
