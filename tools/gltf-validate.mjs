// Validate glTF / GLB files with the Khronos glTF validator (npm: gltf-validator).
// usage: node tools/gltf-validate.mjs FILE...
// Prints one JSON report per file ({"file", "numErrors", "numWarnings", "messages"})
// on one line each; exits 1 when any file has errors, 2 on usage/IO problems.
import { readFile } from "node:fs/promises";
import path from "node:path";
import validator from "gltf-validator";

const files = process.argv.slice(2);
if (files.length === 0) {
  console.error("usage: node gltf-validate.mjs FILE...");
  process.exit(2);
}

let failed = false;
for (const file of files) {
  const bytes = new Uint8Array(await readFile(file));
  const folder = path.dirname(file);
  const report = await validator.validateBytes(bytes, {
    uri: path.basename(file),
    maxIssues: 200,
    // external resources (a .gltf's textures) are read beside the file
    externalResourceFunction: (uri) =>
      readFile(path.join(folder, decodeURIComponent(uri))).then((b) => new Uint8Array(b)),
  });
  const issues = report.issues;
  const messages = issues.messages.map((m) => ({
    code: m.code, severity: m.severity, message: m.message, pointer: m.pointer,
  }));
  console.log(JSON.stringify({
    file, numErrors: issues.numErrors, numWarnings: issues.numWarnings,
    numInfos: issues.numInfos, messages,
    validatorVersion: report.validatorVersion,
  }));
  if (issues.numErrors > 0) failed = true;
}
process.exit(failed ? 1 : 0);
