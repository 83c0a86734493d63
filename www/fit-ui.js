// @ts-check
// The fitting panel: play / pause / step / reset, statistics, the convergence chart, the error
// colours, the view toggles of the fit (control net, error vectors, iso-parameter lines,
// initial mesh) and exports. The fit runs in fit-worker.js (messages in protocol.js); the
// options form is fit-form.js. This module turns the worker's frames into draw calls on the
// shared Viewer and into text, so no main-thread task grows with the fit.
//
// The panel is one object, `FitPanel`, in one of these states (shown as `body[data-fit]`):
//   loading   the worker reads and parses a file (the fit, if any, is paused; a file that cannot
//             be read leaves it as it was)
//   idle      a scan is loaded, no fit built (Play, Step and Reset build one)
//   building  the worker was asked to build a fit; its first frame moves on to paused/running
//   paused    a fit exists and does not iterate
//   running   the worker iterates slice by slice
//   converged, max_iterations, stalled   the fit stopped (Reset rebuilds it)
//   cancelled the fit or the file's loading was stopped by Cancel (the worker replaced, the
//             scan on screen read again in the background); like idle
//   error     the fit could not be built
import { MSG } from './protocol.js';
import { FitForm } from './fit-form.js';
import {
  CAGE_COLOR, CHART_CONTEXT, CREASE_COLOR, DATA_CREASE_COLOR, CURVE_COLOR, INITIAL_COLOR, ISO_COLOR, VECTOR_COLOR, drawChart,
  distanceColors, drawHistogram, edgeSegments, errorColors, fmtPct, fmtUnits, lineSet,
} from './fit-view.js';

export { drawChart, errorColors } from './fit-view.js';

// What each phase of the work is called in the progress line.
const PHASE_TEXT = {
  reading: 'Reading the file', repair: 'Repairing the mesh', reconstruction: 'Meshing the points',
  simplification: 'Simplifying (QEM)', setup: 'Setting up the fit',
};

// Download name and MIME type of each export.
const DOWNLOADS = {
  cage: ['geofit-cage.obj', 'model/obj'], obj: ['geofit-limit.obj', 'model/obj'],
  creases: ['geofit-cage.creases.json', 'application/json'], usda: ['geofit-cage.usda', 'model/vnd.usda'],
  ply: ['geofit-limit.ply', 'application/octet-stream'], stl: ['geofit-limit.stl', 'model/stl'],
  glb: ['geofit-surface.glb', 'model/gltf-binary'], csv: ['geofit-deviations.csv', 'text/csv'],
  iges: ['geofit.igs', 'model/iges'], step: ['geofit.stp', 'model/step'],
  msh: ['geofit-fem.msh', 'text/plain'], json: ['geofit-report.json', 'application/json'],
};
// CSS pixels around a click within which a data point is picked.
const PICK_RADIUS = 6;

/** The FEM export's quality line. @param {import('../pkg/geofit.js').FemQuality} q */
function femText(q) {
  return `FEM mesh: ${q.elements} quads, ${q.nodes} nodes; aspect ratio ${q.aspectMean.toFixed(2)} mean, `
    + `${q.aspectMax.toFixed(1)} max; skew max ${q.skewMaxDeg.toFixed(1)}°; scaled Jacobian min `
    + `${q.jacobianMin.toFixed(3)}; ${q.inverted} inverted (${q.inverted - q.invertedOffFolds} on folds of the surface)`;
}

const STATUS_TEXT = {
  building: 'building the control net…', paused: 'paused', running: 'fitting…',
  converged: 'converged: tolerances met', max_iterations: 'stopped: iteration cap reached',
  stalled: 'stalled: the errors stopped falling and the control budget is spent',
  error: 'error', loading: 'reading the file', idle: 'press Play or Step to fit', cancelled: 'cancelled: press Play or Step to fit again',
};

const el = (id) => /** @type {HTMLElement} */ (document.getElementById(id));

