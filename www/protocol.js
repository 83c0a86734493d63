// @ts-check
// The messages between the page (fit-ui.js) and the fitting worker (fit-worker.js), in one
// place. Every message carries the `generation` of the fit it belongs to, so the page drops
// what an older fit sent. Bulk data travel as transferable typed arrays.

/** @typedef {import('../pkg/geofit.js').Fitter} Fitter */

/**
 * Page → worker.
 * @typedef {{ type: 'start', generation: number, bytes: Uint8Array, name: string, spec: import('../pkg/geofit.js').FitSpec }} StartMessage
 *   Read `bytes` (a file called `name`) and build a fit with the options object `spec` (the
 *   core's FitSpec, camelCase; left-out fields take the core's defaults).
 * @typedef {{ type: 'play' | 'pause' | 'step' }} DriveMessage
 *   Iterate in slices until stopped or paused; stop; one iteration.
 * @typedef {{ type: 'export', what: string }} ExportMessage
 *   Export the fit (`what` from `exportsFor(scheme)`).
 * @typedef {{ type: 'clear', generation: number }} ClearMessage
 *   Forget the fit (a new file was loaded).
 * @typedef {{ type: 'view', distances: boolean }} ViewMessage
 *   Whether frames carry the surface's distances to the data (to colour the surface by them).
 * @typedef {StartMessage | DriveMessage | ExportMessage | ClearMessage | ViewMessage} ToWorker
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
 *   once?: { data: Float32Array, initial: { positions: Float32Array, edges: Uint32Array, creases: Uint32Array }, dataCreases: Float32Array, notes: string[] },
 * }} FrameMessage
 *   The state of the fit after a slice (`limit` a B-spline surface cut to the data's outline,
 *   `untrimmed` its whole tessellation over the same positions); `once` (data points, initial control net and what was
 *   done to the data on intake) only on the first frame of a fit; `distances` (per vertex of `limit`,
 *   model units, −1 over a hole of the data; empty when the fit measures none) only while the page
 *   asked for them with a `view` message, and not on every frame of a running fit.
 * @typedef {{ type: 'exported', what: string, bytes: Uint8Array, quality?: import('../pkg/geofit.js').FemQuality }} ExportedMessage
 *   An export's bytes; `quality` for the FEM mesh (`msh`).
 * @typedef {{ type: 'error', during: string, generation: number, message: string }} ErrorMessage
 * @typedef {FrameMessage | ExportedMessage | ErrorMessage} FromWorker
 */

/** The message types, so neither side spells them twice. */
export const MSG = Object.freeze({
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
