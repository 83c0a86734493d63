// Validates every .glb in a directory with the Khronos glTF-Validator (npm gltf-validator) and
// fails on any error. The GLBs are the ones `cargo test --test io_glb` writes.
//
//   cargo test --release --test io_glb        # writes target/glb-samples/*.glb
//   node scripts/validate-glb.mjs [DIR]       # DIR defaults to $GEOFIT_GLB_DIR or target/glb-samples
//
// Prints each file's error/warning/info counts and its messages, then "N passed, N failed";
// exits 1 when a file has an error or when there is no file to check.
import { readdir, readFile } from 'node:fs/promises';
import { join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import * as validator from 'gltf-validator';

const root = resolve(fileURLToPath(import.meta.url), '../..');
const dir = resolve(process.argv[2] ?? process.env.GEOFIT_GLB_DIR ?? join(root, 'target/glb-samples'));

let files;
try {
    files = (await readdir(dir)).filter((f) => f.endsWith('.glb')).sort();
} catch (e) {
    console.error(`validate-glb: cannot read ${dir}: ${e.message}`);
    process.exit(1);
}
if (files.length === 0) {
    console.error(`validate-glb: no .glb files in ${dir} (run: cargo test --release --test io_glb)`);
    process.exit(1);
}

const severity = ['error', 'warning', 'info', 'hint'];
let passed = 0;
let failed = 0;
for (const f of files) {
    const bytes = new Uint8Array(await readFile(join(dir, f)));
    const report = await validator.validateBytes(bytes, { uri: f, maxIssues: 100 });
    const { numErrors, numWarnings, numInfos } = report.issues;
    console.log(`${f}: ${numErrors} errors, ${numWarnings} warnings, ${numInfos} infos (validator ${report.validatorVersion})`);
    for (const m of report.issues.messages) {
        console.log(`  ${severity[m.severity] ?? m.severity} ${m.code} ${m.pointer ?? ''}: ${m.message}`);
    }
    if (numErrors > 0) {
        failed += 1;
    } else {
        passed += 1;
    }
}
console.log(`${passed} passed, ${failed} failed`);
process.exit(failed > 0 ? 1 : 0);