function download(bytes, name, type) {
  const url = URL.createObjectURL(new Blob([bytes], { type }));
  const a = document.createElement('a');
  a.href = url;
  a.download = name;
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 10_000);
}

/**
 * Keeps a tolerance's % and model-unit fields in step (the diagonal is the scan's).
 * @param {HTMLInputElement} pct
 * @param {HTMLInputElement} units
 * @param {() => number} diagonal
 * @param {() => void} edited
 */
function linkTolerance(pct, units, diagonal, edited) {
  const toUnits = () => {
    const d = diagonal();
    units.value = pct.value.trim() === '' || !(d > 0) ? '' : String(Number(((Number(pct.value) * d) / 100).toPrecision(4)));
  };
  pct.addEventListener('input', toUnits);
  units.addEventListener('input', () => {
    const d = diagonal();
    if (units.value.trim() !== '' && d > 0) {
      pct.value = String(Number(((Number(units.value) / d) * 100).toPrecision(4)));
      edited();
    }
  });
  return toUnits;
}

class FitPanel {
  constructor(host) {
    this.host = host;
    this.ui = {
      form: /** @type {HTMLFormElement} */ (el('fit-form')),
      tolAvg: /** @type {HTMLInputElement} */ (el('fit-tol-avg')), tolMax: /** @type {HTMLInputElement} */ (el('fit-tol-max')),
      tolAvgUnits: /** @type {HTMLInputElement} */ (el('fit-tol-avg-units')),
      tolMaxUnits: /** @type {HTMLInputElement} */ (el('fit-tol-max-units')),
      refine: /** @type {HTMLInputElement} */ (el('fit-refine')), maxControl: /** @type {HTMLInputElement} */ (el('fit-max-control')),
      play: el('fit-play'), step: el('fit-step'), reset: el('fit-reset'), cancel: el('fit-cancel'),
      vectors: /** @type {HTMLInputElement} */ (el('show-vectors')), cage: /** @type {HTMLInputElement} */ (el('show-cage')),
      backColors: /** @type {HTMLInputElement} */ (el('show-back')), backLegend: el('back-legend'), backLegendTol: el('back-legend-tol'),
      iso: /** @type {HTMLInputElement} */ (el('show-iso')), untrimmed: /** @type {HTMLInputElement} */ (el('show-untrimmed')), initialMesh: /** @type {HTMLInputElement} */ (el('show-initial')),
      chart: /** @type {HTMLCanvasElement} */ (el('fit-chart')),
      status: el('fit-status'), iter: el('fit-iter'), ctrl: el('fit-ctrl'), eAvg: el('fit-eavg'),
      eMax: el('fit-emax'), eRms: el('fit-erms'), eBack: el('fit-eback'), ms: el('fit-ms'), total: el('fit-total'),
      intake: el('fit-intake'),
      legendTol: el('legend-tol'), legendNeg: el('legend-neg'),
      histogram: /** @type {HTMLCanvasElement} */ (el('dev-histogram')),
      devMean: el('dev-mean'), devP50: el('dev-p50'), devP95: el('dev-p95'), devMax: el('dev-max'),
      devWithin: el('dev-within'), devCsv: /** @type {HTMLButtonElement} */ (el('dev-csv')),
      pickLabel: el('pick-label'),
      progressRow: el('fit-progress-row'), progress: /** @type {HTMLProgressElement} */ (el('fit-progress')), phase: el('fit-phase'),
      allPoints: /** @type {HTMLInputElement} */ (el('show-all-points')),
    };
    this.form = new FitForm(this.ui.form);
    this.worker = this.startWorker();
    /** The loaded scan: file (a Blob), name, diagonal. */
    this.scan = null;
    // The file being read, its request number and the promise's settlers; `seq` numbers the
    // load requests, so a reply to an older one is dropped.
    this.loading = null;
    this.seq = 0;
    this.state = 'idle';
    // generation: the fit the worker was last asked to build; frames of older fits are
    // dropped. built: the generation that has a fit (0: none for this scan).
    this.generation = 0;
    this.built = 0;
    this.playing = false;
    // The frame on screen, the newest not yet shown, and what a fit's first frame carries once
    // (data points in the order of the errors, initial control net).
    this.frame = null;
    this.pending = null;
    this.once = null;
    this.showing = false;
    // The newest distances of the surface's vertices to the data (see protocol.js), while the
    // surface is coloured by them.
    this.distances = null;
    // Figures the page and the tests read: the worker's latest statistics and history, frames
    // shown, the longest stage of showing one and the longest of each stage.
    // deviation: the latest frame's distribution of the errors (the package's `Deviation`).
    // phases: every progress phase heard since the page opened, in order, with the largest
    // share reported (the tests read it); drawnPoints: data points drawn.
    this.figures = { phases: [], drawnPoints: 0, lastStats: null, history: [], creaseEdges: 0, deviation: null, surfaceTriangles: 0, deviationMs: 0, chartMs: 0, frames: 0, maxStageMs: 0, stageMs: [0, 0, 0, 0] };
    this.tolUnits = [
      linkTolerance(this.ui.tolAvg, this.ui.tolAvgUnits, () => this.diagonal(), () => this.form.edited.add('tolAvg')),
      linkTolerance(this.ui.tolMax, this.ui.tolMaxUnits, () => this.diagonal(), () => this.form.edited.add('tolMax')),
    ];
    this.bind();
    // A browser may restore the checkbox checked: the worker must hear of it.
    if (this.ui.backColors.checked) this.backColorsChanged();
    this.go('idle');
  }

