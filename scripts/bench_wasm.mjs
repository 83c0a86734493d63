// Benchmark of the wasm build against the native one on the same fit (issue 4: wasm in headless
// chromium must take at most 2x the native time). Fits the whole Stanford bunny with Loop,
// 612 initial control points, E_avg 0.01 %, E_max 0.05 %, at most 7049 control points: in the
// browser through the `Fitter` API of pkg/ (main thread, one thread), then natively with
// `target/release/geofit fit` and the same options. Prints a Markdown table.
//
// Usage: bash scripts/build-wasm.sh && cargo build --release && node scripts/bench_wasm.mjs [DATA_DIR]
// DATA_DIR defaults to ../shared/data, else /work/shared/data. Needs Debian's /usr/bin/chromium.
import { execFileSync } from 'node:child_process';
import { existsSync, mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { cpus, loadavg, tmpdir } from 'node:os';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';
import { startServer } from './serve.mjs';

const ROOT = join(dirname(fileURLToPath(import.meta.url)), '..');
const OPTIONS = { scheme: 'loop', initial: 612, tolAvg: 0.01, tolMax: 0.05, maxControl: 7049 };
const CLI_ARGS = ['--scheme', 'loop', '--initial', '612', '--tol-avg', '0.01', '--tol-max', '0.05',
  '--max-control', '7049', '-q'];

function dataDir() {
  if (process.argv[2]) return process.argv[2];
  const beside = join(ROOT, '..', 'shared', 'data');
  return existsSync(beside) ? beside : '/work/shared/data';
}

/** The fit in headless chromium: setup (QEM + first foot points) and iterations, in ms. */
async function wasmFit(bunny) {
  const { server, url } = await startServer(0);
  const browser = await chromium.launch({
    executablePath: '/usr/bin/chromium',
    headless: true,
    args: ['--no-sandbox', '--no-first-run', '--disable-background-networking'],
  });
  try {
    const page = await browser.newPage();
    await page.route('**/bench-data/bunny.obj', (route) => route.fulfill({ body: bunny }));
    // A same-origin page without the demo app, so nothing else runs while we measure.
    await page.goto(new URL('bench-blank', url).href);
    return await page.evaluate(async (options) => {
      const m = await import('/pkg/geofit.js');
      await m.default();
      const bytes = new Uint8Array(await (await fetch('/www/bench-data/bunny.obj')).arrayBuffer());
      const t0 = performance.now();
      const scan = m.loadFile(bytes, 'stanford-bunny.obj');
      const t1 = performance.now();
      const fitter = new m.Fitter(scan, options);
      const t2 = performance.now();
      const s = fitter.run(1e12);
      const t3 = performance.now();
      return {
        iterations: s.iter,
        controlPoints: s.controlPoints,
        status: s.status,
        eAvg: s.eAvgPct,
        eMax: s.eMaxPct,
        eRms: s.eRmsPct,
        readMs: t1 - t0,
        setupMs: t2 - t1,
        fitMs: t3 - t2,
      };
    }, OPTIONS);
  } finally {
    await browser.close();
    server.close();
  }
}

/** The same fit natively (the CLI's JSON report; reading the file is not in its total). */
function nativeFit(path) {
  const exe = join(ROOT, 'target', 'release', 'geofit');
  if (!existsSync(exe)) throw new Error(`${exe} not found: run cargo build --release first`);
  const dir = mkdtempSync(join(tmpdir(), 'geofit-bench-'));
  try {
    const json = join(dir, 'report.json');
    execFileSync(exe, ['fit', path, ...CLI_ARGS, '--json', json], { stdio: 'ignore' });
    const r = JSON.parse(readFileSync(json, 'utf8'));
    return {
      iterations: r.iterations,
      controlPoints: r.final_control_points,
      status: r.converged ? 'converged' : 'not converged',
      eAvg: r.e_avg_pct,
      eMax: r.e_max_pct,
      eRms: r.e_rms_pct,
      setupMs: r.precompute_s * 1000,
      fitMs: r.fit_s * 1000,
    };
  } finally {
    rmSync(dir, { recursive: true, force: true });
  }
}

const path = join(dataDir(), 'stanford-bunny.obj');
const wasm = await wasmFit(readFileSync(path));
const native = nativeFit(path);
const row = (name, r) =>
  `| ${name} | ${r.status} | ${r.iterations} | ${r.controlPoints} | ${r.eAvg.toFixed(5)} | ` +
  `${r.eMax.toFixed(5)} | ${r.eRms.toFixed(5)} | ${(r.setupMs / 1000).toFixed(2)} | ` +
  `${(r.fitMs / 1000).toFixed(2)} | ${((r.setupMs + r.fitMs) / 1000).toFixed(2)} |`;
console.log(`machine: ${cpus().length} cores, ${cpus()[0]?.model ?? '?'}, load ${loadavg()[0].toFixed(2)}`);
console.log('');
console.log('| build | status | iterations | control points | E_avg % | E_max % | E_rms % | setup s | fit s | total s |');
console.log('|---|---|---|---|---|---|---|---|---|---|');
console.log(row('wasm (headless chromium)', wasm));
console.log(row('native (release)', native));
const ratio = (wasm.setupMs + wasm.fitMs) / (native.setupMs + native.fitMs);
console.log('');
console.log(`wasm / native total time: ${ratio.toFixed(2)}x`);
