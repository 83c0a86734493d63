// Shared set-up of the browser tests: Debian's chromium (never a downloaded browser), its flags
// per graphics backend, the shared scans, the test-artifacts/ folder and canvas pixel counting.
import { existsSync, mkdirSync, readFileSync, writeFileSync } from 'node:fs';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

export const ROOT = join(dirname(fileURLToPath(import.meta.url)), '..', '..');
export const ARTIFACTS = join(ROOT, 'test-artifacts');
export const CHROMIUM = '/usr/bin/chromium';
/**
 * The longest main-thread task a fit may cause on the page (ms). The longtask API reports from
 * 50 ms; on the 2-core CI machine the worker's fit, SwiftShader's rendering and the main thread
 * share the cores, and a task's wall time includes the time it waits for one: a single 60 ms
 * task was seen once (deviation test, WebGL2) where the page's own stages take 16 ms at most.
 * 100 ms is the response budget a user does not notice.
 */
export const LONG_TASK_MS = 100;
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

/**
 * Serves the npm package three (node_modules/three) to `page` under /three/, with its bare
 * `from 'three'` imports pointed at the module build, so a test can import three.js loaders
 * without a bundler or an import map.
 */
export async function routeThree(page) {
  const base = join(ROOT, 'node_modules', 'three');
  await page.route(/\/three\//, async (route) => {
    const rel = new URL(route.request().url()).pathname.replace(/^.*?\/three\//, '');
    const file = join(base, rel);
    if (!file.startsWith(base) || !existsSync(file)) return route.fulfill({ status: 404, body: '' });
    const body = readFileSync(file, 'utf8').replaceAll("from 'three'", "from '/three/build/three.module.js'");
    return route.fulfill({ status: 200, contentType: 'text/javascript', body });
  });
}

/**
 * Parses `bytes` (a GLB) with three.js's GLTFLoader in `page` and summarises the scene: meshes,
 * vertices, triangles, whether they carry vertex colours and the custom _DEVIATION attribute, and
 * the scene's userData (the GLB's extras).
 */
export async function loadGlbWithThree(page, bytes) {
  await routeThree(page);
  return page.evaluate(async (b64) => {
    const { GLTFLoader } = await import('/three/examples/jsm/loaders/GLTFLoader.js');
    const buffer = Uint8Array.from(atob(b64), (c) => c.charCodeAt(0)).buffer;
    const gltf = await new GLTFLoader().parseAsync(buffer, '');
    const out = { meshes: 0, vertices: 0, triangles: 0, colors: true, deviation: true, userData: gltf.scene.userData };
    gltf.scene.traverse((o) => {
      if (!o.isMesh) return;
      const g = o.geometry;
      out.meshes += 1;
      out.vertices += g.attributes.position.count;
      out.triangles += (g.index ? g.index.count : g.attributes.position.count) / 3;
      out.colors &&= Boolean(g.attributes.color);
      out.deviation &&= Boolean(g.attributes._deviation);
    });
    return out;
  }, Buffer.from(bytes).toString('base64'));
}