  diagonal() {
    return this.scan?.diagonal ?? 0;
  }

  /** Enters `state`: shows it in the status line, the Play button and `body[data-fit]`. */
  go(state) {
    this.state = state;
    document.body.dataset.fit = state;
    this.ui.status.textContent = STATUS_TEXT[state] ?? state;
    this.ui.play.textContent = state === 'running' ? 'Pause' : 'Play';
    this.ui.play.setAttribute('aria-pressed', String(state === 'running'));
    this.ui.cancel.hidden = !['loading', 'building', 'running'].includes(state);
    if (!['loading', 'building', 'running'].includes(state)) this.ui.progressRow.hidden = true;
  }

  /**
   * Shows a phase of the work under way and how far it is.
   * @param {import('../pkg/geofit.js').Phase} phase
   * @param {number} done
   */
  showProgress(phase, done) {
    const u = this.ui;
    if (!['loading', 'building', 'running'].includes(this.state)) return;
    const iter = (this.figures.lastStats?.iter ?? 0) + 1;
    const label = phase === 'iteration' ? `Iteration ${iter}` : PHASE_TEXT[phase] ?? phase;
    u.progress.value = done;
    u.phase.textContent = `${label}: ${Math.round(100 * done)} %`;
    u.progressRow.hidden = false;
    const seen = this.figures.phases;
    const last = seen[seen.length - 1];
    if (last?.phase === phase && done >= last.done) last.done = done;
    else seen.push({ phase, done });
  }

  /**
   * Has the worker read and parse `file` (a File or Blob called `name`); resolves with the
   * worker's `loaded` message once it is the page's scan (`preset`: the fit options of a
   * bundled sample), rejects with the reader's error (the previous scan and its fit stay),
   * with `{ superseded: true }` when a newer load overtakes it, or with `{ cancelled: true }`
   * when Cancel stops it (the previous scan stays).
   * @param {Blob} file
   * @param {string} name
   * @returns {Promise<import('./protocol.js').LoadedMessage>}
   */
  load(file, name, preset = {}) {
    this.loading?.reject({ superseded: true });
    if (this.playing) this.worker.postMessage({ type: MSG.pause });
    this.seq += 1;
    this.go('loading');
    this.worker.postMessage({ type: MSG.load, seq: this.seq, file, name });
    return new Promise((resolve, reject) => {
      this.loading = { seq: this.seq, file, name, preset, resolve, reject };
    });
  }

