// End-to-end tests of the demo page in Debian's headless chromium (never a downloaded browser),
// once with WebGL2 and once with WebGPU, both rendered by SwiftShader on the CPU. Screenshots go to
// test-artifacts/.
import { after, before, describe, test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { startServer } from '../../scripts/serve.mjs';
import { BACKENDS, ROOT, countPixels, dataDir, launch, saveArtifact } from './helpers.mjs';

const TIMEOUT_MS = 60_000;

/** Waits until the page has drawn a frame after `previous` frames. */
async function nextFrame(page, previous) {
  await page.waitForFunction(
    (n) => Number(document.body.dataset.frames ?? 0) > n,
    previous,
    { timeout: TIMEOUT_MS },
  );
}

const framesDrawn = (page) => page.evaluate(() => Number(document.body.dataset.frames ?? 0));

/** Near the background colour (the top-left corner pixel). */
const isBackground = (r, g, b, [br, bg, bb]) => Math.abs(r - br) + Math.abs(g - bg) + Math.abs(b - bb) < 24;

/**
 * Screenshots the canvas (saved under test-artifacts/) and counts its pixels by class:
 * drawn (not background), the blue and amber ends of the height colours, and the clay of the lit
 * surface.
 */
function canvasPixels(page, file) {
  return countPixels(page, '#view', file, {
    drawn: (r, g, b, corner) => !isBackground(r, g, b, corner),
    blue: (r, g, b, corner) => !isBackground(r, g, b, corner) && b > 120 && b > r + 60,
    amber: (r, g, b, corner) => !isBackground(r, g, b, corner) && r > 170 && g > 80 && g < r - 30 && b < g - 40,
    clay: (r, g, b, corner) => !isBackground(r, g, b, corner) && r > 60 && Math.abs(r - g) < 30 && r >= b && r - b < 60,
  });
}

for (const backend of BACKENDS) {
  describe(`demo page, ${backend.name} flags`, () => {
    let server;
    let browser;
    let page;
    let pageUrl;
    const problems = [];

    before(async () => {
      const started = await startServer(0);
      server = started.server;
      pageUrl = started.url;
      browser = await launch(backend);
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

    test('every scanner format of tests/data/formats opens through the file input with its counts', async () => {
      const dir = join(ROOT, 'tests', 'data', 'formats');
      const expected = JSON.parse(readFileSync(join(dir, 'expected.json'), 'utf8'));
      const seen = new Set();
      for (const [file, want] of Object.entries(expected)) {
        const frames = await framesDrawn(page);
        await page.setInputFiles('#file', join(dir, file));
        await page.waitForFunction(
          ([name, points]) =>
            document.getElementById('file-name').textContent === name &&
            document.getElementById('num-points').textContent === points,
          [file, want.points.toLocaleString('en-US')],
          { timeout: TIMEOUT_MS },
        );
        await nextFrame(page, frames);
        assert.equal(await page.isHidden('#error'), true, `${file}: no error shown`);
        assert.equal(await page.textContent('#num-triangles'), want.triangles.toLocaleString('en-US'), `${file}: triangles`);
        const px = await canvasPixels(page, `format-${file}-${backend.name}.png`);
        // Something is drawn: a few hundred points, or two registered scans far apart, cover a
        // few hundred pixels only.
        assert.ok(px.drawn > 100, `${file}: only ${px.drawn} of ${px.total} pixels drawn`);
        seen.add(file.split('.').pop());
      }
      for (const ext of ['e57', 'las', 'laz', 'pcd', 'ptx', 'pts', 'gltf', 'glb']) {
        assert.ok(seen.has(ext), `a .${ext} sample was opened`);
      }
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
    });

    test('wireframe, orbit, zoom and fit change the view as expected', async () => {
      const frames = () => framesDrawn(page);
      const base = await canvasPixels(page, `camera-0-fitted-${backend.name}.png`);

      let n = await frames();
      await page.check('#show-wireframe');
      await nextFrame(page, n);
      const wired = await canvasPixels(page, `camera-1-wireframe-${backend.name}.png`);
      assert.ok(wired.clay < 0.95 * base.clay, `wireframe hides no surface: ${wired.clay} vs ${base.clay}`);
      n = await frames();
      await page.uncheck('#show-wireframe');
      await nextFrame(page, n);

      const box = await page.locator('#view').boundingBox();
      const cx = box.x + box.width / 2;
      const cy = box.y + box.height / 2;
      n = await frames();
      await page.mouse.move(cx, cy);
      await page.mouse.down();
      await page.mouse.move(cx + 120, cy + 30, { steps: 4 });
      await page.mouse.up();
      await nextFrame(page, n);
      const turned = await canvasPixels(page, `camera-2-orbited-${backend.name}.png`);
      assert.notDeepEqual(turned, base, 'dragging changed nothing');

      n = await frames();
      await page.mouse.wheel(0, -400);
      await nextFrame(page, n);
      const zoomed = await canvasPixels(page, `camera-3-zoomed-${backend.name}.png`);
      assert.ok(zoomed.drawn > 1.2 * turned.drawn, `zooming in did not enlarge: ${zoomed.drawn} vs ${turned.drawn}`);

      n = await frames();
      await page.dblclick('#view');
      await nextFrame(page, n);
      const fitted = await canvasPixels(page, `camera-4-refitted-${backend.name}.png`);
      assert.ok(
        Math.abs(fitted.drawn - base.drawn) <= 0.01 * base.drawn,
        `double-click did not restore the fitted view: ${fitted.drawn} vs ${base.drawn}`,
      );
    });

    test('bad data at the JavaScript API throws errors with messages', async () => {
      const messages = await page.evaluate(() => {
        const { viewer, loadFile } = window.geofit;
        const caught = (f) => {
          try {
            f();
            return 'no error';
          } catch (e) {
            return e instanceof Error ? e.message : `not an Error: ${e}`;
          }
        };
        const three = new Float32Array([0, 0, 0]);
        return [
          caught(() => loadFile(new Uint8Array(), 'empty.xyz')),
          caught(() => viewer.setPoints(new Float32Array([1, 2]), new Float32Array([1, 2]))),
          caught(() => viewer.setPoints(new Float32Array([0, NaN, 0]), three)),
          caught(() => viewer.setMesh(three, three, new Uint32Array([0, 0, 7]))),
          caught(() => viewer.setLines(new Float32Array(9), new Float32Array(9))),
        ];
      });
      assert.match(messages[0], /empty/);
      assert.match(messages[1], /point positions has 2 values/);
      assert.match(messages[2], /point positions value 1 is not finite/);
      assert.match(messages[3], /index 7 .* out of range for 1 vertices/);
      assert.match(messages[4], /multiple of 6/);
    });

    test('line sets draw in their colours', async () => {
      const n = await framesDrawn(page);
      await page.evaluate(() => {
        const { viewer } = window.geofit;
        // A red cross through the view's centre, drawn over the (hidden) scene.
        viewer.setLayers(false, false, false, true);
        const c = [-0.0168, 0.11, 0.0015];
        const d = 0.08;
        const pos = [];
        for (let axis = 0; axis < 3; axis += 1) {
          for (let k = -4; k <= 4; k += 1) {
            for (const s of [-d, d]) {
              const p = [...c];
              p[axis] += s;
              p[(axis + 1) % 3] += k * 0.0005;
              pos.push(...p);
            }
          }
        }
        viewer.setLines(new Float32Array(pos), new Float32Array(pos.length).map((_, i) => (i % 3 === 0 ? 1 : 0)));
        window.geofit.requestRender();
      });
      await nextFrame(page, n);
      const { red } = await countPixels(page, '#view', `lines-${backend.name}.png`, {
        red: (r, g, b) => r > 200 && g < 60 && b < 60,
      });
      assert.ok(red > 200, `only ${red} red line pixels`);
      await page.evaluate(() => {
        window.geofit.viewer.setLines(new Float32Array(), new Float32Array());
      });
      await page.uncheck('#show-points');
      await page.check('#show-points');
    });

    test('a narrow window at device pixel ratio 2 keeps a sharp, working view', async () => {
      const small = await browser.newPage({ viewport: { width: 360, height: 640 }, deviceScaleFactor: 2 });
      try {
        await small.goto(pageUrl);
        await small.waitForSelector('body[data-state="ready"]', { timeout: TIMEOUT_MS });
        await nextFrame(small, 0);
        const m = await small.evaluate(() => {
          const c = document.getElementById('view');
          return {
            css: [c.clientWidth, c.clientHeight],
            px: [c.width, c.height],
            scrollWidth: document.documentElement.scrollWidth,
          };
        });
        assert.deepEqual(m.px, [m.css[0] * 2, m.css[1] * 2], JSON.stringify(m));
        assert.ok(m.css[1] > 200, `the view is only ${m.css[1]} px tall`);
        assert.ok(m.scrollWidth <= 360, `the page scrolls sideways: ${m.scrollWidth}`);
        assert.equal(await small.textContent('#num-points'), '2,007');
        saveArtifact(`narrow-dpr2-${backend.name}.png`, await small.locator('#view').screenshot());
      } finally {
        await small.close();
      }
    });

    test('the page logged no errors', () => {
      assert.deepEqual(problems, []);
    });
  });
}
