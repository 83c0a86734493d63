// @ts-check
// The fitting worker: reads and parses the page's file once and keeps it (`LoadedScan`), owns a
// geofit `Fitter` of it and iterates it off the main thread, posting the progress of every
// long call (reading, repair, reconstruction, QEM, set-up, iterations). After every
// `run(budget)` slice (at least one iteration, at most ~40 ms of work when iterations are fast) it
// posts a frame (see protocol.js): statistics, history, signed point errors and their
// distribution (figures and histogram), the limit mesh (or
// curve), the control-net edges, the error vectors and iso-parameter lines, all as transferable
// typed arrays. While the page colours the surface by its distance to the data, frames also carry
// those distances, measured on every frame of a fit that stands still and, while it runs, only as
// often as keeps them under a tenth of the worker's time.
import init, { Fitter, loadFile } from '../pkg/geofit.js';
import { deviationCsv } from './fit-view.js';
import { MSG, POINT_BUDGET, PROGRESS_MS, frameTransfers, loadedTransfers } from './protocol.js';

const SLICE_MS = 40;
// Segments per patch edge of the drawn limit surface: fewer while the fit runs (a frame every
// slice) than when it stands still, and lowered while the tessellation has more than
// MAX_TRIANGLES (Doo–Sabin, refined cages), so that the page's uploads per frame stay small.
const LIMIT_RESOLUTION = 3;
const RUNNING_RESOLUTION = 2;
const MAX_TRIANGLES = 40_000;
// Bins of the deviation histogram the page draws.
const HISTOGRAM_BINS = 64;
let resolution = LIMIT_RESOLUTION;
// While running, the surface's distances are measured again only when DISTANCE_DUTY times their
// last cost has passed since (bun000's B-spline surface: ~85K vertices, a quarter second).
const DISTANCE_DUTY = 10;
/** Whether the page wants the surface's distances to the data, and when and at what cost (ms) they were last measured. */
const distances = { wanted: false, at: -Infinity, ms: 0 };

/** The share of the reading phase that fetching the file's bytes takes (parsing: the rest). */
const FETCH_SHARE = 0.3;

/** The loaded file and its name. @type {import('../pkg/geofit.js').LoadedScan | null} */
let scan = null;
let scanName = '';
/** Whether every data point is drawn (else at most POINT_BUDGET). */
let allPoints = false;
/** A fit's frames carry `once` again (the drawn points changed). */
let onceAgain = false;
/** @type {Fitter | null} */
let fitter = null;
let playing = false;
/** The worker's postMessage (the DOM typings describe the window's). */
const post = /** @type {(message: unknown, transfer?: Transferable[]) => void} */ (/** @type {unknown} */ (postMessage));
let generation = 0;
const ready = init();

function fail(error, during) {
  if (during !== MSG.load) playing = false;
  post({ type: MSG.error, during, generation, message: String(error?.message ?? error) });
}

/** The last progress posted: its phase and time. */
const lastProgress = { phase: '', at: -Infinity };

/**
 * Posts how far the work under way is; `onProgress` of the core's calls. Thinned to one
 * message per PROGRESS_MS within a phase (fast iterations report many times a slice).
 * @param {import('../pkg/geofit.js').Phase} phase
 * @param {number} done
 */
function progress(phase, done) {
  const now = performance.now();
  if (phase === lastProgress.phase && now - lastProgress.at < PROGRESS_MS && done < 1) return;
  Object.assign(lastProgress, { phase, at: now });
  post({ type: MSG.progress, phase, done });
}

/** Every `stride`-th point (xyz triples) of `positions`, or `positions` itself. */
function everyNth(positions, stride, width = 3) {
  if (stride === 1) return positions;
  const n = Math.ceil(positions.length / width / stride);
  const out = new Float32Array(n * width);
  for (let i = 0; i < n; i += 1) {
    for (let c = 0; c < width; c += 1) out[i * width + c] = positions[i * stride * width + c];
  }
  return out;
}

/** The stride of the drawn points among `n`. */
function strideFor(n) {
  return allPoints ? 1 : Math.max(1, Math.ceil(n / POINT_BUDGET));
}

/**
 * Reads `file` with progress (the first FETCH_SHARE of the reading phase).
 * @param {Blob} file
 */
async function readBytes(file) {
  const bytes = new Uint8Array(file.size);
  const reader = file.stream().getReader();
  let at = 0;
  for (;;) {
    const { done, value } = await reader.read();
    if (done) break;
    bytes.set(value, at);
    at += value.length;
    progress('reading', (FETCH_SHARE * at) / Math.max(1, file.size));
  }
  return bytes;
}

/** Posts the loaded scan's figures and draw buffers. */
function postLoaded(seq) {
  if (!scan) return;
  const positions = scan.positions();
  const indices = scan.indices();
  const [lo, hi] = [scan.bboxMin(), scan.bboxMax()];
  const stride = strideFor(scan.numPoints);
  /** @type {import('./protocol.js').LoadedMessage} */
  const loaded = {
    type: MSG.loaded,
    seq,
    name: scanName,
    numPoints: scan.numPoints,
    numTriangles: scan.numTriangles,
    strays: scan.strays(),
    diagonal: lo.length === 3 ? Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) : 0,
    // A buffer is transferred once: the points get their own copy only when the mesh sends
    // the same positions.
    points: stride === 1 && indices.length > 0 ? positions.slice() : everyNth(positions, stride),
    stride,
    mesh: indices.length > 0 ? { positions, normals: scan.normals(), indices } : null,
  };
  post(loaded, loadedTransfers(loaded));
}

