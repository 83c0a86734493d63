// A tiny static server for the demo: serves www/ and pkg/ from the repository root on 127.0.0.1,
// with the MIME types browsers insist on (application/wasm for streaming compilation, text/javascript
// for modules). Used by scripts/serve.sh and by the end-to-end tests (startServer on port 0).
import { createServer } from 'node:http';
import { readFile, stat } from 'node:fs/promises';
import { extname, join, normalize, sep, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';

const ROOT = join(dirname(fileURLToPath(import.meta.url)), '..');
const SERVED = ['www', 'pkg'];
const TYPES = {
  '.html': 'text/html; charset=utf-8',
  '.js': 'text/javascript; charset=utf-8',
  '.mjs': 'text/javascript; charset=utf-8',
  '.css': 'text/css; charset=utf-8',
  '.json': 'application/json',
  '.wasm': 'application/wasm',
  '.ts': 'text/plain; charset=utf-8',
  '.png': 'image/png',
  '.svg': 'image/svg+xml',
};

/** The file a URL path names, or null when it is outside the `served` folders of `root`. */
function resolve(urlPath, root, served) {
  let path;
  try {
    path = decodeURIComponent(urlPath.split('?')[0]);
  } catch {
    return null;
  }
  const rel = normalize(path).replace(/^[/\\]+/, '');
  if (!served.some((dir) => rel === dir || rel.startsWith(dir + sep))) return null;
  return join(root, rel);
}

async function handle(req, res, root, served) {
  if (req.url === '/' || req.url === '/index.html') {
    res.writeHead(302, { Location: '/www/' });
    res.end();
    return;
  }
  let file = resolve(req.url, root, served);
  try {
    if (file && (await stat(file)).isDirectory()) file = join(file, 'index.html');
    if (!file) throw new Error('outside the served folders');
    const body = await readFile(file);
    res.writeHead(200, {
      'Content-Type': TYPES[extname(file)] ?? 'application/octet-stream',
      'Cache-Control': 'no-cache',
    });
    res.end(body);
  } catch {
    res.writeHead(404, { 'Content-Type': 'text/plain' });
    res.end('not found\n');
  }
}

/**
 * Starts the server on 127.0.0.1:`port` (0: any free port) for the folders `served` of `root`
 * (the repository's www/ and pkg/ by default); resolves to { server, url } (url: the first folder).
 */
export function startServer(port = 0, { root = ROOT, served = SERVED } = {}) {
  return new Promise((resolvePromise, reject) => {
    const server = createServer((req, res) => {
      handle(req, res, root, served).catch(() => res.destroy());
    });
    server.once('error', reject);
    server.listen(port, '127.0.0.1', () => {
      const { port: actual } = server.address();
      resolvePromise({ server, url: `http://127.0.0.1:${actual}/${served[0]}/` });
    });
  });
}

if (process.argv[1] === fileURLToPath(import.meta.url)) {
  const port = Number.parseInt(process.env.PORT ?? '8080', 10);
  const { url } = await startServer(port);
  console.log(`geofit demo: ${url}`);
}
