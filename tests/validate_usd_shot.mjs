// Reads an animated .usda hairgen wrote (convert --frames, run on a shot) with TinyUSDZ (npm package
// tinyusdz, a WebAssembly build of an independent USD reader) and checks it against the caches: the
// typed stage builds; the layer TinyUSDZ parsed, printed back by TinyUSDZ, has the time codes and rate
// asked for, and the prim PRIM's points time-sampled at every frame, each sample equal as float32 to
// that frame's cache (given as an ASCII PLY, which hairgen writes in shortest exact floats).
// Usage: node validate_usd_shot.mjs TINYUSDZ_DIR FILE.usda PRIM FIRST LAST FPS FRAME.####.ply
import fs from 'fs';
import path from 'path';

import { readLayer } from './tinyusdz_layer.mjs';

const [dir, file, prim, firstText, lastText, fps, plyPattern] = process.argv.slice(2);
const first = Number(firstText), last = Number(lastText);
let failed = false;
const fail = (message) => { console.log(`FAIL ${file}: ${message}`); failed = true; };
const text = await readLayer(dir, file, fail);

for (const [key, want] of [['startTimeCode', first], ['endTimeCode', last], ['timeCodesPerSecond', Number(fps)]]) {
  const m = new RegExp(`\\b${key} = ([-0-9.e]+)`).exec(text);
  if (!m || Number(m[1]) !== want) fail(`${key} is ${m ? m[1] : 'missing'}, expected ${want}`);
}

// The prim's body, and in it the points' time samples.
const at = text.indexOf(`def BasisCurves "${prim}"`);
if (at < 0) { fail(`no BasisCurves prim ${prim}`); process.exit(1); }
const next = text.indexOf('def BasisCurves', at + 10);
const body = text.slice(at, next < 0 ? text.length : next);
const samplesAt = body.indexOf('point3f[] points.timeSamples = {');
if (samplesAt < 0) { fail(`${prim}'s points are not time-sampled`); process.exit(1); }
const samplesEnd = body.indexOf('\n        }', samplesAt);
const samples = new Map();
for (const m of body.slice(samplesAt, samplesEnd).matchAll(/\n\s*(-?[0-9.]+): \[([^\]]*)\]/g))
  samples.set(Number(m[1]), (m[2].match(/[-+0-9.eE]+/g) || []).map(Number));
const times = [...samples.keys()];
if (times.length !== last - first + 1 || times[0] !== first || times[times.length - 1] !== last)
  fail(`time samples at ${times.join(' ')}, expected ${first} to ${last}`);

// A frame's points from its ASCII PLY: the first three numbers of each vertex line.
const plyPoints = (name) => {
  const lines = fs.readFileSync(name, 'utf8').split('\n');
  const vertices = Number(/element vertex (\d+)/.exec(lines.join('\n'))[1]);
  const start = lines.indexOf('end_header') + 1;
  return lines.slice(start, start + vertices).flatMap((l) => l.split(' ').slice(0, 3).map(Number));
};
let compared = 0;
for (let f = first; f <= last; ++f) {
  const want = plyPoints(plyPattern.replace(/#+/, (h) => String(f).padStart(h.length, '0')));
  const got = samples.get(f) || [];
  if (got.length !== want.length) { fail(`frame ${f}: ${got.length / 3} points, the cache has ${want.length / 3}`); continue; }
  let differing = 0;
  for (let i = 0; i < want.length; ++i) differing += Math.fround(got[i]) !== Math.fround(want[i]);
  if (differing) fail(`frame ${f}: ${differing} coordinates differ from the cache`);
  compared += want.length / 3;
}
console.log(`${file}: TinyUSDZ reads ${prim} at ${times.length} time codes ${first}-${last}, ${compared} points ` +
            `compared${failed ? '' : ', equal to the caches'}`);
process.exit(failed ? 1 : 0);
