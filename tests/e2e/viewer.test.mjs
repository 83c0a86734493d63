// End-to-end tests of the demo page in Debian's headless chromium (never a downloaded browser),
// once with WebGL2 and once with WebGPU, both rendered by SwiftShader on the CPU. Screenshots go to
// test-artifacts/.
import { after, before, describe, test } from 'node:test';
import assert from 'node:assert/strict';
import { existsSync, mkdirSync, writeFileSync } from 'node:fs';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';
import { startServer } from '../../scripts/serve.mjs';

const ROOT = join(dirname(fileURLToPath(import.meta.url)), '..', '..');
const ARTIFACTS = join(ROOT, 'test-artifacts');
const CHROMIUM = '/usr/bin/chromium';
const COMMON_ARGS = [
  '--no-sandbox',
  '--no-first-run',
  '--disable-background-networking',
  '--disable-component-update',
  '--disable-sync',
  '--disable-quic',
  '--disable-default-apps',
];
// Flag sets and the backend each one must give the page.
const BACKENDS = [
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
const TIMEOUT_MS = 60_000;

/** The shared scans: $GEOFIT_DATA, else <repo>/../shared/data, else /work/shared/data. */
function dataDir() {
  const candidates = [process.env.GEOFIT_DATA, join(ROOT, '..', 'shared', 'data'), '/work/shared/data'];
  return candidates.find((d) => d && existsSync(d));
}

/** Waits until the page has drawn a frame after `previous` frames. */
async function nextFrame(page, previous) {
  await page.waitForFunction(
    (n) => Number(document.body.dataset.frames ?? 0) > n,
    previous,
    { timeout: TIMEOUT_MS },
  );
}

const framesDrawn = (page) => page.evaluate(() => Number(document.body.dataset.frames ?? 0));

/**
 * Screenshots the canvas (saved under test-artifacts/) and classifies its pixels in the page:
 * background, the blue and amber ends of the height colours, and the clay of the lit surface.
 */
async function canvasPixels(page, file) {
  const png = await page.locator('#view').screenshot();
  mkdirSync(ARTIFACTS, { recursive: true });
  writeFileSync(join(ARTIFACTS, file), png);
  return page.evaluate(async (b64) => {
    const img = new Image();
    img.src = `data:image/png;base64,${b64}`;
    await img.decode();
    const c = new OffscreenCanvas(img.width, img.height);
    const ctx = c.getContext('2d');
    ctx.drawImage(img, 0, 0);
    const { data } = ctx.getImageData(0, 0, img.width, img.height);
    const [br, bg, bb] = [data[0], data[1], data[2]]; // a corner is background
    const counts = { total: img.width * img.height, drawn: 0, blue: 0, amber: 0, clay: 0 };
    for (let i = 0; i < data.length; i += 4) {
      const [r, g, b] = [data[i], data[i + 1], data[i + 2]];
      if (Math.abs(r - br) + Math.abs(g - bg) + Math.abs(b - bb) < 24) continue;
      counts.drawn += 1;
      if (b > 120 && b > r + 60) counts.blue += 1;
      if (r > 170 && g > 80 && g < r - 30 && b < g - 40) counts.amber += 1;
      if (r > 60 && Math.abs(r - g) < 30 && r >= b && r - b < 60) counts.clay += 1;
    }
    return { ...counts, background: [br, bg, bb] };
  }, png.toString('base64'));
}

for (const backend of BACKENDS) {
  describe(`demo page, ${backend.name} flags`, () => {
    let server;
    let browser;
    let page;
    const problems = [];

    before(async () => {
      const started = await startServer(0);
      server = started.server;
      browser = await chromium.launch({
        executablePath: CHROMIUM,
        headless: true,
        args: [...COMMON_ARGS, ...backend.args],
      });
      page = await browser.newPage({ viewport: { width: 800, height: 600 } });
      page.on('pageerror', (e) => problems.push(`page error: ${e.message}`));
      page.on('console', (m) => {
        if (m.type() === 'error') problems.push(`console error: ${m.text()}`);
      });
      await page.goto(started.url);
      await page.waitForSelector('body[data-state="ready"]', { timeout: TIMEOUT_MS });
      await nextFrame(page, 0);
    });

    after(async () => {
      await browser?.close();
      server?.close();
    });

    test('the default sample renders in its colours', async (t) => {
      const reported = await page.textContent('#backend');
      t.diagnostic(`backend reported by the page: ${reported}`);
      console.log(`[e2e] ${backend.name} flags: the page reports backend ${reported}`);
      assert.equal(reported, backend.name);
      assert.equal(await page.textContent('#num-points'), '2,007');
      const px = await canvasPixels(page, `default-sample-${backend.name}.png`);
      t.diagnostic(JSON.stringify(px));
      assert.ok(px.drawn > 0.05 * px.total, `only ${px.drawn} of ${px.total} pixels drawn`);
      assert.ok(px.clay > 0.02 * px.total, `too little lit surface: ${px.clay} pixels`);
      assert.ok(px.blue > 50, `no low (blue) points: ${px.blue} pixels`);
      assert.ok(px.amber > 50, `no high (amber) points: ${px.amber} pixels`);
    });

    test('bun000.ply through the file input shows 40,256 points', async () => {
      const dir = dataDir();
      assert.ok(dir, 'shared data folder not found (set GEOFIT_DATA)');
      const frames = await framesDrawn(page);
      await page.setInputFiles('#file', join(dir, 'bun000.ply'));
      await page.waitForFunction(
        () => document.getElementById('num-points').textContent === '40,256',
        null,
        { timeout: TIMEOUT_MS },
      );
      await nextFrame(page, frames);
      assert.equal(await page.textContent('#file-name'), 'bun000.ply');
      assert.equal(await page.isHidden('#error'), true);
      const px = await canvasPixels(page, `bun000-${backend.name}.png`);
      assert.ok(px.drawn > 0.05 * px.total, `only ${px.drawn} of ${px.total} pixels drawn`);
    });

    test('a corrupt file shows an error and the page keeps working', async () => {
      const before = await page.textContent('#num-points');
      const corrupt = Buffer.from(
        'ply\nformat binary_little_endian 1.0\nelement vertex 1000\nproperty float x\n' +
          'property float y\nproperty float z\nend_header\n\x01\x02\x03',
        'latin1',
      );
      await page.setInputFiles('#file', { name: 'corrupt.ply', mimeType: 'application/octet-stream', buffer: corrupt });
      await page.waitForSelector('#error:not([hidden])', { timeout: TIMEOUT_MS });
      const message = await page.textContent('#error');
      console.log(`[e2e] ${backend.name}: corrupt file message: ${message}`);
      assert.match(message, /corrupt\.ply/);
      assert.equal(await page.textContent('#num-points'), before, 'previous data stays shown');
      const frames = await framesDrawn(page);
      await page.setInputFiles('#file', join(ROOT, 'www', 'samples', 'bunny.obj'));
      await page.waitForFunction(
        () => document.getElementById('num-points').textContent === '2,007',
        null,
        { timeout: TIMEOUT_MS },
      );
      await nextFrame(page, frames);
      assert.equal(await page.isHidden('#error'), true, 'the error clears on the next good file');
      assert.deepEqual(problems, []);
    });
  });
}
