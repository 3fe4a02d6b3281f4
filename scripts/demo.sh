#!/usr/bin/env bash
# Sets up and runs hairgen on the bundled default coupe (configs/default), writing into out/default:
# the guides and the interpolated coupe as .hair, and a GLB of the guides for any glTF viewer. The
# render stage (an EXR and a PNG preview) joins when it lands.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
out=out/default
./build/hairgen run -o "$out" --stats "$out.json"
./build/hairgen convert "$out/guides.hair" "$out/guides.glb"
./build/hairgen info "$out/coupe.hair"
echo "demo: wrote $out/guides.hair, $out/coupe.hair, $out/guides.glb (open it in any glTF viewer) and $out.json" >&2
