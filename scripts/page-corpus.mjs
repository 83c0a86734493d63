// Drops every mesh of ../shared/data and its corpus on a fresh page (headless chromium,
// WebGL2), picks each subdivision scheme and touches nothing else, presses Play and prints a
// Markdown row: file, scheme, status, iterations, control points, E_max %, E_back max %, seconds,
// page errors. The page's side of `cargo test --release --test corpus` (see docs/subdivision.md).
// With `--points`, each mesh's vertices are dropped instead, as an XYZ point file (the corpus
// test's `*-points.xyz`), so the page reconstructs and fits bare points.
// Usage: node scripts/page-corpus.mjs [--points]   (after bash scripts/build-wasm.sh)
import { readFileSync, readdirSync } from 'node:fs';
import { join } from 'node:path';
import { startServer } from './serve.mjs';
import { BACKENDS, dataDir, launch } from '../tests/e2e/helpers.mjs';

const data = dataDir();
const files = [
  ...readdirSync(data).filter((f) => (process.argv.includes('--points') ? /\.obj$/ : /\.(obj|ply)$/).test(f)),
  ...readdirSync(join(data, 'corpus')).filter((f) => f.endsWith('.obj')).map((f) => `corpus/${f}`),
];
const points = process.argv.includes('--points');

/// The file as dropped: the mesh itself, or its vertices as XYZ lines.
function dropped(file) {
  const text = readFileSync(join(data, file));
  const stem = file.split('/').pop();
  if (!points) return { name: stem, buffer: text };
  const xyz = text.toString('latin1').split('\n').filter((l) => l.startsWith('v ')).map((l) => l.slice(2).trim()).join('\n');
  return { name: stem.replace(/\.\w+$/, '-points.xyz'), buffer: Buffer.from(xyz + '\n') };
}

const { server, url } = await startServer(0);
const browser = await launch(BACKENDS[0]);
for (const file of files) {
  for (const scheme of ['loop', 'catmull-clark', 'doo-sabin']) {
    if (/stanford-bunny|bun000/.test(file) && scheme !== 'loop') continue;
    const page = await browser.newPage();
    const errors = [];
    page.on('pageerror', (e) => errors.push(e.message));
    await page.goto(url);
    await page.waitForSelector('body[data-state="ready"][data-fit="idle"]', { timeout: 120000 });
    const drop = dropped(file);
    await page.setInputFiles('#file', { name: drop.name, mimeType: 'application/octet-stream', buffer: drop.buffer });
    await page.waitForFunction((n) => document.getElementById('file-name').textContent === n, drop.name, { timeout: 120000 });
    await page.waitForSelector('body[data-fit="idle"]', { timeout: 120000 });
    if (scheme !== 'loop') await page.selectOption('#fit-scheme', scheme);
    const t0 = Date.now();
    await page.click('#fit-play');
    await page.waitForSelector('body[data-fit="converged"], body[data-fit="max_iterations"], body[data-fit="stalled"]', { timeout: 600000 });
    const s = await page.evaluate(() => window.geofitFit.lastStats);
    console.log(`| ${drop.name} | ${scheme} | ${s.status} | ${s.iter} | ${s.controlPoints} | ${s.eMaxPct.toFixed(3)} | ${s.eBackMaxPct == null ? '—' : s.eBackMaxPct.toFixed(3)} | ${((Date.now() - t0) / 1000).toFixed(1)} | ${errors.join('; ')} |`);
    await page.close();
  }
}
await browser.close();
server.close();