/**
 * Posts the current state of the fit; typed arrays move to the main thread without copying.
 * @param {Fitter} f
 * @param {'start' | 'play' | 'pause' | 'step'} kind
 */
function postFrame(f, kind) {
  const running = playing && f.stats().status === 'running';
  let limit = f.limitMesh(running ? Math.min(resolution, RUNNING_RESOLUTION) : resolution);
  while (limit.indices.length > 3 * MAX_TRIANGLES && resolution > 1) {
    limit.free();
    resolution -= 1;
    limit = f.limitMesh(resolution);
  }
  // A B-spline surface is drawn cut to the data's outline; the whole surface (same points)
  // comes along for the page's "untrimmed" toggle.
  let untrimmed = null;
  if (f.stats().scheme === 'bspline-surface') {
    const whole = f.limitMesh(resolution, true);
    untrimmed = { normals: whole.normals, indices: whole.indices };
    whole.free();
  }
  const control = f.controlMesh();
  const now = performance.now();
  let surfaceDistances = null;
  if (distances.wanted && (!running || now - distances.at >= DISTANCE_DUTY * distances.ms)) {
    surfaceDistances = f.surfaceDistances(limit.positions);
    distances.at = performance.now();
    distances.ms = distances.at - now;
  }
  /** @type {import('./protocol.js').FrameMessage} */
  const frame = {
    type: MSG.frame,
    kind,
    generation,
    playing,
    stats: f.stats(),
    history: f.history(),
    errors: f.pointErrors(),
    deviation: f.deviations(HISTOGRAM_BINS),
    limit: { positions: limit.positions, normals: limit.normals, indices: limit.indices, edges: limit.edges },
    untrimmed,
    control: { positions: control.positions, edges: control.edges, creases: control.creases },
    vectors: f.errorVectors(),
    iso: f.isoLines(resolution),
    creaseCurves: f.creaseCurves(resolution),
    distances: surfaceDistances,
  };
  limit.free();
  control.free();
  // The fit's points (strays left out): one error each.
  const stride = strideFor(frame.errors.length);
  frame.errors = everyNth(frame.errors, stride, 1);
  if (kind === 'start' || onceAgain) {
    onceAgain = false;
    const initial = f.initialMesh();
    frame.once = {
      data: everyNth(f.dataPositions(), stride),
      stride,
      initial: { positions: initial.positions, edges: initial.edges, creases: initial.creases },
      dataCreases: f.dataCreases(),
      notes: f.intakeNotes(),
    };
    initial.free();
  }
  post(frame, frameTransfers(frame));
}

/** Iterates slice by slice while playing, yielding to the message queue between slices. */
function play(gen) {
  if (!fitter || !playing || gen !== generation) return;
  let stats;
  try {
    stats = fitter.run(SLICE_MS, progress);
  } catch (e) {
    fail(e, 'iteration');
    return;
  }
  if (stats.status !== 'running') playing = false;
  postFrame(fitter, 'play');
  if (playing) setTimeout(() => play(gen), 0);
}

const handlers = {
  async [MSG.load]({ seq, file, name, quiet }) {
    const bytes = await readBytes(file);
    const next = loadFile(bytes, name, (phase, done) => progress(phase, FETCH_SHARE + (1 - FETCH_SHARE) * done));
    scan?.free();
    scan = next;
    scanName = name;
    if (quiet) return;
    handlers[MSG.clear]({ generation: undefined });
    postLoaded(seq);
  },
  [MSG.start]({ generation: gen, spec }) {
    handlers[MSG.clear]({ generation: gen });
    if (!scan) throw new Error('no file is loaded');
    fitter = new Fitter(scan, spec, progress);
    postFrame(fitter, 'start');
  },
  [MSG.points]({ all }) {
    allPoints = all;
    if (fitter) {
      onceAgain = true;
      if (!playing) postFrame(fitter, 'pause');
    } else {
      postLoaded(-1);
    }
  },
  [MSG.clear]({ generation: gen }) {
    playing = false;
    resolution = LIMIT_RESOLUTION;
    generation = gen ?? generation + 1;
    fitter?.free();
    fitter = null;
  },
  [MSG.play]() {
    if (!fitter || playing) return;
    playing = true;
    play(generation);
  },
  [MSG.view]({ distances: wanted }) {
    distances.wanted = wanted;
    distances.at = -Infinity;
    if (fitter && !playing && wanted) postFrame(fitter, 'pause');
  },
  [MSG.pause]() {
    playing = false;
    if (fitter) postFrame(fitter, 'pause');
  },
  [MSG.step]() {
    if (!fitter) return;
    playing = false;
    fitter.step(progress);
    postFrame(fitter, 'step');
  },
  [MSG.export]({ what }) {
    if (!fitter) throw new Error('nothing is fitted yet');
    if (what === 'csv') {
      const text = deviationCsv(fitter.dataPositions(), fitter.pointErrors(), fitter.deviations(HISTOGRAM_BINS));
      const bytes = new TextEncoder().encode(text);
      post({ type: MSG.exported, what, bytes }, [bytes.buffer]);
      return;
    }
    // The FEM export also reports its element quality.
    const { bytes, quality } = what === 'msh'
      ? fitter.exportFem({ format: 'msh' })
      : { bytes: fitter.exportAs(what), quality: undefined };
    post({ type: MSG.exported, what, bytes, quality }, [bytes.buffer]);
  },
};

// Messages are handled one after the other: reading a file awaits its bytes, and a fit must
// not start on a half-read file.
/** @type {Promise<unknown>} */
let queue = ready;
onmessage = (event) => {
  const message = event.data;
  queue = queue.then(async () => {
    try {
      await handlers[message.type](message);
    } catch (e) {
      fail(e, message.type);
    }
  });
};
