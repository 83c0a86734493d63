// End-to-end tests of the deviation views and page links, on WebGL2 and on WebGPU: the bundled
// bunny (2,007 points) is fitted with the page's defaults, then the histogram (its counts add up
// to the points, bars and the tolerance band are drawn), the statistics, the CSV download and
// point picking (the deviation shown is the CSV's for that point) are checked; then page links
// `?src=…&scheme=…`: a bundled sample with its settings, a cross-origin file refused, a bad
// file and a bad parameter shown as errors with the page still fitting.
import { after, before, describe, test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { startServer } from '../../scripts/serve.mjs';
import { BACKENDS, LONG_TASK_MS, launch, saveArtifact } from './helpers.mjs';

const TIMEOUT_MS = 180_000;

/** Parses the CSV of the "Deviations CSV" button: header figures and rows. */
function parseCsv(text) {
  const figures = {};
  const rows = [];
  const lines = text.trim().split('\n');
  for (const line of lines) {
    if (line.startsWith('# ')) {
      const [k, v] = line.slice(2).split(',');
      figures[k] = v === '' ? null : Number(v);
    } else if (!line.startsWith('index,')) {
      const [index, x, y, z, deviation] = line.split(',');
      rows.push({ index: Number(index), x: Number(x), y: Number(y), z: Number(z), deviation });
    }
  }
  assert.equal(lines.find((l) => !l.startsWith('#')), 'index,x,y,z,deviation');
  return { figures, rows };
}

/** Histogram canvas pixels: the background, the shaded band and bar colours. */
function histogramPixels(page) {
  return page.evaluate(() => {
    const c = /** @type {HTMLCanvasElement} */ (document.getElementById('dev-histogram'));
    const { data } = c.getContext('2d').getImageData(0, 0, c.width, c.height);
    const counts = { total: data.length / 4, band: 0, bars: 0 };
    for (let i = 0; i < data.length; i += 4) {
      const [r, g, b] = [data[i], data[i + 1], data[i + 2]];
      // Background #10141b shaded green by the band; bars pale or saturated (bright).
      if (g > r + 10 && g > b && g < 80) counts.band += 1;
      if (r + g + b > 400 || r > 180 || b > 180) counts.bars += 1;
    }
    return counts;
  });
}

/** Clicks the view at spots of a grid until a point is picked; returns the label's data. */
async function pickSomePoint(page) {
  const box = await page.locator('#view').boundingBox();
  for (const [fx, fy] of [[0.5, 0.5], [0.45, 0.5], [0.55, 0.5], [0.5, 0.45], [0.5, 0.55], [0.4, 0.4], [0.6, 0.6], [0.45, 0.6], [0.55, 0.4]]) {
    await page.mouse.click(box.x + fx * box.width, box.y + fy * box.height);
    const label = await page.evaluate(() => {
      const l = document.getElementById('pick-label');
      return l.hidden ? null : { text: l.textContent, ...l.dataset };
    });
    if (label) return label;
  }
  return null;
}

for (const backend of BACKENDS) describe(`deviation views and page links, ${backend.name}`, () => {
  let server;
  let browser;
  let page;
  let base;
  const problems = [];

  /** Opens `query` on the page and waits until it has shown a file and its fit is idle. */
  async function open(query) {
    await page.goto(`${base}${query}`);
    await page.waitForSelector('body[data-state="ready"][data-fit="idle"]', { timeout: TIMEOUT_MS });
  }

  before(async () => {
    const started = await startServer(0);
    server = started.server;
    base = started.url;
    browser = await launch(backend);
    page = await browser.newPage({ viewport: { width: 1100, height: 800 }, acceptDownloads: true });
    page.on('pageerror', (e) => problems.push(`page error: ${e.message}`));
    page.on('console', (m) => {
      if (m.type() === 'error') problems.push(`console error: ${m.text()}`);
    });
    await page.addInitScript(() => {
      window.longTasks = [];
      new PerformanceObserver((list) => {
        for (const e of list.getEntries()) window.longTasks.push(e.duration);
      }).observe({ type: 'longtask', buffered: true });
    });
    await page.route('**/samples/broken.ply', (route) => route.fulfill({
      status: 200,
      contentType: 'application/octet-stream',
      body: 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1\n2 x\n',
    }));
    await open('');
  });

  after(async () => {
    await browser?.close();
    server?.close();
  });

  test('histogram, statistics, CSV and picking agree on the fitted bunny', async () => {
    await page.evaluate(() => { window.longTasks = []; });
    await page.click('#fit-play');
    await page.waitForSelector('body[data-fit="converged"]', { timeout: TIMEOUT_MS });
    await page.waitForTimeout(300);
    const longTasks = await page.evaluate(() => window.longTasks);
    const f = await page.evaluate(() => window.geofitFit);
    console.log(`${backend.name}: ${f.frames} frames; longest stages of showing one (figures, points, surface, lines): ` +
      `${f.stageMs.map((ms) => Math.round(ms)).join(', ')} ms; of the figures, deviation views ${f.deviationMs.toFixed(1)} ms, ` +
      `convergence chart ${f.chartMs.toFixed(1)} ms; long tasks ${JSON.stringify(longTasks)}`);
    const dev = await page.evaluate(() => window.geofitFit.deviation);
    const stats = await page.evaluate(() => window.geofitFit.lastStats);
    // The histogram: every point in one bin, symmetric range covering the band.
    assert.equal(dev.counts.length, 64);
    assert.equal(dev.points, 2007);
    assert.equal(dev.counts.reduce((a, b) => a + b, 0), dev.points);
    assert.ok(dev.halfWidth >= 1.5 * dev.tolerance, JSON.stringify(dev));
    assert.ok(Math.abs(dev.tolerance - (stats.tolMaxPct * stats.diagonal) / 100) < 1e-12);
    // Converged: E_max within tolerance, so every point is within the band.
    assert.equal(dev.withinTolerancePct, 100);
    assert.ok(dev.max <= dev.tolerance && Math.abs(dev.max - stats.eMax) <= 1e-9 * stats.eMax, `${dev.max} vs ${stats.eMax}`);
    const px = await histogramPixels(page);
    await page.locator('#dev-histogram').screenshot({ path: undefined }).then((png) => saveArtifact(`deviation-histogram-${backend.name}.png`, png));
    assert.ok(px.band > px.total * 0.1, `tolerance band shaded: ${JSON.stringify(px)}`);
    assert.ok(px.bars > 50, `bars drawn: ${JSON.stringify(px)}`);
    assert.match(await page.textContent('#dev-within'), /^100\.00 %/);
    assert.deepEqual(longTasks.filter((ms) => ms > LONG_TASK_MS), [], `no main-thread task over ${LONG_TASK_MS} ms`);

    const [download] = await Promise.all([page.waitForEvent('download'), page.click('#dev-csv')]);
    assert.equal(download.suggestedFilename(), 'geofit-deviations.csv');
    const text = readFileSync(await download.path(), 'utf8');
    saveArtifact(`deviations-${backend.name}.csv`, text);
    const csv = parseCsv(text);
    assert.equal(csv.rows.length, dev.points);
    assert.equal(csv.figures.points, dev.points);
    for (const k of ['mean', 'sigma', 'p50', 'p90', 'p95', 'p99', 'max', 'tolerance', 'withinTolerancePct']) {
      assert.equal(csv.figures[k], dev[k], k);
    }
    // The CSV's deviations (f32) give the figures (f64) to f32 precision.
    const d = csv.rows.map((r) => Number(r.deviation));
    const mean = d.reduce((a, b) => a + b, 0) / d.length;
    assert.ok(Math.abs(mean - dev.mean) <= 1e-6 * dev.max, `mean ${mean} vs ${dev.mean}`);
    assert.ok(Math.abs(Math.max(...d.map(Math.abs)) - dev.max) <= 1e-6 * dev.max);
    const data = await page.evaluate(async () => {
      const m = await import(new URL('../pkg/geofit.js', location.href).href);
      const scan = m.loadFile(new Uint8Array(await (await fetch('samples/bunny.obj')).arrayBuffer()), 'bunny.obj');
      const p = [...scan.positions().subarray(0, 3)];
      scan.free();
      return p;
    });
    assert.deepEqual([csv.rows[0].x, csv.rows[0].y, csv.rows[0].z], data, 'first row is the first point of the file');

    const label = await pickSomePoint(page);
    assert.ok(label, 'a click on the bunny picks a point');
    const row = csv.rows[Number(label.index)];
    assert.equal(label.deviation, row.deviation, `picked point ${label.index}`);
    assert.ok(label.text.startsWith(`point ${label.index} (`), label.text);
    await page.screenshot({ path: undefined }).then((png) => saveArtifact(`deviation-pick-${backend.name}.png`, png));
    // A click on the empty corner picks nothing and hides the label.
    const box = await page.locator('#view').boundingBox();
    await page.mouse.click(box.x + 3, box.y + 3);
    assert.equal(await page.isHidden('#pick-label'), true);
  });

  test('?src= opens a bundled sample with the link\'s settings', async () => {
    await open('?src=samples/bun000-points.xyz&scheme=bspline-surface&tolMax=0.8&initial=150');
    assert.equal(await page.textContent('#file-name'), 'bun000-points.xyz');
    assert.equal(await page.inputValue('#fit-scheme'), 'bspline-surface');
    assert.equal(await page.inputValue('#fit-tol-max'), '0.8');
    assert.equal(await page.inputValue('#fit-initial'), '150');
    assert.equal(await page.isHidden('#error'), true);
    await page.click('#fit-step');
    await page.waitForFunction(() => document.body.dataset.fitIter === '1', null, { timeout: TIMEOUT_MS });
    const s = await page.evaluate(() => window.geofitFit.lastStats);
    assert.equal(s.scheme, 'bspline-surface');
    assert.equal(s.tolMaxPct, 0.8);
  });

  for (const [label, query, message] of [
    ['a cross-origin src is refused', '?src=http://example.invalid/bunny.obj', /own site .* not of http:\/\/example\.invalid/],
    // Served by the test (page.route below): a PLY whose vertex line is cut short.
    ['a bad file via src', '?src=samples/broken.ply', /Could not load broken\.ply: /],
    ['an unknown parameter', '?src=samples/bunny.obj&tolerance=1', /unknown page parameter 'tolerance'/],
    ['a parameter that is not a number', '?src=samples/bunny.obj&tolMax=abc', /tolMax=abc: not a number/],
    ['a scheme that does not exist', '?src=samples/bunny.obj&scheme=nurbs', /scheme=nurbs: not one of/],
  ]) {
    test(`${label}: the error is shown and the page still fits the first sample`, async () => {
      await open(query);
      assert.match(await page.textContent('#error'), message);
      assert.equal(await page.isVisible('#error'), true);
      assert.equal(await page.textContent('#file-name'), 'bunny.obj');
      await page.click('#fit-step');
      await page.waitForFunction(() => document.body.dataset.fitIter === '1', null, { timeout: TIMEOUT_MS });
    });
  }

  test('the page logged no errors', () => {
    assert.deepEqual(problems, []);
  });
});
