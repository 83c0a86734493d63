// The fitting worker: owns a geofit `Fitter` and iterates it off the main thread. After every
// `run(budget)` slice (at least one iteration, at most ~40 ms of work when iterations are fast) it
// posts a frame: statistics, history, signed point errors, the limit mesh (or curve), the
// control-net edges, the error vectors and iso-parameter lines, all as transferable typed arrays.
// Messages in: start, play, pause, step, export, clear. Messages out: frame, exported, error
// (each with the `generation` of the fit it belongs to, so that the page can drop what an older
// fit sent).
import init, { Fitter, loadFile } from '../pkg/geofit.js';

const SLICE_MS = 40;
// Segments per patch edge of the drawn limit surface: fewer while the fit runs (a frame every
// slice) than when it stands still, and lowered while the tessellation has more than
// MAX_TRIANGLES (Doo–Sabin, refined cages), so that the page's uploads per frame stay small.
const LIMIT_RESOLUTION = 3;
const RUNNING_RESOLUTION = 2;
const MAX_TRIANGLES = 40_000;
let resolution = LIMIT_RESOLUTION;

let fitter = null;
let playing = false;
let generation = 0;
const ready = init();

function fail(error, during) {
  playing = false;
  postMessage({ type: 'error', during, generation, message: String(error?.message ?? error) });
}

/** Posts the current state of the fit; typed arrays move to the main thread without copying. */
function postFrame(kind) {
  const running = playing && fitter.stats().status === 'running';
  let limit = fitter.limitMesh(running ? Math.min(resolution, RUNNING_RESOLUTION) : resolution);
  while (limit.indices.length > 3 * MAX_TRIANGLES && resolution > 1) {
    limit.free();
    resolution -= 1;
    limit = fitter.limitMesh(resolution);
  }
  const control = fitter.controlMesh();
  const frame = {
    type: 'frame',
    kind,
    generation,
    playing,
    stats: fitter.stats(),
    history: fitter.history(),
    errors: fitter.pointErrors(),
    limit: { positions: limit.positions, normals: limit.normals, indices: limit.indices, edges: limit.edges },
    control: { positions: control.positions, edges: control.edges },
    vectors: fitter.errorVectors(),
    iso: fitter.isoLines(resolution),
  };
  limit.free();
  control.free();
  const transfer = [
    frame.errors, frame.limit.positions, frame.limit.normals, frame.limit.indices, frame.limit.edges,
    frame.control.positions, frame.control.edges, frame.vectors, frame.iso,
  ];
  // Sent once per fit: the data points (in the order of `errors`) and the initial control net.
  if (kind === 'start') {
    const initial = fitter.initialMesh();
    frame.once = { data: fitter.dataPositions(), initial: { positions: initial.positions, edges: initial.edges } };
    initial.free();
    transfer.push(frame.once.data, frame.once.initial.positions, frame.once.initial.edges);
  }
  postMessage(frame, transfer.map((a) => a.buffer));
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
  postFrame('play');
  if (playing) setTimeout(() => play(gen), 0);
}

const handlers = {
  start({ generation: gen, bytes, name, options }) {
    handlers.clear({ generation: gen });
    const scan = loadFile(bytes, name);
    try {
      fitter = new Fitter(scan, options);
    } finally {
      scan.free();
    }
    postFrame('start');
  },
  clear({ generation: gen }) {
    playing = false;
    resolution = LIMIT_RESOLUTION;
    generation = gen ?? generation + 1;
    fitter?.free();
    fitter = null;
  },
  play() {
    if (!fitter || playing) return;
    playing = true;
    play(generation);
  },
  pause() {
    playing = false;
    if (fitter) postFrame('pause');
  },
  step() {
    if (!fitter) return;
    playing = false;
    fitter.step();
    postFrame('step');
  },
  export({ what }) {
    if (!fitter) throw new Error('nothing is fitted yet');
    const make = {
      cage: () => fitter.exportCage(),
      obj: () => fitter.exportObj(),
      ply: () => fitter.exportPly(),
      stl: () => fitter.exportStl(),
      iges: () => fitter.exportIges(),
      step: () => fitter.exportStep(),
      json: () => new TextEncoder().encode(fitter.reportJson()),
    }[what];
    if (!make) throw new Error(`unknown export '${what}'`);
    const bytes = make();
    postMessage({ type: 'exported', what, bytes }, [bytes.buffer]);
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
