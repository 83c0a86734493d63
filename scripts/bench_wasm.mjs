// Benchmark of the wasm build against the native one on the same fit (issue 4: wasm in headless
// chromium must take at most 2x the native time). Fits the whole Stanford bunny with Loop,
// 612 initial control points, E_avg 0.01 %, E_max 0.05 %, at most 7049 control points: in the
// browser through the `Fitter` API of pkg/ (main thread, one thread), then natively with
// `target/release/geofit fit`, the same options and one thread. Prints a Markdown table.
//
// Then the foot-point rate (issue 17, item 2) in the browser: for Loop, Catmull–Clark and
// Doo–Sabin, the same fit to its end, then every data point's foot point on the final surface,
// cold (from the spatial index) and warm (from the foot points before the fit's last move),
// best of 7 windows of at least 0.2 s each, one thread: the browser's side of
// `cargo bench --bench foot_points` (which prints the native figures).
//
// Usage: bash scripts/build-wasm.sh && cargo build --release && node scripts/bench_wasm.mjs [DATA_DIR]
//        [--feet-only | --no-feet]
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

const ARGS = process.argv.slice(2);
const FEET = !ARGS.includes('--no-feet');
const FIT = !ARGS.includes('--feet-only');

function dataDir() {
  const given = ARGS.find((a) => !a.startsWith('--'));
  if (given) return given;
  const beside = join(ROOT, '..', 'shared', 'data');
  return existsSync(beside) ? beside : '/work/shared/data';
}

/** A page of the headless browser with the bunny served at /www/bench-data/bunny.obj; `run`
 * gets it and returns what `run` returns. */
async function inBrowser(bunny, run) {
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
    return await run(page);
  } finally {
    await browser.close();
    server.close();
  }
}

/** The fit in headless chromium: setup (QEM + first foot points) and iterations, in ms. */
async function wasmFit(bunny) {
  return inBrowser(bunny, (page) =>
    page.evaluate(async (options) => {
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
    }, OPTIONS),
  );
}

/** Foot points per second in headless chromium, per scheme: cold and warm passes on the final
 * surface of the model C fit (`FootPointBench`). */
async function wasmFootPoints(bunny) {
  return inBrowser(bunny, (page) =>
    page.evaluate(async (options) => {
      const m = await import('/pkg/geofit.js');
      await m.default();
      const bytes = new Uint8Array(await (await fetch('/www/bench-data/bunny.obj')).arrayBuffer());
      const scan = m.loadFile(bytes, 'stanford-bunny.obj');
      const rows = [];
      for (const scheme of ['loop', 'catmull-clark', 'doo-sabin']) {
        const t0 = performance.now();
        const bench = new m.FootPointBench(scan, { ...options, scheme });
        const setupMs = performance.now() - t0;
        const row = { scheme, points: bench.numPoints, controlPoints: bench.controlPoints, setupMs };
        for (const kind of ['cold', 'warm']) {
          const first = bench[kind]();
          let best = 0;
          for (let r = 0; r < 7; r++) {
            let points = 0;
            const start = performance.now();
            while (performance.now() - start < 200) {
              if (bench[kind]() !== first) throw new Error(`${scheme} ${kind}: passes differ`);
              points += bench.numPoints;
            }
            best = Math.max(best, points / ((performance.now() - start) / 1000));
          }
          row[kind] = best;
          row[`${kind}Sum`] = first;
        }
        bench.free();
        rows.push(row);
      }
      return rows;
    }, OPTIONS),
  );
}

/** The same fit natively (the CLI's JSON report; reading the file is not in its total). */
function nativeFit(path) {
  const exe = join(ROOT, 'target', 'release', 'geofit');
  if (!existsSync(exe)) throw new Error(`${exe} not found: run cargo build --release first`);
  const dir = mkdtempSync(join(tmpdir(), 'geofit-bench-'));
  try {
    const json = join(dir, 'report.json');
    // One thread, as the browser has: the CLI would otherwise find its foot points on all cores.
    execFileSync(exe, ['fit', path, ...CLI_ARGS, '--json', json], {
      stdio: 'ignore',
      env: { ...process.env, GEOFIT_THREADS: '1' },
    });
    const r = JSON.parse(readFileSync(json, 'utf8'));
    return {
      iterations: r.iterations,
      controlPoints: r.final_control_points,
      status: r.status,
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
console.log(`machine: ${cpus().length} cores, ${cpus()[0]?.model ?? '?'}, load ${loadavg()[0].toFixed(2)}`);
console.log('');
if (FIT) await fitTable(path);
if (FEET) await footPointTable(path);

async function footPointTable(path) {
  const rows = await wasmFootPoints(readFileSync(path));
  console.log('Foot points on the final surface of the model C fit, wasm in headless chromium, one thread');
  console.log(`(native: cargo bench --bench foot_points; load now ${loadavg()[0].toFixed(2)}):`);
  console.log('');
  console.log('| scheme | control points | points | fit s | cold M/s | warm M/s | warm ns each |');
  console.log('|---|---|---|---|---|---|---|');
  for (const r of rows) {
    console.log(
      `| ${r.scheme} | ${r.controlPoints} | ${r.points} | ${(r.setupMs / 1000).toFixed(2)} | ` +
        `${(r.cold / 1e6).toFixed(3)} | ${(r.warm / 1e6).toFixed(3)} | ${(1e9 / r.warm).toFixed(0)} |`,
    );
  }
  console.log('');
}

async function fitTable(path) {
  const wasm = await wasmFit(readFileSync(path));
  const native = nativeFit(path);
  const row = (name, r) =>
    `| ${name} | ${r.status} | ${r.iterations} | ${r.controlPoints} | ${r.eAvg.toFixed(5)} | ` +
    `${r.eMax.toFixed(5)} | ${r.eRms.toFixed(5)} | ${(r.setupMs / 1000).toFixed(2)} | ` +
    `${(r.fitMs / 1000).toFixed(2)} | ${((r.setupMs + r.fitMs) / 1000).toFixed(2)} |`;
  console.log('| build | status | iterations | control points | E_avg % | E_max % | E_rms % | setup s | fit s | total s |');
  console.log('|---|---|---|---|---|---|---|---|---|---|');
  console.log(row('wasm (headless chromium)', wasm));
  console.log(row('native (release)', native));
  const ratio = (wasm.setupMs + wasm.fitMs) / (native.setupMs + native.fitMs);
  console.log('');
  console.log(`wasm / native total time: ${ratio.toFixed(2)}x`);
  console.log('');
}
