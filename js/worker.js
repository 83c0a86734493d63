// @ts-check
// The worker behind `fitInWorker` (fit-in-worker.js): reads the file it is sent, fits it with the
// spec, and posts a frame (statistics and the limit mesh, typed arrays transferred) after every
// slice of `sliceMs`, then the result. It fits one file and is terminated by its caller, which is
// how a fit is cancelled. The wasm file is found beside geofit.js (`new URL(..., import.meta.url)`
// inside wasm-bindgen's init), which bundlers follow.
import init, { Fitter, loadFile } from './geofit.js';

/** @typedef {import('./fit-in-worker.js').MeshData} MeshData */
/** @typedef {import('./fit-in-worker.js').WorkerRequest} WorkerRequest */
/** @typedef {import('./fit-in-worker.js').WorkerMessage} WorkerMessage */

/** The worker's postMessage (the DOM typings describe the window's). */
const post = /** @type {(message: WorkerMessage, transfer?: Transferable[]) => void} */ (
  /** @type {unknown} */ (postMessage)
);

/**
 * A mesh handle's arrays, the handle freed.
 * @param {import('./geofit.js').MeshArrays} mesh
 * @returns {MeshData}
 */
function meshData(mesh) {
  const data = { positions: mesh.positions, normals: mesh.normals, indices: mesh.indices, edges: mesh.edges };
  mesh.free();
  return data;
}

/**
 * The buffers of `meshes`, to transfer instead of copying.
 * @param {MeshData[]} meshes
 * @returns {Transferable[]}
 */
function buffers(...meshes) {
  return meshes.flatMap((m) => [m.positions.buffer, m.normals.buffer, m.indices.buffer, m.edges.buffer]);
}

/**
 * Fits `request` to the end, posting frames; the fitter is freed whatever happens.
 * @param {WorkerRequest} request
 */
function fit({ bytes, name, spec, sliceMs, resolution, exports }) {
  const scan = loadFile(bytes, name, phase);
  let fitter;
  try {
    fitter = new Fitter(scan, spec, phase);
  } finally {
    scan.free();
  }
  try {
    let stats = fitter.stats();
    while (stats.status === 'running') {
      stats = fitter.run(sliceMs, phase);
      const limit = meshData(fitter.limitMesh(resolution));
      post({ type: 'frame', stats, limit }, buffers(limit));
    }
    const limit = meshData(fitter.limitMesh(resolution));
    const control = meshData(fitter.controlMesh());
    /** @type {Partial<Record<import('./geofit.js').ExportName, Uint8Array>>} */
    const files = {};
    for (const what of exports) files[what] = fitter.exportAs(what);
    const report = JSON.parse(fitter.reportJson());
    const transfer = [...buffers(limit, control), ...Object.values(files).map((b) => b.buffer)];
    post({ type: 'done', result: { stats, report, limit, control, exports: files } }, transfer);
  } finally {
    fitter.free();
  }
}

/** The last phase posted and when: one message per PHASE_MS within a phase. */
const PHASE_MS = 50;
const lastPhase = { phase: '', at: -Infinity };

/**
 * Posts how far the work is (the core's `onProgress`).
 * @param {import('./geofit.js').Phase} phase
 * @param {number} done
 */
function phase(phase, done) {
  const now = performance.now();
  if (phase === lastPhase.phase && now - lastPhase.at < PHASE_MS && done < 1) return;
  Object.assign(lastPhase, { phase, at: now });
  post({ type: 'phase', phase, done });
}

const ready = init();

onmessage = async (/** @type {MessageEvent<WorkerRequest>} */ event) => {
  try {
    await ready;
    fit(event.data);
  } catch (e) {
    post({ type: 'error', message: String(/** @type {Error} */ (e)?.message ?? e) });
  }
};
