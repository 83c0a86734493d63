// @ts-check
// The messages between the page (fit-ui.js) and the fitting worker (fit-worker.js), in one
// place. Every message carries the `generation` of the fit it belongs to, so the page drops
// what an older fit sent. Bulk data travel as transferable typed arrays.

/** @typedef {import('../pkg/geofit.js').Fitter} Fitter */

/**
 * Page → worker.
 * @typedef {{ type: 'load', seq: number, file: Blob, name: string, quiet?: boolean }} LoadMessage
 *   Read and parse `file` (called `name`): the worker keeps the scan for the fits it builds and
 *   answers with `loaded` (a failed read leaves the previous scan and its fit in place).
 *   `quiet`: a new worker re-reading the page's scan after Cancel (no fit to clear, no reply
 *   but errors).
 * @typedef {{ type: 'start', generation: number, spec: import('../pkg/geofit.js').FitSpec }} StartMessage
 *   Build a fit of the loaded scan with the options object `spec` (the core's FitSpec,
 *   camelCase; left-out fields take the core's defaults).
 * @typedef {{ type: 'play' | 'pause' | 'step' }} DriveMessage
 *   Iterate in slices until stopped or paused; stop; one iteration.
 * @typedef {{ type: 'export', what: string }} ExportMessage
 *   Export the fit (`what` from `exportsFor(scheme)`).
 * @typedef {{ type: 'clear', generation: number }} ClearMessage
 *   Forget the fit (a new file was loaded).
 * @typedef {{ type: 'view', distances: boolean }} ViewMessage
 *   Whether frames carry the surface's distances to the data (to colour the surface by them).
 * @typedef {{ type: 'points', all: boolean }} PointsMessage
 *   Whether every data point is drawn, or a subsample within POINT_BUDGET; answered with a
 *   `loaded` message (no fit) or a frame carrying `once` (a fit).
 * @typedef {LoadMessage | StartMessage | DriveMessage | ExportMessage | ClearMessage | ViewMessage | PointsMessage} ToWorker
 */

/**
 * Worker → page.
 * @typedef {{ positions: Float32Array, normals: Float32Array, indices: Uint32Array, edges: Uint32Array }} Shape
 * @typedef {{
 *   type: 'frame', kind: 'start' | 'play' | 'pause' | 'step', generation: number, playing: boolean,
 *   stats: import('../pkg/geofit.js').FitStats, history: import('../pkg/geofit.js').HistoryEntry[], errors: Float32Array,
 *   deviation: import('../pkg/geofit.js').Deviation,
 *   limit: Shape, untrimmed: { normals: Float32Array, indices: Uint32Array } | null,
 *   control: { positions: Float32Array, edges: Uint32Array, creases: Uint32Array },
 *   vectors: Float32Array, iso: Float32Array, creaseCurves: Float32Array, distances: Float32Array | null,
 *   once?: { data: Float32Array, stride: number, initial: { positions: Float32Array, edges: Uint32Array, creases: Uint32Array }, dataCreases: Float32Array, notes: string[] },
 * }} FrameMessage
 *   The state of the fit after a slice (`errors` of every `once.stride`-th data point, as
 *   `once.data` holds them; `limit` a B-spline surface cut to the data's outline,
 *   `untrimmed` its whole tessellation over the same positions); `once` (data points, initial control net and what was
 *   done to the data on intake) only on the first frame of a fit; `distances` (per vertex of `limit`,
 *   model units, −1 over a hole of the data; empty when the fit measures none) only while the page
 *   asked for them with a `view` message, and not on every frame of a running fit.
 * @typedef {{
 *   type: 'loaded', seq: number, name: string, numPoints: number, numTriangles: number, strays: Uint32Array,
 *   diagonal: number, points: Float32Array, stride: number,
 *   mesh: { positions: Float32Array, normals: Float32Array, indices: Uint32Array } | null,
 * }} LoadedMessage
 *   A file parsed: its counts, the points to draw (every `stride`-th of the file's, strays left
 *   out) and its triangles (all of them), when it has any.
 * @typedef {{ type: 'progress', phase: import('../pkg/geofit.js').Phase, done: number }} ProgressMessage
 *   How far the work under way is: a phase of reading a file, of a fit's set-up, or an
 *   iteration, `done` from 0 to 1 (at most one message per PROGRESS_MS but at a phase change).
 * @typedef {{ type: 'exported', what: string, bytes: Uint8Array, quality?: import('../pkg/geofit.js').FemQuality }} ExportedMessage
 *   An export's bytes; `quality` for the FEM mesh (`msh`).
 * @typedef {{ type: 'error', during: string, generation: number, message: string }} ErrorMessage
 * @typedef {FrameMessage | LoadedMessage | ProgressMessage | ExportedMessage | ErrorMessage} FromWorker
 */

/**
 * Data points drawn at most, unless the page asks for all: a bigger scan is drawn (and its
 * per-point errors sent with every frame) as every k-th point. 300K points cost SwiftShader
 * (the tests' renderer) about as much to draw as a frame's surface, and a frame's errors stay
 * near a megabyte; the fit itself always uses every point.
 */
export const POINT_BUDGET = 300_000;

/** The worker's least interval between two progress messages of one phase (ms). */
export const PROGRESS_MS = 50;

/** The message types, so neither side spells them twice. */
export const MSG = Object.freeze({
  load: 'load',
  loaded: 'loaded',
  progress: 'progress',
  points: 'points',
  start: 'start',
  play: 'play',
  pause: 'pause',
  step: 'step',
  export: 'export',
  clear: 'clear',
  view: 'view',
  frame: 'frame',
  exported: 'exported',
  error: 'error',
});

/**
 * The typed arrays of a frame, to transfer instead of copying.
 * @param {FrameMessage} frame
 * @returns {Transferable[]}
 */
export function frameTransfers(frame) {
  const arrays = [
    frame.errors, frame.limit.positions, frame.limit.normals, frame.limit.indices, frame.limit.edges,
    frame.control.positions, frame.control.edges, frame.vectors, frame.iso,
  ];
  if (frame.distances) arrays.push(frame.distances);
  if (frame.untrimmed) arrays.push(frame.untrimmed.normals, frame.untrimmed.indices);
  if (frame.once) arrays.push(frame.once.data, frame.once.initial.positions, frame.once.initial.edges);
  return arrays.map((a) => /** @type {ArrayBuffer} */ (a.buffer));
}

/**
 * The typed arrays of a `loaded` message, to transfer instead of copying.
 * @param {LoadedMessage} loaded
 * @returns {Transferable[]}
 */
export function loadedTransfers(loaded) {
  const arrays = [loaded.points, loaded.strays];
  if (loaded.mesh) arrays.push(loaded.mesh.positions, loaded.mesh.normals, loaded.mesh.indices);
  return arrays.map((a) => /** @type {ArrayBuffer} */ (a.buffer));
}