  /** The state a fit that is not running rests in: from its last frame, else idle. */
  resting() {
    if (!this.frame) return 'idle';
    const status = this.frame.stats.status;
    return status === 'running' ? 'paused' : status;
  }

  /** @param {import('./protocol.js').LoadedMessage} m */
  loaded(m) {
    this.figures.drawnPoints = m.points.length / 3;
    if (m.seq === -1) {
      this.host.showPoints?.(m);
      return;
    }
    const loading = this.loading;
    if (!loading || m.seq !== loading.seq) return;
    this.loading = null;
    this.scan = { file: loading.file, name: loading.name, diagonal: m.diagonal };
    this.form.apply(loading.preset);
    for (const update of this.tolUnits) update();
    this.clear();
    loading.resolve(m);
  }

  /** A fitting worker, its messages routed to this panel. */
  startWorker() {
    const worker = new Worker(new URL('./fit-worker.js', import.meta.url), { type: 'module' });
    worker.onmessage = ({ data }) => this.received(data);
    worker.onerror = (e) => {
      this.host.showError(`The fitting worker failed: ${e.message}`);
      this.go('error');
    };
    return worker;
  }

  /**
   * Stops the fit at once, whatever the worker is doing: the worker is replaced, since a
   * set-up (reading, repair, reconstruction, QEM of a big scan) runs inside one call that
   * cannot be interrupted. The scan stays loaded; Play or Step builds the fit again.
   */
  cancel() {
    this.worker.terminate();
    this.worker = this.startWorker();
    if (this.ui.backColors.checked) this.backColorsChanged();
    if (this.ui.allPoints.checked) this.allPointsChanged();
    this.loading?.reject({ cancelled: true });
    this.loading = null;
    // The new worker reads the scan on screen again, in the background.
    if (this.scan) {
      this.seq += 1;
      this.worker.postMessage({ type: MSG.load, seq: this.seq, file: this.scan.file, name: this.scan.name, quiet: true });
    }
    this.clear();
    this.go('cancelled');
  }

  /** The "all points" toggle: the worker sends every point, or a subsample within its budget. */
  allPointsChanged() {
    this.worker.postMessage({ type: MSG.points, all: this.ui.allPoints.checked });
  }

  /** Asks the worker for a new fit of the current scan with the form's options (iteration 0). */
  restart() {
    if (!this.scan) return;
    Object.assign(this, { playing: false, frame: null, pending: null, once: null, distances: null });
    this.generation += 1;
    this.built = this.generation;
    this.go('building');
    this.worker.postMessage({ type: MSG.start, generation: this.generation, spec: this.form.spec() });
  }

  /** Forgets the fit (a new scan was loaded): the page shows the scan until Play, Step or Reset. */
  clear() {
    this.generation += 1;
    Object.assign(this, { built: 0, playing: false, frame: null, pending: null, once: null, distances: null });
    this.worker.postMessage({ type: MSG.clear, generation: this.generation });
    Object.assign(this.figures, { lastStats: null, history: [], deviation: null, distanceColored: 0, distanceFar: 0 });
    const u = this.ui;
    for (const dd of [u.iter, u.ctrl, u.eAvg, u.eMax, u.eRms, u.eBack, u.ms, u.total, u.devMean, u.devP50, u.devP95, u.devMax, u.devWithin]) {
      dd.textContent = '—';
    }
    u.devCsv.disabled = true;
    u.pickLabel.hidden = true;
    const h = /** @type {CanvasRenderingContext2D | null} */ (u.histogram.getContext('2d', CHART_CONTEXT));
    h?.clearRect(0, 0, u.histogram.width, u.histogram.height);
    this.showIntake([]);
    delete document.body.dataset.fitIter;
    const g = /** @type {CanvasRenderingContext2D | null} */ (u.chart.getContext('2d', CHART_CONTEXT));
    g?.clearRect(0, 0, u.chart.width, u.chart.height);
    this.go('idle');
  }

