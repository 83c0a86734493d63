// The npm package as a user gets it: pkg/ passes publint and @arethetypeswrong/cli and declares no
// `any`; `npm pack` makes a tarball that installs (offline) into a scratch project; a tiny page
// bundled there with esbuild and with Vite fits the bundled bunny in chromium through
// `fitInWorker` (progress frames, the result with a GLB, cancel by AbortSignal, errors with the
// core's message); and the statistics, report and default spec it gets type-check against the
// package's declarations (excess and missing fields fail), so the interfaces cannot drift from
// what serde writes.
import { after, before, describe, test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { copyFileSync, mkdirSync, mkdtempSync, readFileSync, readdirSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { BACKENDS, ROOT, launch } from './helpers.mjs';
import { startServer } from '../../scripts/serve.mjs';

const PKG = join(ROOT, 'pkg');
const BIN = join(ROOT, 'node_modules', '.bin');
const TIMEOUT_MS = 60_000;
const run = (cmd, args, cwd) => execFileSync(cmd, args, { cwd, encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'] });

// The page: fits through the package's worker entry, and calls the main entry for the defaults.
const MAIN_JS = `
import init, { Fitter, defaultSpec, loadFile } from 'geofit';
import { fitInWorker } from 'geofit/worker';

const file = (name) => fetch(name).then((r) => r.arrayBuffer());
window.geofit = {
  async fit(name, spec, exports) {
    const frames = [];
    const onProgress = ({ stats, limit }) =>
      frames.push({ iter: stats.iter, f32: limit.positions instanceof Float32Array, vertices: limit.positions.length / 3 });
    const phases = [];
    const onPhase = (phase, done) => {
      if (phases[phases.length - 1]?.phase !== phase) phases.push({ phase, done });
      phases[phases.length - 1].done = done;
    };
    const r = await fitInWorker(await file(name), name, spec, { onProgress, onPhase, exports });
    const glb = r.exports.glb ? new TextDecoder().decode(r.exports.glb.subarray(0, 4)) : null;
    return { frames, phases, stats: r.stats, report: r.report, triangles: r.limit.indices.length / 3, glb };
  },
  async cancel(name, spec) {
    const abort = new AbortController();
    let frames = 0;
    const onProgress = () => { frames += 1; abort.abort(); };
    const error = await fitInWorker(await file(name), name, spec, { onProgress, signal: abort.signal, sliceMs: 1 })
      .then(() => null, (e) => e);
    const atAbort = frames;
    await new Promise((r) => setTimeout(r, 500));
    return { name: error?.name ?? null, atAbort, later: frames };
  },
  async error(text, name, spec, exports) {
    const bytes = text === null ? await file(name) : new TextEncoder().encode(text);
    return fitInWorker(bytes, name, spec, { exports }).then(() => null, (e) => [e instanceof Error, e.message]);
  },
  async history(name, spec) {
    await init();
    const scan = loadFile(new Uint8Array(await file(name)), name);
    const fitter = new Fitter(scan, spec);
    scan.free();
    fitter.run(60_000);
    const history = fitter.history();
    fitter.free();
    return history;
  },
  async defaults(scheme) {
    await init();
    return defaultSpec(scheme);
  },
};
document.body.dataset.ready = 'yes';
`;
const INDEX_HTML = (src) =>
  `<!doctype html><html><head><meta charset="utf-8"><title>geofit package</title></head><body><script type="module" src="${src}"></script></body></html>\n`;
const SAMPLES = ['bunny.obj', 'bunny-section.xyz', 'bun000-points.xyz'];

/** Strips comments, so that only declarations are searched. */
const code = (dts) => dts.replace(/\/\*[^]*?\*\//g, '').replace(/\/\/.*$/gm, '');

describe('the npm package', () => {
  let dir;
  let app;
  let server;
  let browser;
  const results = {};

  before(() => {
    dir = mkdtempSync(join(tmpdir(), 'geofit-package-'));
    app = join(dir, 'app');
    mkdirSync(join(app, 'public'), { recursive: true });
    for (const s of SAMPLES) copyFileSync(join(ROOT, 'www', 'samples', s), join(app, 'public', s));
  });
  after(async () => {
    await browser?.close();
    server?.close();
    if (dir) rmSync(dir, { recursive: true, force: true });
  });

  test('pkg/package.json is written from Cargo.toml, and no `any` is declared', () => {
    const manifest = JSON.parse(readFileSync(join(PKG, 'package.json'), 'utf8'));
    const cargoVersion = readFileSync(join(ROOT, 'Cargo.toml'), 'utf8').match(/^version = "([^"]+)"/m)[1];
    assert.equal(manifest.name, 'geofit');
    assert.equal(manifest.version, cargoVersion);
    assert.equal(manifest.type, 'module');
    for (const entry of ['.', './worker']) assert.equal(Object.keys(manifest.exports[entry])[0], 'types');
    for (const file of ['geofit.d.ts', 'fit-in-worker.d.ts']) {
      const anys = code(readFileSync(join(PKG, file), 'utf8')).match(/\bany\b/g) ?? [];
      assert.equal(anys.length, 0, `pkg/${file} declares ${anys.length} any`);
    }
  });

  test('publint and @arethetypeswrong/cli find no problem', () => {
    const lint = run(join(BIN, 'publint'), ['--strict', PKG], ROOT);
    assert.match(lint, /All good/);
    // ESM only: node10 and require() resolution are not offered (attw's esm-only profile).
    run(join(BIN, 'attw'), ['--pack', PKG, '--profile', 'esm-only'], ROOT);
  });

  test('npm pack, and the tarball installs into a scratch project offline', () => {
    const tarball = run('npm', ['pack', PKG, '--pack-destination', dir, '--silent'], ROOT).trim().split('\n').pop();
    writeFileSync(join(app, 'package.json'), '{ "name": "scratch", "private": true, "type": "module" }\n');
    run('npm', ['install', join(dir, tarball), '--offline', '--no-audit', '--no-fund'], app);
    const installed = readdirSync(join(app, 'node_modules', 'geofit')).sort();
    for (const f of ['fit-in-worker.js', 'geofit.js', 'geofit_bg.wasm', 'package.json', 'worker.js']) assert.ok(installed.includes(f), f);
    writeFileSync(join(app, 'main.js'), MAIN_JS);
  });

  test('esbuild bundles the page: the worker as a second entry point, the .wasm beside it', () => {
    const out = join(app, 'dist-esbuild');
    run(join(BIN, 'esbuild'), ['main.js', 'node_modules/geofit/worker.js', '--bundle', '--format=esm',
      '--entry-names=[name]', `--outdir=${out}`, '--log-level=warning'], app);
    copyFileSync(join(app, 'node_modules', 'geofit', 'geofit_bg.wasm'), join(out, 'geofit_bg.wasm'));
    writeFileSync(join(out, 'index.html'), INDEX_HTML('main.js'));
    for (const s of SAMPLES) copyFileSync(join(app, 'public', s), join(out, s));
  });

  test('Vite bundles the page as it is', () => {
    writeFileSync(join(app, 'index.html'), INDEX_HTML('/main.js'));
    writeFileSync(join(app, 'vite.config.js'), "export default { base: './', worker: { format: 'es' }, logLevel: 'warn' };\n");
    run(join(BIN, 'vite'), ['build', '--outDir', 'dist-vite', '--emptyOutDir'], app);
  });

  test('both bundles are served', async () => {
    ({ server } = await startServer(0, { root: app, served: ['dist-esbuild', 'dist-vite'] }));
    browser = await launch(BACKENDS[0]);
  });

  for (const bundle of ['dist-esbuild', 'dist-vite']) {
    test(`${bundle}: fitInWorker fits the bunny with progress, cancels, and rejects bad input`, async () => {
      const page = await browser.newPage();
      const problems = [];
      page.on('pageerror', (e) => problems.push(e.message));
      try {
        const { port } = server.address();
        await page.goto(`http://127.0.0.1:${port}/${bundle}/index.html`);
        await page.waitForSelector('body[data-ready="yes"]', { state: 'attached', timeout: TIMEOUT_MS });
        const spec = { scheme: 'loop', tolAvg: 0.1, tolMax: 0.5, initial: 200 };
        const fit = await page.evaluate(([s]) => window.geofit.fit('bunny.obj', s, ['glb']), [spec]);
        assert.equal(fit.stats.status, 'converged');
        assert.ok(fit.stats.eMaxPct <= 0.5 && fit.stats.eAvgPct <= 0.1, JSON.stringify(fit.stats));
        assert.ok(fit.frames.length >= 1 && fit.frames.every((f) => f.f32 && f.vertices > 0), JSON.stringify(fit.frames));
        assert.deepEqual(fit.frames.map((f) => f.iter), [...fit.frames.map((f) => f.iter)].sort((a, b) => a - b));
        assert.ok(fit.triangles > 1000, `${fit.triangles} triangles`);
        assert.equal(fit.glb, 'glTF');
        assert.equal(fit.report.history.length, fit.stats.iter);
        // The phases heard: reading, QEM (the bunny mesh is clean: no repair), set-up, then the
        // iterations, each reported to its end.
        assert.deepEqual(fit.phases.map((p) => p.phase), ['reading', 'simplification', 'setup', 'iteration'], JSON.stringify(fit.phases));
        assert.ok(fit.phases.every((p) => p.done === 1), JSON.stringify(fit.phases));

        const cancel = await page.evaluate(([s]) => window.geofit.cancel('bunny.obj', s), [{ scheme: 'loop', tolMax: 1e-6, maxIter: 10000 }]);
        assert.deepEqual(cancel, { name: 'AbortError', atAbort: 1, later: 1 });

        const badSpec = await page.evaluate(() => window.geofit.error('v 0 0 0\n', 'a.obj', { tolAvgg: 1 }));
        assert.equal(badSpec[0], true);
        assert.match(badSpec[1], /fit options: unknown field `tolAvgg`/);
        const badFile = await page.evaluate(() => window.geofit.error('ply\nformat nonsense\n', 'a.ply', {}));
        assert.equal(badFile[0], true);
        assert.match(badFile[1], /ply/i);
        const badExport = await page.evaluate(() => window.geofit.error(null, 'bunny-section.xyz', { scheme: 'bspline-curve' }, ['dwg']));
        assert.deepEqual(badExport, [true, "unknown export 'dwg': one of cage, creases, usda, obj, ply, stl, glb, iges, step, json, msh"]);

        if (bundle === 'dist-esbuild') {
          const curve = await page.evaluate(() => window.geofit.fit('bunny-section.xyz', { scheme: 'bspline-curve', method: 'knots' }, []));
          results.stats = fit.stats;
          results.report = fit.report;
          results.curveReport = curve.report;
          const surface = await page.evaluate(() => window.geofit.fit('bun000-points.xyz', { scheme: 'bspline-surface', maxIter: 2 }, ['step']));
          assert.ok(surface.report.control_points_u > 0, JSON.stringify(surface.report).slice(0, 300));
          results.surfaceReport = surface.report;
          results.history = await page.evaluate(() => window.geofit.history('bunny-section.xyz', { scheme: 'bspline-curve' }));
          assert.ok(results.history.length > 0);
          results.defaults = await page.evaluate(() => window.geofit.defaults('bspline-surface'));
        }
        assert.deepEqual(problems, []);
      } finally {
        await page.close();
      }
    });
  }

  test('what the fits gave type-checks against the declarations (no field too many or missing)', () => {
    assert.ok(results.report, 'the esbuild fit ran');
    const lit = (v) => JSON.stringify(v, null, 1);
    writeFileSync(join(app, 'sample.ts'), [
      "import type { FitReport, FitStats, HistoryEntry, ResolvedFitSpec } from 'geofit';",
      "import type { FitResult } from 'geofit/worker';",
      `export const stats: FitStats = ${lit(results.stats)};`,
      `export const report: FitReport = ${lit(results.report)};`,
      `export const curveReport: FitReport = ${lit(results.curveReport)};`,
      `export const surfaceReport: FitReport = ${lit(results.surfaceReport)};`,
      `export const history: HistoryEntry[] = ${lit(results.history)};`,
      `export const defaults: ResolvedFitSpec = ${lit(results.defaults)};`,
      'export type Checked = FitResult;',
      '',
    ].join('\n'));
    writeFileSync(join(app, 'tsconfig.json'), JSON.stringify({
      compilerOptions: { strict: true, noEmit: true, target: 'es2022', module: 'esnext', moduleResolution: 'bundler',
        lib: ['esnext', 'dom', 'esnext.disposable'], skipLibCheck: false, types: [] },
      files: ['sample.ts'],
    }));
    try {
      run(join(BIN, 'tsc'), ['-p', 'tsconfig.json'], app);
    } catch (e) {
      assert.fail(`tsc: ${e.stdout}${e.stderr}`);
    }
  });
});
