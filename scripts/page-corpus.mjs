// Drops every mesh of ../shared/data and its corpus on a fresh page (headless chromium,
// WebGL2), picks each subdivision scheme and touches nothing else, presses Play and prints a
// Markdown row: file, scheme, status, iterations, control points, E_max %, E_back max %, seconds,
// page errors. The page's side of `cargo test --release --test corpus` (see docs/subdivision.md).
// Usage: node scripts/page-corpus.mjs   (after bash scripts/build-wasm.sh)
import { readFileSync, readdirSync } from 'node:fs';
import { join } from 'node:path';
import { startServer } from './serve.mjs';
import { BACKENDS, dataDir, launch } from '../tests/e2e/helpers.mjs';

const data = dataDir();
const files = [
  ...readdirSync(data).filter((f) => /\.(obj|ply)$/.test(f)),
  ...readdirSync(join(data, 'corpus')).filter((f) => f.endsWith('.obj')).map((f) => `corpus/${f}`),
];
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
    await page.setInputFiles('#file', { name: file.split('/').pop(), mimeType: 'application/octet-stream', buffer: readFileSync(join(data, file)) });
    await page.waitForFunction((n) => document.getElementById('file-name').textContent === n, file.split('/').pop(), { timeout: 120000 });
    await page.waitForSelector('body[data-fit="idle"]', { timeout: 120000 });
    if (scheme !== 'loop') await page.selectOption('#fit-scheme', scheme);
    const t0 = Date.now();
    await page.click('#fit-play');
    await page.waitForSelector('body[data-fit="converged"], body[data-fit="max_iterations"], body[data-fit="stalled"]', { timeout: 600000 });
    const s = await page.evaluate(() => window.geofitFit.lastStats);
    console.log(`| ${file} | ${scheme} | ${s.status} | ${s.iter} | ${s.controlPoints} | ${s.eMaxPct.toFixed(3)} | ${s.eBackMaxPct == null ? '—' : s.eBackMaxPct.toFixed(3)} | ${((Date.now() - t0) / 1000).toFixed(1)} | ${errors.join('; ')} |`);
    await page.close();
  }
}
await browser.close();
server.close();
