// @ts-check
// The fitting worker: owns a geofit `Fitter` and iterates it off the main thread. After every
// `run(budget)` slice (at least one iteration, at most ~40 ms of work when iterations are fast) it
// posts a frame (see protocol.js): statistics, history, signed point errors and their
// distribution (figures and histogram), the limit mesh (or
// curve), the control-net edges, the error vectors and iso-parameter lines, all as transferable
// typed arrays. While the page colours the surface by its distance to the data, frames also carry
// those distances, measured on every frame of a fit that stands still and, while it runs, only as
// often as keeps them under a tenth of the worker's time.
import init, { Fitter, loadFile } from '../pkg/geofit.js';
import { MSG, frameTransfers } from './protocol.js';

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

/** @type {Fitter | null} */
let fitter = null;
let playing = false;
/** The worker's postMessage (the DOM typings describe the window's). */
const post = /** @type {(message: unknown, transfer?: Transferable[]) => void} */ (/** @type {unknown} */ (postMessage));
let generation = 0;
const ready = init();

function fail(error, during) {
  playing = false;
  post({ type: MSG.error, during, generation, message: String(error?.message ?? error) });
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
  if (kind === 'start') {
    const initial = f.initialMesh();
    frame.once = {
      data: f.dataPositions(),
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
    stats = fitter.run(SLICE_MS);
  } catch (e) {
    fail(e, 'iteration');
    return;
  }
  if (stats.status !== 'running') playing = false;
  postFrame(fitter, 'play');
  if (playing) setTimeout(() => play(gen), 0);
}

const handlers = {
  [MSG.start]({ generation: gen, bytes, name, spec }) {
    handlers[MSG.clear]({ generation: gen });
    const scan = loadFile(bytes, name);
    try {
      fitter = new Fitter(scan, spec);
    } finally {
      scan.free();
    }
    postFrame(fitter, 'start');
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
    fitter.step();
    postFrame(fitter, 'step');
  },
  [MSG.export]({ what }) {
    if (!fitter) throw new Error('nothing is fitted yet');
    // The FEM export also reports its element quality.
    const { bytes, quality } = what === 'msh'
      ? fitter.exportFem({ format: 'msh' })
      : { bytes: fitter.exportAs(what), quality: undefined };
    post({ type: MSG.exported, what, bytes, quality }, [bytes.buffer]);
  },
};

onmessage = async (event) => {
  await ready;
  const message = event.data;
  try {
    handlers[message.type](message);
  } catch (e) {
    fail(e, message.type);
  }
};
