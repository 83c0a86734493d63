// Shared set-up of the browser tests: Debian's chromium (never a downloaded browser), its flags
// per graphics backend, the shared scans, the test-artifacts/ folder and canvas pixel counting.
import { existsSync, mkdirSync, writeFileSync } from 'node:fs';
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

/** The shared scans: $GEOFIT_DATA, else <repo>/../shared/data, else /work/shared/data. */
export function dataDir() {
  const candidates = [process.env.GEOFIT_DATA, join(ROOT, '..', 'shared', 'data'), '/work/shared/data'];
  return candidates.find((d) => d && existsSync(d));
}

/**
 * Screenshots the element `selector` of `page` (saved as test-artifacts/`file`) and counts its
 * pixels per class: `classes` maps a class name to a predicate of (r, g, b, corner), where
 * `corner` is the [r, g, b] of the top-left pixel (the background). Also returns the pixel total. The PNG is decoded by the page itself, so no image library is needed.
 */
export async function countPixels(page, selector, file, classes) {
  const png = await page.locator(selector).screenshot();
  saveArtifact(file, png);
  const rgba = Buffer.from(
    await page.evaluate(async (b64) => {
      const img = new Image();
      img.src = `data:image/png;base64,${b64}`;
      await img.decode();
      const ctx = new OffscreenCanvas(img.width, img.height).getContext('2d');
      ctx.drawImage(img, 0, 0);
      const { data } = ctx.getImageData(0, 0, img.width, img.height);
      let bin = '';
      for (let i = 0; i < data.length; i += 0x8000) bin += String.fromCharCode(...data.subarray(i, i + 0x8000));
      return btoa(bin);
    }, png.toString('base64')),
    'base64',
  );
  const counts = { total: rgba.length / 4 };
  const corner = [rgba[0], rgba[1], rgba[2]];
  const entries = Object.entries(classes);
  for (const [name] of entries) counts[name] = 0;
  for (let i = 0; i < rgba.length; i += 4) {
    const [r, g, b] = [rgba[i], rgba[i + 1], rgba[i + 2]];
    for (const [name, test] of entries) if (test(r, g, b, corner)) counts[name] += 1;
  }
  return counts;
}