  play() {
    if (!this.scan) return;
    if (this.playing) {
      this.worker.postMessage({ type: MSG.pause });
      return;
    }
    if (!this.built) this.restart();
    this.worker.postMessage({ type: MSG.play });
    this.playing = true;
    this.go('running');
  }

  step() {
    if (!this.scan) return;
    if (!this.built) this.restart();
    this.worker.postMessage({ type: MSG.step });
  }

  /** The E_max tolerance in model units: what the point colours and the legend show. */
  tolMaxUnits(stats) {
    return ((stats.tolMaxPct ?? 0) * stats.diagonal) / 100;
  }

  /** The surface → data distance (units) beyond which a surface strays from the data. */
  tolBackUnits(stats) {
    return ((stats.tolBackPct ?? 0) * stats.diagonal) / 100;
  }

  /** The line layer: fitted curve, control net, error vectors, iso lines, initial net. */
  lines() {
    const parts = [];
    const { limit, control } = this.frame;
    const u = this.ui;
    if (limit.indices.length === 0) parts.push([edgeSegments(limit.positions, limit.edges), CURVE_COLOR]);
    if (u.cage.checked) parts.push([edgeSegments(control.positions, control.edges), CAGE_COLOR]);
    // With creases on: the cage's crease edges when the cage is shown, their limit curves on the
    // surface, and the lines found on the data.
    if (u.cage.checked && control.creases.length > 0) parts.push([edgeSegments(control.positions, control.creases), CREASE_COLOR]);
    if (this.frame.creaseCurves.length > 0) parts.push([this.frame.creaseCurves, CREASE_COLOR]);
    if (this.once.dataCreases.length > 0) parts.push([this.once.dataCreases, DATA_CREASE_COLOR]);
    if (u.vectors.checked) parts.push([this.frame.vectors, VECTOR_COLOR]);
    if (u.iso.checked) parts.push([this.frame.iso, ISO_COLOR]);
    if (u.initialMesh.checked) parts.push([edgeSegments(this.once.initial.positions, this.once.initial.edges), INITIAL_COLOR]);
    return lineSet(parts);
  }

  drawPoints(viewer) {
    viewer.setPoints(this.once.data, errorColors(this.frame.errors, this.tolMaxUnits(this.frame.stats)));
    this.figures.drawnPoints = this.once.data.length / 3;
  }

  /**
   * The surface's vertex colours by distance to the data while that view is on and the newest
   * distances belong to a tessellation of the same size (a running fit measures them only
   * now and then: its surface moves little in between); else none (the clay colour). Counts
   * the vertices of the drawn `indices` that stray (`figures.distanceFar`).
   * @param {Uint32Array} indices
   */
  surfaceColors(indices) {
    const n = this.frame.limit.positions.length / 3;
    const d = this.distances;
    const on = this.ui.backColors.checked && d !== null && d.length === n && n > 0;
    const far = this.tolBackUnits(this.frame.stats);
    this.figures.distanceColored = on ? n : 0;
    this.figures.distanceFar = 0;
    if (!on) return undefined;
    const counted = new Uint8Array(n);
    for (const i of indices) {
      if (counted[i] || !(d[i] > far)) continue;
      counted[i] = 1;
      this.figures.distanceFar += 1;
    }
    return distanceColors(d, far);
  }

  drawSurface(viewer) {
    const { limit, untrimmed } = this.frame;
    const whole = untrimmed && this.ui.untrimmed.checked;
    this.figures.surfaceTriangles = (whole ? untrimmed.indices.length : limit.indices.length) / 3;
    const colors = this.surfaceColors(whole ? untrimmed.indices : limit.indices);
    if (whole) viewer.setMesh(limit.positions, untrimmed.normals, untrimmed.indices, colors);
    else if (limit.indices.length > 0) viewer.setMesh(limit.positions, limit.normals, limit.indices, colors);
    else viewer.setMesh(new Float32Array(), new Float32Array(), new Uint32Array());
  }

