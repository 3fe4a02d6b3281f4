// Loads a glTF with three.js's GLTFLoader (npm package three), as a web viewer or a TD's script would,
// and checks that it gets every vertex attribute and every per-strand array hairgen wrote: the vertex
// attributes named, and each accessor of the primitive's extras.perStrand loaded through the loader's
// parser with one entry per strand, which each vertex's _strand indexes. Exits 1 on any difference.
// Usage: node three_gltf.mjs NODE_MODULES FILE ATTRIBUTES PER_STRAND (comma-separated lists)
import fs from 'fs';

const [modules, file, attributeList, perStrandList] = process.argv.slice(2);
// three.js fetches a .gltf's data: URI and reports progress with the browser's ProgressEvent.
globalThis.ProgressEvent ??= class extends Event {
  constructor(type, init = {}) {
    super(type);
    Object.assign(this, init);
  }
};
const { GLTFLoader } = await import(modules + '/three/examples/jsm/loaders/GLTFLoader.js');
const bytes = fs.readFileSync(file);
const data = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);
const fail = (message) => {
  console.error(`${file}: ${message}`);
  process.exit(1);
};

new GLTFLoader().parse(data, '', async (gltf) => {
  const lines = [];
  gltf.scene.traverse((o) => o.isLineSegments && lines.push(o));
  if (lines.length !== 1) fail(`expected one LineSegments, found ${lines.length}`);
  const geometry = lines[0].geometry;
  const strands = gltf.asset.extras.strands;
  for (const name of attributeList.split(',')) {
    const a = geometry.attributes[name];
    if (!a) fail(`three.js has no vertex attribute ${name} (it has ${Object.keys(geometry.attributes)})`);
    if (a.count !== geometry.attributes.position.count) fail(`${name} has ${a.count} entries`);
  }
  const strandOf = geometry.attributes._strand.array;
  for (let v = 0; v < strandOf.length; ++v) {
    const k = strandOf[v];
    if (!Number.isInteger(k) || k < 0 || k >= strands || (v > 0 && k !== strandOf[v - 1] && k !== strandOf[v - 1] + 1))
      fail(`vertex ${v}'s _strand ${k} is not the next strand of ${strands}`);
  }
  if (strandOf[strandOf.length - 1] !== strands - 1) fail('the last vertex is not on the last strand');
  const perStrand = geometry.userData.perStrand || {};
  for (const name of perStrandList ? perStrandList.split(',') : []) {
    if (!(name in perStrand)) fail(`the primitive's extras.perStrand has no ${name}`);
    const accessor = await gltf.parser.getDependency('accessor', perStrand[name]);
    if (accessor.count !== strands) fail(`${name} has ${accessor.count} entries for ${strands} strands`);
  }
  console.log(`${file}: three.js gets ${Object.keys(geometry.attributes).length} vertex attributes and ` +
              `${Object.keys(perStrand).length} per-strand arrays of ${strands} strands`);
}, (error) => fail(error));
