// TinyUSDZ (npm package tinyusdz, a WebAssembly build of an independent USD reader) on a .usda hairgen
// wrote, for tests/validate_usd.mjs and tests/validate_usd_shot.mjs: the typed stage must build (its
// BasisCurves reconstruction checks each attribute's type), and the layer TinyUSDZ parsed is returned as
// TinyUSDZ prints it back, the only view of the values it read (its render scene does not convert
// curves). `fail(message)` is called for a stage that does not build; a layer that cannot be read ends
// the process (exit 1).
import fs from 'fs';
import path from 'path';

// The package is built for browsers; it runs in Node as it would in an Electron renderer.
globalThis.window = globalThis;
process.type = 'renderer';

export async function readLayer(dir, file, fail) {
  const { default: init } = await import(path.resolve(dir, 'tinyusdz.js'));
  const usd = await init({ wasmBinary: fs.readFileSync(path.resolve(dir, 'tinyusdz.wasm')) });
  const bytes = new Uint8Array(fs.readFileSync(file));
  const stage = new usd.TinyUSDZLoaderNative();
  if (!stage.loadFromBinary(bytes, path.basename(file))) fail(`TinyUSDZ cannot build the stage: ${stage.error()}`);
  stage.delete();
  const layer = new usd.TinyUSDZLoaderNative();
  if (!layer.loadAsLayerFromBinary(bytes, path.basename(file))) {
    fail(`TinyUSDZ cannot read the layer: ${layer.error()}`);
    process.exit(1);
  }
  return layer.layerToString();
}
