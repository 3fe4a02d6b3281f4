// Runs the Khronos glTF validator (npm package gltf-validator) on each file given; exits 1 if any has
// an error or a warning. Usage: node validate_gltf.js VALIDATOR_DIR FILE...
const fs = require('fs');
const path = require('path');
const validator = require(path.resolve(process.argv[2]));
(async () => {
  let failed = false;
  for (const file of process.argv.slice(3)) {
    const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
      uri: path.basename(file),
      externalResourceFunction: (uri) => Promise.resolve(new Uint8Array(fs.readFileSync(path.join(path.dirname(file), uri)))),
    });
    const i = report.issues;
    console.log(`${file}: ${i.numErrors} errors, ${i.numWarnings} warnings, ${i.numInfos} infos`);
    for (const m of i.messages) console.log(`  ${m.severity === 0 ? 'error' : 'note'} ${m.code} ${m.pointer || ''}: ${m.message}`);
    if (i.numErrors > 0 || i.numWarnings > 0) failed = true;
  }
  process.exit(failed ? 1 : 0);
})().catch((e) => { console.error(e); process.exit(1); });