  /** The surface-by-distance view was switched: the worker measures distances while it is on. */
  backColorsChanged() {
    const on = this.ui.backColors.checked;
    this.ui.backLegend.hidden = !on;
    this.worker.postMessage({ type: MSG.view, distances: on });
    this.redraw();
  }

  drawLines(viewer) {
    const l = this.lines();
    viewer.setLines(l.positions, l.colors);
  }

  /** Replaces the whole scene with the current frame's (after a toggle). */
  redraw() {
    const viewer = this.host.viewer();
    if (!viewer || !this.frame) return;
    this.drawPoints(viewer);
    this.drawSurface(viewer);
    this.drawLines(viewer);
    this.host.requestRender();
  }

  showStats(s) {
    const u = this.ui;
    u.iter.textContent = String(s.iter);
    u.ctrl.textContent = s.controlPoints.toLocaleString('en-US');
    u.eAvg.textContent = `${fmtPct(s.eAvgPct)} (${fmtUnits(s.eAvg)} units)`;
    u.eMax.textContent = `${fmtPct(s.eMaxPct)} (${fmtUnits(s.eMax)} units)`;
    u.eRms.textContent = `${fmtPct(s.eRmsPct)} (${fmtUnits(s.eRms)} units)`;
    // A B-spline surface fit measures E_back once, when it stops (docs/splines.md).
    const later = s.status === 'running' && s.scheme === 'bspline-surface';
    u.eBack.textContent = s.eBackMaxPct != null ? `${fmtPct(s.eBackMaxPct)} (p99 ${fmtPct(s.eBackP99Pct)})`
      : later ? 'when the fit stops' : 'not measured';
    u.ms.textContent = `${s.ms.toFixed(1)} ms`;
    u.total.textContent = `${(s.totalMs / 1000).toFixed(2)} s`;
    const tol = this.tolMaxUnits(s);
    u.legendTol.textContent = `+${fmtUnits(tol)}`;
    u.legendNeg.textContent = `−${fmtUnits(tol)}`;
    u.backLegendTol.textContent = fmtUnits(this.tolBackUnits(s));
    document.body.dataset.fitIter = String(s.iter);
  }

  /**
   * The deviation figures and histogram of a frame.
   * @param {import('../pkg/geofit.js').Deviation} d
   */
  showDeviation(d) {
    const u = this.ui;
    const signed = (v) => `${v >= 0 ? '+' : '−'}${fmtUnits(Math.abs(v))}`;
    u.devMean.textContent = `${signed(d.mean)} ± ${fmtUnits(d.sigma)}`;
    u.devP50.textContent = `${fmtUnits(d.p50)} / ${fmtUnits(d.p90)}`;
    u.devP95.textContent = `${fmtUnits(d.p95)} / ${fmtUnits(d.p99)}`;
    u.devMax.textContent = fmtUnits(d.max);
    u.devWithin.textContent = d.withinTolerancePct == null ? 'no E_max tolerance'
      : `${d.withinTolerancePct.toFixed(2)} % (±${fmtUnits(d.tolerance ?? 0)})`;
    u.devCsv.disabled = false;
    drawHistogram(u.histogram, d);
  }

  /** Downloads the deviations of every data point (not only the drawn ones) as CSV. */
  downloadCsv() {
    if (this.frame) this.worker.postMessage({ type: MSG.export, what: 'csv' });
  }

