// Validates one glTF/GLB file with the Khronos glTF-Validator and prints its report as JSON.
//
// Usage: node scripts/gltf_validate.mjs <gltf-validator package dir> <file.glb|file.gltf>
// The package dir is where `npm install gltf-validator` put it (…/node_modules/gltf-validator);
// CI exports it as PLEAT_GLTF_VALIDATOR. Exit status: 0 when the report was printed (whatever
// it says), 2 on a usage or I/O error.
import { readFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { dirname, join, resolve } from 'node:path';

const [pkg, file] = process.argv.slice(2);
if (!pkg || !file) {
  console.error('usage: node gltf_validate.mjs <gltf-validator dir> <file>');
  process.exit(2);
}
const require = createRequire(import.meta.url);
const validator = require(resolve(pkg));
let data;
try {
  data = new Uint8Array(readFileSync(file));
} catch (e) {
  console.error(`cannot read ${file}: ${e.message}`);
  process.exit(2);
}
const base = dirname(resolve(file));
const report = await validator.validateBytes(data, {
  uri: file,
  maxIssues: 1000,
  externalResourceFunction: (uri) =>
    new Promise((ok, fail) => {
      try {
        ok(new Uint8Array(readFileSync(join(base, decodeURIComponent(uri)))));
      } catch (e) {
        fail(e.message);
      }
    }),
});
console.log(JSON.stringify(report));
