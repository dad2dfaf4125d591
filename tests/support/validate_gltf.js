// SPDX-License-Identifier: Apache-2.0
// Validates glTF/GLB files with the Khronos glTF-Validator (npm package gltf-validator) and prints
// one JSON line per file: {"file", "errors", "warnings", "messages": ["CODE at POINTER: message", ...]}.
// Exit status 3 when the validator is not installed (the caller reports the check as not run),
// 1 when a file cannot be read or validated, 0 otherwise (the counts say whether it passed).
// Run with NODE_PATH set to `npm root -g` so a global install is found.
'use strict';
const fs = require('fs');
let validator;
try {
  validator = require('gltf-validator');
} catch (e) {
  console.log(JSON.stringify({error: 'gltf-validator is not installed (npm install -g gltf-validator)'}));
  process.exit(3);
}
(async () => {
  let status = 0;
  for (const file of process.argv.slice(2)) {
    try {
      const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {maxIssues: 100});
      const messages = report.issues.messages.filter((m) => m.severity <= 1).map((m) => `${m.code} at ${m.pointer || '/'}: ${m.message}`);
      console.log(JSON.stringify({file, errors: report.issues.numErrors, warnings: report.issues.numWarnings, messages}));
    } catch (e) {
      console.log(JSON.stringify({file, error: String(e)}));
      status = 1;
    }
  }
  process.exit(status);
})();
