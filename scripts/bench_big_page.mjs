// The 2-million-point scan of scripts/bench_big.sh in headless chromium (issue 17, item 3: ≤ 60 s,
// wasm memory under 1.5 GB): the file is fetched, read by `loadFile`, fitted by `Fitter` with the
// defaults of SCHEME, all on the page's main thread (one thread, as scripts/bench_wasm.mjs does;
// not the demo page's worker and progress bar). Prints the seconds of each step and the wasm
// memory after it (a wasm memory only grows, so the last figure is its peak), with the load
// average before and after.
// Usage: bash scripts/build-wasm.sh && node scripts/bench_big_page.mjs [FILE] [SCHEME]
//        (FILE defaults to bench-results/bunny-loop3-noise.obj, which scripts/bench_big.sh makes;
//        SCHEME to loop). Needs Debian's /usr/bin/chromium.
import { existsSync } from 'node:fs';
import { cpus, loadavg } from 'node:os';
import { basename, dirname, join, relative } from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';
import { startServer } from './serve.mjs';

const ROOT = join(dirname(fileURLToPath(import.meta.url)), '..');
const file = process.argv[2] ?? join(ROOT, 'bench-results', 'bunny-loop3-noise.obj');
const scheme = process.argv[3] ?? 'loop';
if (!existsSync(file)) throw new Error(`${file} not found: run bash scripts/bench_big.sh first`);
const rel = relative(ROOT, file);
if (rel.startsWith('..')) throw new Error(`${file}: must be inside the repository (bench-results/)`);
const load = () => loadavg().map((l) => l.toFixed(2)).join(' ');

console.log(`machine: ${cpus().length} cores, ${cpus()[0]?.model ?? '?'}; load ${load()} at the start`);
const { server, url } = await startServer(0, { served: ['www', 'pkg', dirname(rel)] });
const browser = await chromium.launch({
  executablePath: '/usr/bin/chromium',
  headless: true,
  args: ['--no-sandbox', '--no-first-run', '--disable-background-networking'],
});
let result;
try {
  const page = await browser.newPage();
  await page.goto(new URL('bench-blank', url).href);
  result = await page.evaluate(
    async ({ path, name, scheme }) => {
      const m = await import('/pkg/geofit.js');
      const wasm = await m.default();
      const mb = () => wasm.memory.buffer.byteLength / 1e6;
      const steps = [];
      let t = performance.now();
      const step = (what) => {
        const now = performance.now();
        steps.push({ what, s: (now - t) / 1000, wasmMb: mb() });
        t = now;
      };
      const bytes = new Uint8Array(await (await fetch(path)).arrayBuffer());
      step('fetch (not counted)');
      const start = performance.now();
      const scan = m.loadFile(bytes, name);
      step('loadFile');
      const fitter = new m.Fitter(scan, { scheme });
      step('Fitter (QEM, set-up, first foot points)');
      const s = fitter.run(1e12);
      step('run');
      const total = (performance.now() - start) / 1000;
      return { steps, total, stats: s, points: scan.numPoints ?? null };
    },
    { path: `/${rel}`, name: basename(file), scheme },
  );
} finally {
  await browser.close();
  server.close();
}
console.log(`file: ${rel}, scheme ${scheme}`);
console.log('');
console.log('| step | s | wasm memory MB after |');
console.log('|---|---|---|');
for (const s of result.steps) console.log(`| ${s.what} | ${s.s.toFixed(2)} | ${s.wasmMb.toFixed(0)} |`);
const st = result.stats;
console.log('');
console.log(
  `total (loadFile to the end of run) ${result.total.toFixed(2)} s; ${st.status} after ${st.iter} iterations, ` +
    `${st.controlPoints} control points, E_avg ${st.eAvgPct.toFixed(5)} %, E_max ${st.eMaxPct.toFixed(5)} %, ` +
    `E_back ${st.eBackMaxPct?.toFixed(4) ?? '—'} %`,
);
console.log(`load ${load()} at the end`);
