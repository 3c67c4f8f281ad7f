// Validates one glTF or GLB file with the Khronos glTF validator (npm package gltf-validator,
// installed here by scripts/install-gltf-validator.sh) and prints its report's summary as JSON:
// {"errors": n, "warnings": n, "infos": n, "hints": n, "messages": [{code, severity, message,
// pointer}]}. Exit 0 when the validator ran, 77 when the package is missing (the test skips),
// 2 on a bad call.
const fs = require("fs");
const path = require("path");

if (process.argv.length !== 3) {
  console.error("usage: node validate.js FILE.gltf|FILE.glb");
  process.exit(2);
}
let validator;
try {
  validator = require("gltf-validator");
} catch (e) {
  console.error("gltf-validator is not installed: run scripts/install-gltf-validator.sh");
  process.exit(77);
}
const file = process.argv[2];
const bytes = new Uint8Array(fs.readFileSync(file));
validator
  .validateBytes(bytes, {
    uri: path.basename(file),
    maxIssues: 100,
    externalResourceFunction: (uri) =>
      Promise.reject(new Error("the export has no external resources: " + uri)),
  })
  .then((report) => {
    const issues = report.issues;
    console.log(
      JSON.stringify({
        errors: issues.numErrors,
        warnings: issues.numWarnings,
        infos: issues.numInfos,
        hints: issues.numHints,
        messages: issues.messages.map((m) => ({
          code: m.code,
          severity: m.severity,
          message: m.message,
          pointer: m.pointer,
        })),
      }),
    );
  })
  .catch((error) => {
    console.error("the validator could not read " + file + ": " + error);
    process.exit(1);
  });
