import type { ExportName, FitReport, FitSpec, FitStats, Phase } from './geofit.js';

/** A shape for drawing: `x, y, z` per vertex (f32), smooth normals (empty for a curve), three indices per triangle (empty for a curve), two per polygon edge or curve segment. */
export interface MeshData {
  positions: Float32Array;
  normals: Float32Array;
  indices: Uint32Array;
  edges: Uint32Array;
}

/** What `onProgress` gets after every slice of the fit: the statistics and the limit surface (or curve) now. Its arrays were transferred from the worker, not copied: keep them. */
export interface FitFrame {
  type: 'frame';
  stats: FitStats;
  limit: MeshData;
}

/** What `fitInWorker` resolves to once the fit has stopped (converged, iteration cap, stalled). */
export interface FitResult {
  stats: FitStats;
  /** The fit report: set-up, final errors, times, history. */
  report: FitReport;
  /** The fitted surface at `resolution` segments per patch edge, or the curve. */
  limit: MeshData;
  /** The final control net (`edges`: its polygon edges). */
  control: MeshData;
  /** The bytes of each export asked for in `options.exports`. */
  exports: Partial<Record<ExportName, Uint8Array>>;
}

export interface FitInWorkerOptions {
  /** Called with a frame after every slice while the fit runs. */
  onProgress?: (frame: FitFrame) => void;
  /** Called as the worker reads the file, sets the fit up and iterates: the phase and how far it is (0 to 1), at most one call per 50 ms within a phase (see `ProgressCallback`). */
  onPhase?: (phase: Phase, done: number) => void;
  /** Aborting it terminates the worker; the promise rejects with `signal.reason` (an `AbortError` `DOMException` unless another reason was given). */
  signal?: AbortSignal;
  /** Milliseconds of fitting between frames (at least one iteration each) [40]. */
  sliceMs?: number;
  /** Segments per patch edge of the frames' and result's limit surface, 1..=64 [3]. */
  resolution?: number;
  /** Exports to make at the end (`exportsFor(scheme)` lists a scheme's) [none]. */
  exports?: ExportName[];
}

/**
 * Fits the file `fileBytes` (called `name`, which hints its format) with `spec` in a module
 * worker, and resolves with the result once the fit stops. `fileBytes` is transferred to the
 * worker (a `Uint8Array` over an `ArrayBuffer` is detached; pass a copy to keep it). Rejects
 * with an `Error` carrying the core's message when the file cannot be read or the spec is bad,
 * and with `signal.reason` when `signal` aborts.
 */
export function fitInWorker(
  fileBytes: Uint8Array | ArrayBuffer,
  name: string,
  spec?: FitSpec,
  options?: FitInWorkerOptions,
): Promise<FitResult>;

/** The message `fitInWorker` sends its worker. */
export interface WorkerRequest {
  bytes: Uint8Array;
  name: string;
  spec: FitSpec;
  sliceMs: number;
  resolution: number;
  exports: ExportName[];
}

/** The messages the worker sends back. */
export type WorkerMessage =
  | FitFrame
  | { type: 'phase'; phase: Phase; done: number }
  | { type: 'done'; result: FitResult }
  | { type: 'error'; message: string };