  /**
   * Shows the index, position and deviation of the data point seen at CSS pixel `x`, `y` of
   * the view (nothing there, or no fit yet: hides the label).
   */
  pick(x, y) {
    const label = this.ui.pickLabel;
    const viewer = this.host.viewer();
    const i = viewer && this.frame && this.once ? viewer.pick(this.once.data, x, y, PICK_RADIUS) : undefined;
    if (i === undefined) {
      label.hidden = true;
      return;
    }
    const p = this.once.data.subarray(3 * i, 3 * i + 3);
    const d = this.frame.errors[i];
    const pct = this.frame.stats.diagonal > 0 ? ` (${fmtPct((100 * d) / this.frame.stats.diagonal)})` : '';
    label.textContent = `point ${i} (${[...p].map((v) => v.toPrecision(5)).join(', ')}): deviation ${d >= 0 ? '+' : ''}${fmtUnits(d)}${pct}`;
    Object.assign(label.dataset, { index: String(i), deviation: String(d) });
    label.style.left = `${x + 10}px`;
    label.style.top = `${y + 10}px`;
    label.hidden = false;
  }

  /**
   * Lists what the core did to the data before fitting (repair, reconstruction, a
   * simplification that stopped above its target); hidden when nothing was done.
   * @param {string[]} notes
   */
  showIntake(notes) {
    const list = this.ui.intake;
    list.replaceChildren(...notes.map((n) => Object.assign(document.createElement('li'), { textContent: n })));
    list.hidden = notes.length === 0;
  }

  /** The tolerances in force, for the chart's dashed lines. */
  chartTolerances(s) {
    return { avg: s?.tolAvgPct, max: s?.tolMaxPct, rms: s?.tolRmsPct };
  }

  // A frame is shown in stages, each its own task (figures, points, surface, lines), so that
  // no main-thread task holds all of a frame's uploads; the picture is drawn at the next
  // animation frame. Frames that arrive meanwhile are skipped but the newest one.
  stage(k, viewer, m) {
    if (k === 0) {
      if (m.once) {
        this.once = m.once;
        this.showIntake(m.once.notes);
      }
      this.frame = m;
      if (m.distances) this.distances = m.distances;
      Object.assign(this.figures, { lastStats: m.stats, history: m.history, creaseEdges: m.control.creases.length / 2, creaseCurveSegments: m.creaseCurves.length / 6, dataCreaseSegments: this.once.dataCreases.length / 6 });
      this.figures.frames += 1;
      this.showStats(m.stats);
      this.figures.deviation = m.deviation;
      const t0 = performance.now();
      this.showDeviation(m.deviation);
      const t1 = performance.now();
      drawChart(this.ui.chart, m.history, this.chartTolerances(m.stats));
      this.figures.deviationMs = Math.max(this.figures.deviationMs, t1 - t0);
      this.figures.chartMs = Math.max(this.figures.chartMs, performance.now() - t1);
    } else if (k === 1) {
      if (viewer) this.drawPoints(viewer);
    } else if (k === 2) {
      if (viewer) this.drawSurface(viewer);
    } else {
      if (viewer) this.drawLines(viewer);
      this.host.requestRender();
      this.playing = m.playing;
      const status = m.stats.status;
      // A file being read keeps its state; the frame is the paused fit's.
      if (this.state !== 'loading') this.go(status === 'running' ? (this.playing ? 'running' : 'paused') : status);
    }
  }

  /** Runs stage `k` of frame `m`, then the next one in a new task. */
  showStage(m, k) {
    if (m.generation !== this.generation) {
      this.showNewest();
      return;
    }
    const t0 = performance.now();
    this.stage(k, this.host.viewer(), m);
    const ms = performance.now() - t0;
    this.figures.maxStageMs = Math.max(this.figures.maxStageMs, ms);
    this.figures.stageMs[k] = Math.max(this.figures.stageMs[k], ms);
    setTimeout(() => (k + 1 < 4 ? this.showStage(m, k + 1) : this.showNewest()), 0);
  }

  showNewest() {
    const m = this.pending;
    this.pending = null;
    this.showing = Boolean(m);
    if (m) this.showStage(m, 0);
  }

