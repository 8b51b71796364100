// The Khronos glTF validator (npm gltf-validator) on one .glb/.gltf file:
// prints the issue counts and every error/warning, exits 1 when the file
// has errors, 2 when it cannot be validated. Usage:
//   node gltf_validate.mjs NODE_MODULES_DIR FILE
// (the validator is installed by scripts/lib.sh ms_gltf_validator).
import { createRequire } from 'module';
import fs from 'fs';
import path from 'path';

const [modules, file] = process.argv.slice(2);
if (!modules || !file) {
  console.error('usage: node gltf_validate.mjs NODE_MODULES_DIR FILE');
  process.exit(2);
}
const require = createRequire(path.join(path.resolve(modules), 'x.js'));
const validator = require('gltf-validator');
const folder = path.dirname(path.resolve(file));
try {
  const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
    uri: path.basename(file),
    maxIssues: 0,
    externalResourceFunction: (uri) =>
      new Promise((resolve, reject) => {
        fs.readFile(path.join(folder, decodeURIComponent(uri)), (err, data) =>
          err ? reject(err.toString()) : resolve(new Uint8Array(data)));
      }),
  });
  const issues = report.issues;
  console.log(`${file}: ${issues.numErrors} errors, ${issues.numWarnings} warnings, ` +
              `${issues.numInfos} infos, ${issues.numHints} hints`);
  for (const m of issues.messages) {
    if (m.severity <= 1) {
      console.log(`  ${m.severity === 0 ? 'error' : 'warning'} ${m.code}: ${m.message} (${m.pointer || ''})`);
    }
  }
  process.exit(issues.numErrors > 0 ? 1 : 0);
} catch (e) {
  console.error(`${file}: cannot validate: ${e}`);
  process.exit(2);
}
