// The fitting worker: owns a geofit `Fitter` and iterates it off the main thread. After every
// `run(budget)` slice (at least one iteration, at most ~40 ms of work when iterations are fast) it
// posts a frame: statistics, history, signed point errors, the limit mesh, the control-mesh edges
// and the error vectors, all as transferable typed arrays. Messages in: start, play, pause, step,
// export, clear. Messages out: frame, exported, error (each with the `generation` of the
// fit it belongs to, so that the page can drop what an older fit sent).
import init, { Fitter, loadFile } from '../pkg/geofit.js';

const SLICE_MS = 40;
const LIMIT_RESOLUTION = 3;

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
  const limit = fitter.limitMesh(LIMIT_RESOLUTION);
  const control = fitter.controlMesh();
  const frame = {
    type: 'frame',
    kind,
    generation,
    playing,
    stats: fitter.stats(),
    history: fitter.history(),
    errors: fitter.pointErrors(),
    limit: { positions: limit.positions, normals: limit.normals, indices: limit.indices },
    control: { positions: control.positions, edges: control.edges },
    vectors: fitter.errorVectors(),
  };
  // The data points (in the order of `errors`) travel once per fit.
  if (kind === 'start') frame.data = fitter.dataPositions();
  limit.free();
  control.free();
  const transfer = [
    frame.errors.buffer, frame.limit.positions.buffer, frame.limit.normals.buffer,
    frame.limit.indices.buffer, frame.control.positions.buffer, frame.control.edges.buffer,
    frame.vectors.buffer,
  ];
  if (frame.data) transfer.push(frame.data.buffer);
  postMessage(frame, transfer);
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
