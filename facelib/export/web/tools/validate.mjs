// Validate glTF files with the Khronos glTF-Validator (npm gltf-validator).
// Usage: node tools/validate.mjs FILE.glb...  Prints one JSON report per file on stdout;
// exits 1 when any file has errors.
import { readFile } from "node:fs/promises";
import validator from "gltf-validator";

let failed = false;
for (const path of process.argv.slice(2)) {
  const bytes = new Uint8Array(await readFile(path));
  const report = await validator.validateBytes(bytes, { maxIssues: 100 });
  const { numErrors, numWarnings, numInfos, numHints, messages } = report.issues;
  console.log(JSON.stringify({ path, numErrors, numWarnings, numInfos, numHints, messages }));
  failed ||= numErrors > 0;
}
process.exit(failed ? 1 : 0);