  /** @param {import('./protocol.js').FromWorker} m */
  received(m) {
    if (m.type === MSG.frame) {
      if (m.generation !== this.generation) return;
      // What a fit's first frame carries once: keep it if a newer frame overtakes that one.
      if (this.pending?.once && !m.once) m.once = this.pending.once;
      if (this.pending?.distances && !m.distances) m.distances = this.pending.distances;
      this.pending = m;
      if (!this.showing) {
        this.showing = true;
        setTimeout(() => this.showNewest(), 0);
      }
    } else if (m.type === MSG.loaded) {
      this.loaded(m);
    } else if (m.type === MSG.progress) {
      this.showProgress(m.phase, m.done);
    } else if (m.type === MSG.exported) {
      download(m.bytes, ...DOWNLOADS[m.what]);
      if (m.quality) el('fit-fem-quality').textContent = femText(m.quality);
    } else if (m.type === MSG.error && m.during === MSG.load) {
      const loading = this.loading;
      this.loading = null;
      this.go(this.resting());
      if (loading) loading.reject(new Error(m.message));
      else this.host.showError(`Could not read the file again: ${m.message}`);
    } else if (m.type === MSG.error) {
      if (m.generation !== this.generation) return;
      this.host.showError(`Fit (${m.during}): ${m.message}`);
      this.playing = false;
      if (m.during === MSG.start) this.built = 0;
      this.go(this.frame ? 'paused' : 'error');
    }
  }

  bind() {
    const u = this.ui;
    u.play.addEventListener('click', () => this.play());
    u.cancel.addEventListener('click', () => this.cancel());
    u.devCsv.addEventListener('click', () => this.downloadCsv());
    u.step.addEventListener('click', () => this.step());
    u.reset.addEventListener('click', () => this.restart());
    this.form.scheme.addEventListener('change', () => this.form.schemeChanged());
    this.form.method.addEventListener('change', () => this.form.showDefaults());
    for (const input of [this.form.scheme, ...this.form.controls(), u.tolAvgUnits, u.tolMaxUnits]) {
      input.addEventListener('change', () => this.built && this.restart());
    }
    u.refine.addEventListener('change', () => { u.maxControl.disabled = !u.refine.checked; });
    for (const box of [u.cage, u.vectors, u.iso, u.untrimmed, u.initialMesh]) box.addEventListener('change', () => this.redraw());
    u.backColors.addEventListener('change', () => this.backColorsChanged());
    u.allPoints.addEventListener('change', () => this.allPointsChanged());
    for (const button of document.querySelectorAll('[data-export]')) {
      const what = /** @type {HTMLElement} */ (button).dataset.export;
      button.addEventListener('click', () => this.worker.postMessage({ type: MSG.export, what }));
    }
    el('fit-screenshot').addEventListener('click', () => {
      const viewer = this.host.viewer();
      if (!viewer) return;
      // Render and read back in the same task: the drawing buffer is still valid.
      viewer.render();
      this.host.canvas.toBlob(async (blob) => {
        if (blob) download(new Uint8Array(await blob.arrayBuffer()), 'geofit-view.png', 'image/png');
      }, 'image/png');
    });
    new ResizeObserver(() => {
      if (this.figures.history.length) drawChart(u.chart, this.figures.history, this.chartTolerances(this.figures.lastStats));
    }).observe(u.chart);
    new ResizeObserver(() => {
      if (this.figures.deviation) drawHistogram(u.histogram, this.figures.deviation);
    }).observe(u.histogram);
  }

}

/**
 * Wires the fitting panel. `host` gives the viewer, a render request, the error line and
 * `showPoints(loaded)` (draws a scan's points again after the "all points" toggle).
 * Returns `{ load(file, name, preset), pick(x, y), figures }`.
 */
export function createFitUi(host) {
  const panel = new FitPanel(host);
  return {
    load: (file, name, preset) => panel.load(file, name, preset),
    pick: (x, y) => panel.pick(x, y),
    figures: panel.figures,
  };
}
