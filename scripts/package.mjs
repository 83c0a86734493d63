// Makes pkg/ (wasm-bindgen's output) an npm package: writes pkg/package.json (name, version,
// description and licence from Cargo.toml, so they are written once), copies the worker entry
// (js/) and the package's README (docs/package.md), and types the raw wasm exports of
// geofit.d.ts's `InitOutput` as `unknown` instead of wasm-bindgen's `any`, so no `any` is left.
// Run by scripts/build-wasm.sh after wasm-bindgen.
import { copyFileSync, readFileSync, writeFileSync } from 'node:fs';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';

const ROOT = join(dirname(fileURLToPath(import.meta.url)), '..');
const PKG = join(ROOT, 'pkg');

/** The string value of `key` in Cargo.toml's [package] table. */
function cargoField(key) {
  const table = readFileSync(join(ROOT, 'Cargo.toml'), 'utf8').split(/^\[/m).find((t) => t.startsWith('package]'));
  const value = table?.match(new RegExp(`^${key}\\s*=\\s*"([^"]*)"`, 'm'))?.[1];
  if (value === undefined) throw new Error(`Cargo.toml: no ${key} in [package]`);
  return value;
}

const WORKER_FILES = ['fit-in-worker.js', 'fit-in-worker.d.ts', 'worker.js'];

const manifest = {
  name: 'geofit',
  version: cargoField('version'),
  description: cargoField('description'),
  license: cargoField('license'),
  type: 'module',
  exports: {
    '.': { types: './geofit.d.ts', default: './geofit.js' },
    './worker': { types: './fit-in-worker.d.ts', default: './fit-in-worker.js' },
    './package.json': './package.json',
  },
  files: ['geofit.js', 'geofit.d.ts', 'geofit_bg.wasm', 'geofit_bg.wasm.d.ts', ...WORKER_FILES],
  sideEffects: ['./worker.js'],
  keywords: ['surface fitting', 'subdivision', 'b-spline', 'point cloud', '3d scan', 'webassembly'],
};

writeFileSync(join(PKG, 'package.json'), `${JSON.stringify(manifest, null, 2)}\n`);
for (const file of WORKER_FILES) copyFileSync(join(ROOT, 'js', file), join(PKG, file));
copyFileSync(join(ROOT, 'docs', 'package.md'), join(PKG, 'README.md'));

const dts = join(PKG, 'geofit.d.ts');
const typed = readFileSync(dts, 'utf8').replace(/^export interface InitOutput \{[^]*?^\}/m, (block) =>
  block.replace(/\bany\b/g, 'unknown'),
);
writeFileSync(dts, typed);
console.log(`pkg/package.json: geofit ${manifest.version}`);
