// Runs the Khronos glTF validator (npm package `gltf-validator`) on one .glb/.gltf and prints
// its issue counts as one JSON line; exit 1 when it reports an error. Used by the workspace's
// tests through test_data::gltf_validator (node and the package installed by .ci/run).
const fs = require('fs');
const path = require('path');
const validator = require('gltf-validator');
const file = process.argv[2];
const bytes = new Uint8Array(fs.readFileSync(file));
validator
  .validateBytes(bytes, {
    uri: path.basename(file),
    maxIssues: 0,
    externalResourceFunction: (uri) =>
      new Promise((resolve, reject) => {
        fs.readFile(path.join(path.dirname(file), decodeURIComponent(uri)), (err, data) =>
          err ? reject(err.toString()) : resolve(new Uint8Array(data)));
      }),
  })
  .then((report) => {
    const i = report.issues;
    const messages = i.messages.filter((m) => m.severity <= 1).slice(0, 20)
      .map((m) => `${m.code} ${m.pointer || ''}: ${m.message}`);
    console.log(JSON.stringify({ errors: i.numErrors, warnings: i.numWarnings, infos: i.numInfos, hints: i.numHints, messages }));
    process.exit(i.numErrors > 0 ? 1 : 0);
  })
  .catch((e) => { console.error(String(e)); process.exit(2); });
