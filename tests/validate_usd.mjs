// Reads a .usda hairgen wrote with TinyUSDZ (npm package tinyusdz, a WebAssembly build of an
// independent USD reader) and checks it holds what hairgen's own description of the source says.
// TinyUSDZ's typed stage must build (its BasisCurves reconstruction checks each attribute's type), and
// the layer TinyUSDZ parsed, printed back by TinyUSDZ, must have the same curve count, vertex count,
// points (as float32, every one) and widths. TinyUSDZ's render scene does not convert curves, so the
// printed layer is the only view of the values it read.
// Usage: node validate_usd.mjs TINYUSDZ_DIR FILE.usda DESCRIPTION.json (hairgen info --json of the source)
import fs from 'fs';
import path from 'path';

import { readLayer } from './tinyusdz_layer.mjs';

const [dir, file, described] = process.argv.slice(2);
const expected = JSON.parse(fs.readFileSync(described, 'utf8'));
let failed = false;
const fail = (message) => { console.log(`FAIL ${file}: ${message}`); failed = true; };
const text = await readLayer(dir, file, fail);

// The body of `KEY = [...]` and the interpolation that follows it.
const arrayOf = (text, key) => {
  const at = text.indexOf(`${key} = [`);
  if (at < 0) return null;
  const start = at + key.length + 4, end = text.indexOf(']', start);
  const rest = text.slice(end, end + 120);
  const interpolation = /^\]\s*\(\s*interpolation = "(\w+)"/.exec(rest);
  return { body: text.slice(start, end), interpolation: interpolation ? interpolation[1] : null };
};
const numbers = (body) => (body.match(/[-+0-9.eE]+/g) || []).map(Number);

if ((text.match(/def BasisCurves "hair"/g) || []).length !== 1) fail('no single BasisCurves prim /hair');
if (!/uniform token type = "linear"/.test(text)) fail('the curves are not linear');
const counts = arrayOf(text, 'int[] curveVertexCounts');
const points = arrayOf(text, 'point3f[] points');
const widths = arrayOf(text, 'float[] widths');
if (!counts || !points || !widths) {
  fail('curveVertexCounts, points or widths is missing');
  process.exit(1);
}
const perCurve = numbers(counts.body);
const vertices = perCurve.reduce((a, b) => a + b, 0);
if (perCurve.length !== expected.strands) fail(`${perCurve.length} curves, expected ${expected.strands}`);
if (vertices !== expected.points) fail(`curveVertexCounts sum to ${vertices}, expected ${expected.points}`);

// Every point as TinyUSDZ read it against the text hairgen wrote, as float32.
const read = numbers(points.body), written = numbers(arrayOf(fs.readFileSync(file, 'utf8'), 'point3f[] points').body);
if (read.length !== 3 * expected.points) fail(`${read.length / 3} points, expected ${expected.points}`);
let differing = 0;
for (let i = 0; i < Math.min(read.length, written.length); ++i) differing += Math.fround(read[i]) !== Math.fround(written[i]);
if (differing) fail(`${differing} point coordinates differ from what hairgen wrote`);

const w = numbers(widths.body);
if (expected.attributes.includes('thickness')) {
  if (w.length !== expected.points || widths.interpolation !== 'vertex') fail(`widths: ${w.length} ${widths.interpolation}, expected one per vertex`);
} else {
  // TinyUSDZ prints a float with six decimals: half a millionth is its rounding.
  const want = expected.defaults.thickness;
  if (w.length !== 1 || widths.interpolation !== 'constant' || Math.abs(w[0] - want) > 5.1e-7 + 1e-6 * want)
    fail(`widths: ${w.join(' ')} (${widths.interpolation}), expected the constant diameter ${want}`);
}
if (expected.units === 'metres' && !/metersPerUnit = 1\b/.test(text)) fail('metersPerUnit is not 1');
if (expected.upAxis === '+y' && !/upAxis = "Y"/.test(text)) fail('upAxis is not "Y"');
console.log(`${file}: TinyUSDZ reads ${perCurve.length} curves, ${vertices} vertices, ${w.length} width(s) ` +
            `(${widths.interpolation})${failed ? '' : ': as hairgen wrote them'}`);
process.exit(failed ? 1 : 0);
