// Validates a glTF file with the Khronos glTF validator (npm `gltf-validator`, installed by
// scripts/setup.sh into .tools/node_modules) and prints its report as JSON on stdout.
// Usage: node scripts/gltf-validate.cjs FILE.glb
// Exit status: 0 (report printed; read its issues.numErrors), 2 (the validator is missing or failed).
const fs = require('fs');
const path = require('path');
let validator;
try {
    validator = require(path.join(__dirname, '..', '.tools', 'node_modules', 'gltf-validator'));
} catch (e) {
    console.error('the Khronos glTF validator is not installed in .tools/node_modules; run scripts/setup.sh');
    process.exit(2);
}
const file = process.argv[2];
validator
    .validateBytes(new Uint8Array(fs.readFileSync(file)), { maxIssues: 1000 })
    .then((report) => console.log(JSON.stringify(report)))
    .catch((e) => {
        console.error(`${file}: ${e}`);
        process.exit(2);
    });
