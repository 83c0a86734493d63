// Shared set-up of the browser tests: Debian's chromium (never a downloaded browser), its flags
// per graphics backend, and the test-artifacts/ folder.
import { mkdirSync, writeFileSync } from 'node:fs';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

export const ROOT = join(dirname(fileURLToPath(import.meta.url)), '..', '..');
export const ARTIFACTS = join(ROOT, 'test-artifacts');
export const CHROMIUM = '/usr/bin/chromium';
export const COMMON_ARGS = [
  '--no-sandbox',
  '--no-first-run',
  '--disable-background-networking',
  '--disable-component-update',
  '--disable-sync',
  '--disable-quic',
  '--disable-default-apps',
];
/** Flag sets and the backend each one must give the page (both rendered by SwiftShader). */
export const BACKENDS = [
  { name: 'WebGL2', args: ['--enable-unsafe-swiftshader', '--use-angle=swiftshader'] },
  {
    name: 'WebGPU',
    args: [
      '--enable-unsafe-webgpu',
      '--enable-unsafe-swiftshader',
      '--enable-features=Vulkan',
      '--use-vulkan=swiftshader',
      '--use-angle=swiftshader',
    ],
  },
];

/** Launches headless chromium with the flags of `backend`. */
export function launch(backend) {
  return chromium.launch({
    executablePath: CHROMIUM,
    headless: true,
    args: [...COMMON_ARGS, ...backend.args],
  });
}

/** Saves `bytes` as test-artifacts/`file`. */
export function saveArtifact(file, bytes) {
  mkdirSync(ARTIFACTS, { recursive: true });
  writeFileSync(join(ARTIFACTS, file), bytes);
}
