#!/usr/bin/env bash
# Rewrites docs/config-keys.md from the key declarations (`hairgen check --keys`). The build compares
# the committed file with what the declarations give and fails when it is stale; run this, look at the
# diff and commit it with the change to the keys. Usage: scripts/config-keys.sh [HAIRGEN]
set -euo pipefail
cd "$(dirname "$0")/.."
hairgen=${1:-build/hairgen}
"$hairgen" check --keys > docs/config-keys.md.tmp
mv docs/config-keys.md.tmp docs/config-keys.md
echo "config-keys: wrote docs/config-keys.md" >&2
