// The fitting panel: options, play / pause / step / reset, statistics, the convergence chart, the
// error colours, the view toggles of the fit (control net, error vectors, iso-parameter lines,
// initial mesh) and exports. The fit itself runs in fit-worker.js; this module only turns the
// worker's frames into draw calls on the shared Viewer and into text, so no main-thread task
// grows with the fit.

// Diverging map for signed distance: inside the E_max tolerance pale tints, outside saturated.
const INSIDE_NEG = [0.62, 0.78, 1.0];
const INSIDE_ZERO = [0.92, 0.92, 0.9];
const INSIDE_POS = [1.0, 0.74, 0.62];
const OUTSIDE_NEG = [0.05, 0.25, 0.95];
const OUTSIDE_POS = [0.9, 0.08, 0.05];
const VECTOR_COLOR = [1.0, 0.85, 0.2];
const CAGE_COLOR = [0.35, 0.95, 0.55];
const ISO_COLOR = [0.3, 0.85, 1.0];
const INITIAL_COLOR = [0.75, 0.55, 1.0];
const CURVE_COLOR = [1.0, 0.55, 0.1];
const SUBDIV = ['loop', 'catmull-clark', 'doo-sabin'];
const CURVES = ['bspline-curve', 'chaikin-curve'];
// Download name and MIME type of each export.
const EXPORTS = {
  cage: ['geofit-cage.obj', 'model/obj'], obj: ['geofit-limit.obj', 'model/obj'],
  ply: ['geofit-limit.ply', 'application/octet-stream'], stl: ['geofit-limit.stl', 'model/stl'],
  iges: ['geofit.igs', 'model/iges'], step: ['geofit.stp', 'model/step'],
  json: ['geofit-report.json', 'application/json'],
};
// The chart is drawn on the CPU: a GPU-accelerated 2D canvas makes the main thread wait for the
// GPU process (seconds under software rendering on a loaded machine) when the page is composited.
const CHART_CONTEXT = { willReadFrequently: true };
const CHART_COLORS = { eAvgPct: '#4ea1ff', eMaxPct: '#ff6b5b', eRmsPct: '#7ee07e' };

const el = (id) => document.getElementById(id);

function mix(a, b, t) {
  return [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t, a[2] + (b[2] - a[2]) * t];
}

/** One sRGB colour per data point from its signed distance `d` and the tolerance `tol` (units). */
export function errorColors(errors, tol) {
  const colors = new Float32Array(errors.length * 3);
  for (let i = 0; i < errors.length; i += 1) {
    const t = tol > 0 ? errors[i] / tol : 0;
    let c;
    if (t > 1) c = OUTSIDE_POS;
    else if (t < -1) c = OUTSIDE_NEG;
    else if (t >= 0) c = mix(INSIDE_ZERO, INSIDE_POS, t);
    else c = mix(INSIDE_ZERO, INSIDE_NEG, -t);
    colors.set(c, i * 3);
  }
  return colors;
}

/** Segment end points (two per edge) of the indexed `edges` over flat `positions`. */
function edgeSegments(positions, edges) {
  const out = new Float32Array(edges.length * 3);
  for (let k = 0; k < edges.length; k += 1) out.set(positions.subarray(edges[k] * 3, edges[k] * 3 + 3), k * 3);
  return out;
}

/** One line set from `[segments, colour]` parts: flat positions and a colour per vertex. */
function lineSet(parts) {
  const total = parts.reduce((n, [p]) => n + p.length, 0);
  const positions = new Float32Array(total);
  const colors = new Float32Array(total);
  let at = 0;
  for (const [p, color] of parts) {
    positions.set(p, at);
    for (let i = at; i < at + p.length; i += 3) colors.set(color, i);
    at += p.length;
  }
  return { positions, colors };
}

function fmtPct(v) {
  return `${v.toPrecision(4)} %`;
}

function fmtUnits(v) {
  return v === 0 ? '0' : v.toExponential(3);
}

/** Draws E_avg, E_max, E_rms (log scale) against iteration, tolerance lines and refinements. */
export function drawChart(canvas, history, tolerances) {
  const ratio = window.devicePixelRatio || 1;
  const w = Math.max(1, Math.round(canvas.clientWidth * ratio));
  const h = Math.max(1, Math.round(canvas.clientHeight * ratio));
  if (canvas.width !== w || canvas.height !== h) {
    canvas.width = w;
    canvas.height = h;
  }
  const g = canvas.getContext('2d', CHART_CONTEXT);
  g.setTransform(ratio, 0, 0, ratio, 0, 0);
  const cw = w / ratio;
  const ch = h / ratio;
  g.fillStyle = '#10141b';
  g.fillRect(0, 0, cw, ch);
  const pad = { l: 44, r: 8, t: 8, b: 20 };
  const values = history.flatMap((r) => [r.eAvgPct, r.eMaxPct, r.eRmsPct]);
  for (const t of Object.values(tolerances)) if (t > 0) values.push(t);
  const positive = values.filter((v) => v > 0);
  if (positive.length === 0) return;
  let lo = Math.log10(Math.min(...positive));
  let hi = Math.log10(Math.max(...positive));
  lo = Math.floor(lo);
  hi = Math.max(Math.ceil(hi), lo + 1);
  const n = Math.max(history.length, 1);
  const x = (i) => pad.l + ((i) / n) * (cw - pad.l - pad.r);
  const y = (v) => pad.t + ((hi - Math.log10(Math.max(v, 10 ** lo))) / (hi - lo)) * (ch - pad.t - pad.b);
  g.font = '10px system-ui, sans-serif';
  g.fillStyle = '#9aa3ad';
  g.strokeStyle = '#2a313c';
  g.lineWidth = 1;
  for (let e = lo; e <= hi; e += 1) {
    g.beginPath();
    g.moveTo(pad.l, y(10 ** e));
    g.lineTo(cw - pad.r, y(10 ** e));
    g.stroke();
    g.fillText(`${10 ** e >= 1 ? 10 ** e : (10 ** e).toPrecision(1)}%`, 2, y(10 ** e) + 3);
  }
  g.fillText('iteration', cw - 50, ch - 4);
  // Refinement events: dashed vertical lines.
  g.setLineDash([3, 3]);
  g.strokeStyle = '#c9a0ff';
  for (const r of history) {
    if (!r.refined) continue;
    g.beginPath();
    g.moveTo(x(r.iter), pad.t);
    g.lineTo(x(r.iter), ch - pad.b);
    g.stroke();
  }
  // Tolerances: dashed horizontal lines in the colour of their figure.
  const tolKey = { avg: 'eAvgPct', max: 'eMaxPct', rms: 'eRmsPct' };
  for (const [k, t] of Object.entries(tolerances)) {
    if (!(t > 0)) continue;
    g.strokeStyle = CHART_COLORS[tolKey[k]];
    g.beginPath();
    g.moveTo(pad.l, y(t));
    g.lineTo(cw - pad.r, y(t));
    g.stroke();
  }
  g.setLineDash([]);
  g.lineWidth = 2;
  for (const [key, color] of Object.entries(CHART_COLORS)) {
    g.strokeStyle = color;
    g.beginPath();
    history.forEach((r, i) => (i === 0 ? g.moveTo(x(r.iter), y(r[key])) : g.lineTo(x(r.iter), y(r[key]))));
    if (history.length === 1) g.lineTo(x(history[0].iter) + 2, y(history[0][key]));
    g.stroke();
  }
}

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
 * Wires the fitting panel. `host` gives the viewer, a render request and the error line.
 * Returns `{ onScan(bytes, name, diagonal, preset) }`: called by the page after every
 * successfully loaded file (`preset`: form values suiting a bundled sample); the scan stays on
 * screen as loaded until a fit is started.
 */
export function createFitUi(host) {
  const ui = {
    form: el('fit-form'), scheme: el('fit-scheme'), method: el('fit-method'), closed: el('fit-closed'),
    tolAvg: el('fit-tol-avg'), tolMax: el('fit-tol-max'),
    tolAvgUnits: el('fit-tol-avg-units'), tolMaxUnits: el('fit-tol-max-units'),
    initial: el('fit-initial'), maxIter: el('fit-max-iter'), refine: el('fit-refine'),
    maxControl: el('fit-max-control'), weights: el('fit-weights'), accel: el('fit-accel'),
    play: el('fit-play'), step: el('fit-step'), reset: el('fit-reset'),
    vectors: el('show-vectors'), cage: el('show-cage'), iso: el('show-iso'), initialMesh: el('show-initial'),
    chart: el('fit-chart'),
    status: el('fit-status'), iter: el('fit-iter'), ctrl: el('fit-ctrl'), eAvg: el('fit-eavg'),
    eMax: el('fit-emax'), eRms: el('fit-erms'), ms: el('fit-ms'), total: el('fit-total'),
    legendTol: el('legend-tol'), legendNeg: el('legend-neg'),
  };
  const worker = new Worker(new URL('./fit-worker.js', import.meta.url), { type: 'module' });
  let scan = null;
  let frame = null;
  let playing = false;
  let tolerances = {};
  // generation: the fit the worker was last asked to build (0: none for this scan); frames of
  // older fits are dropped. pending: the newest frame not yet drawn (drawn at most once a frame).
  let generation = 0;
  let built = 0;
  let pending = null;
  // Sent once per fit: the data points (in the order of the errors) and the initial control net.
  let once = null;
  // lastStats/history: the worker's latest figures; frames: frames shown; maxStageMs: the
  // longest stage of showing one, stageMs: the longest of each stage.
  const state = { lastStats: null, history: [], frames: 0, maxStageMs: 0, stageMs: [0, 0, 0, 0] };
  window.geofitFit = state;

  function options() {
    const num = (input) => (input.value.trim() === '' ? undefined : Number(input.value));
    const scheme = ui.scheme.value;
    const opts = {
      scheme,
      method: scheme === 'bspline-surface' ? ui.method.value : undefined,
      closed: CURVES.includes(scheme) ? ui.closed.checked : undefined,
      tolAvg: scheme === 'bspline-surface' ? undefined : num(ui.tolAvg),
      tolMax: num(ui.tolMax),
      initial: CURVES.includes(scheme) ? undefined : num(ui.initial),
      maxIter: num(ui.maxIter),
      refine: ui.refine.checked,
      maxControl: ui.refine.checked ? num(ui.maxControl) : undefined,
      weights: SUBDIV.includes(scheme) ? ui.weights.value : undefined,
      acceleration: ui.accel.value === 'default' ? undefined : ui.accel.value,
    };
    return Object.fromEntries(Object.entries(opts).filter(([, v]) => v !== undefined));
  }

  /** Shows the options and exports that apply to the chosen scheme. */
  function schemeChanged() {
    const scheme = ui.scheme.value;
    for (const label of ui.form.querySelectorAll('[data-for]')) {
      label.hidden = !label.dataset.for.split(' ').includes(scheme);
    }
    const spline = !SUBDIV.includes(scheme);
    const curve = CURVES.includes(scheme);
    for (const button of document.querySelectorAll('[data-export]')) {
      const what = button.dataset.export;
      button.disabled = ((what === 'iges' || what === 'step') && !spline) ||
        (['obj', 'ply', 'stl'].includes(what) && curve);
    }
    ui.tolAvg.disabled = scheme === 'bspline-surface';
    ui.tolAvgUnits.disabled = scheme === 'bspline-surface';
    ui.initial.disabled = curve;
  }

  /** Keeps each tolerance's % and model-unit fields in step (the diagonal is the scan's). */
  function linkTolerance(pct, units) {
    const toUnits = () => {
      const d = scan?.diagonal ?? 0;
      units.value = pct.value.trim() === '' || !(d > 0) ? '' : String(Number(((Number(pct.value) * d) / 100).toPrecision(4)));
    };
    pct.addEventListener('input', toUnits);
    units.addEventListener('input', () => {
      const d = scan?.diagonal ?? 0;
      if (units.value.trim() !== '' && d > 0) pct.value = String(Number(((Number(units.value) / d) * 100).toPrecision(4)));
    });
    return toUnits;
  }
  const tolUnits = [linkTolerance(ui.tolAvg, ui.tolAvgUnits), linkTolerance(ui.tolMax, ui.tolMaxUnits)];

  function setFitState(s) {
    document.body.dataset.fit = s;
    ui.status.textContent = {
      building: 'building the control net…', paused: 'paused', running: 'fitting…',
      converged: 'converged: tolerances met', max_iterations: 'stopped: iteration cap reached',
      error: 'error', idle: 'press Play or Step to fit',
    }[s] ?? s;
    ui.play.textContent = s === 'running' ? 'Pause' : 'Play';
    ui.play.setAttribute('aria-pressed', String(s === 'running'));
  }

  /** Asks the worker for a new fit of the current scan with the panel's options (iteration 0). */
  function restart() {
    if (!scan) return;
    playing = false;
    frame = null;
    pending = null;
    once = null;
    const opts = options();
    tolerances = { avg: opts.tolAvg, max: opts.tolMax };
    generation += 1;
    built = generation;
    setFitState('building');
    worker.postMessage({ type: 'start', generation, bytes: scan.bytes.slice(), name: scan.name, options: opts });
  }

  /** Forgets the fit (a new scan was loaded): the page shows the scan until Play, Step or Reset. */
  function clear() {
    generation += 1;
    built = 0;
    playing = false;
    frame = null;
    pending = null;
    once = null;
    worker.postMessage({ type: 'clear', generation });
    Object.assign(state, { lastStats: null, history: [] });
    for (const dd of [ui.iter, ui.ctrl, ui.eAvg, ui.eMax, ui.eRms, ui.ms, ui.total]) dd.textContent = '—';
    delete document.body.dataset.fitIter;
    const g = ui.chart.getContext('2d', CHART_CONTEXT);
    g.clearRect(0, 0, ui.chart.width, ui.chart.height);
    setFitState('idle');
  }

  /** The line layer: fitted curve, control net, error vectors, iso lines, initial net. */
  function lines() {
    const parts = [];
    const { limit, control } = frame;
    if (limit.indices.length === 0) parts.push([edgeSegments(limit.positions, limit.edges), CURVE_COLOR]);
    if (ui.cage.checked) parts.push([edgeSegments(control.positions, control.edges), CAGE_COLOR]);
    if (ui.vectors.checked) parts.push([frame.vectors, VECTOR_COLOR]);
    if (ui.iso.checked) parts.push([frame.iso, ISO_COLOR]);
    if (ui.initialMesh.checked) parts.push([edgeSegments(once.initial.positions, once.initial.edges), INITIAL_COLOR]);
    return lineSet(parts);
  }

  function drawPoints(viewer) {
    const tolUnitsMax = ((tolerances.max ?? 0.05) * frame.stats.diagonal) / 100;
    viewer.setPoints(once.data, errorColors(frame.errors, tolUnitsMax));
  }

  function drawSurface(viewer) {
    const { limit } = frame;
    if (limit.indices.length > 0) viewer.setMesh(limit.positions, limit.normals, limit.indices);
    else viewer.setMesh(new Float32Array(), new Float32Array(), new Uint32Array());
  }

  function drawLines(viewer) {
    const l = lines();
    viewer.setLines(l.positions, l.colors);
  }

  /** Replaces the whole scene with the current frame's (after a toggle). */
  function redraw() {
    const viewer = host.viewer();
    if (!viewer || !frame) return;
    drawPoints(viewer);
    drawSurface(viewer);
    drawLines(viewer);
    host.requestRender();
  }

  function showStats(s) {
    ui.iter.textContent = String(s.iter);
    ui.ctrl.textContent = s.controlPoints.toLocaleString('en-US');
    ui.eAvg.textContent = `${fmtPct(s.eAvgPct)} (${fmtUnits(s.eAvg)} units)`;
    ui.eMax.textContent = `${fmtPct(s.eMaxPct)} (${fmtUnits(s.eMax)} units)`;
    ui.eRms.textContent = `${fmtPct(s.eRmsPct)} (${fmtUnits(s.eRms)} units)`;
    ui.ms.textContent = `${s.ms.toFixed(1)} ms`;
    ui.total.textContent = `${(s.totalMs / 1000).toFixed(2)} s`;
    const tolUnitsMax = ((tolerances.max ?? 0.05) * s.diagonal) / 100;
    ui.legendTol.textContent = `+${fmtUnits(tolUnitsMax)}`;
    ui.legendNeg.textContent = `−${fmtUnits(tolUnitsMax)}`;
    document.body.dataset.fitIter = String(s.iter);
  }

  // A frame is shown in stages, each its own task (figures, points, surface, lines), so that
  // no main-thread task holds all of a frame's uploads; the picture is drawn at the next
  // animation frame. Frames that arrive meanwhile are skipped but the newest one.
  let showing = false;
  const STAGES = [
    (viewer, m) => {
      if (m.once) once = m.once;
      frame = m;
      state.lastStats = m.stats;
      state.history = m.history;
      state.frames += 1;
      showStats(m.stats);
      drawChart(ui.chart, m.history, tolerances);
    },
    (viewer) => viewer && drawPoints(viewer),
    (viewer) => viewer && drawSurface(viewer),
    (viewer, m) => {
      if (viewer) drawLines(viewer);
      host.requestRender();
      playing = m.playing;
      const status = m.stats.status;
      setFitState(status === 'running' ? (playing ? 'running' : 'paused') : status);
    },
  ];

  /** Runs stage `k` of frame `m`, then the next one in a new task. */
  function showStage(m, k) {
    if (m.generation !== generation) {
      showNewest();
      return;
    }
    const t0 = performance.now();
    STAGES[k](host.viewer(), m);
    const ms = performance.now() - t0;
    state.maxStageMs = Math.max(state.maxStageMs, ms);
    state.stageMs[k] = Math.max(state.stageMs[k], ms);
    setTimeout(() => (k + 1 < STAGES.length ? showStage(m, k + 1) : showNewest()), 0);
  }

  function showNewest() {
    const m = pending;
    pending = null;
    showing = Boolean(m);
    if (m) showStage(m, 0);
  }

  worker.onmessage = ({ data: m }) => {
    if (m.type === 'frame') {
      if (m.generation !== generation) return;
      // What a fit's first frame carries once: keep it if a newer frame overtakes that one.
      if (pending?.once && !m.once) m.once = pending.once;
      pending = m;
      if (!showing) {
        showing = true;
        setTimeout(showNewest, 0);
      }
    } else if (m.type === 'exported') {
      download(m.bytes, ...EXPORTS[m.what]);
    } else if (m.type === 'error') {
      if (m.generation !== generation) return;
      host.showError(`Fit (${m.during}): ${m.message}`);
      playing = false;
      if (m.during === 'start') built = 0;
      setFitState(frame ? 'paused' : 'error');
    }
  };
  worker.onerror = (e) => {
    host.showError(`The fitting worker failed: ${e.message}`);
    setFitState('error');
  };

  ui.play.addEventListener('click', () => {
    if (!scan) return;
    if (playing) worker.postMessage({ type: 'pause' });
    else {
      if (!built) restart();
      worker.postMessage({ type: 'play' });
      playing = true;
      setFitState('running');
    }
  });
  ui.step.addEventListener('click', () => {
    if (!scan) return;
    if (!built) restart();
    worker.postMessage({ type: 'step' });
  });
  ui.reset.addEventListener('click', restart);
  ui.scheme.addEventListener('change', schemeChanged);
  for (const input of [ui.scheme, ui.method, ui.closed, ui.tolAvg, ui.tolMax, ui.tolAvgUnits, ui.tolMaxUnits,
    ui.initial, ui.maxIter, ui.refine, ui.maxControl, ui.weights, ui.accel]) {
    input.addEventListener('change', () => built && restart());
  }
  ui.refine.addEventListener('change', () => { ui.maxControl.disabled = !ui.refine.checked; });
  for (const box of [ui.cage, ui.vectors, ui.iso, ui.initialMesh]) box.addEventListener('change', redraw);
  for (const button of document.querySelectorAll('[data-export]')) {
    button.addEventListener('click', () => worker.postMessage({ type: 'export', what: button.dataset.export }));
  }
  el('fit-screenshot').addEventListener('click', () => {
    const viewer = host.viewer();
    if (!viewer) return;
    // Render and read back in the same task: the drawing buffer is still valid.
    viewer.render();
    host.canvas.toBlob(async (blob) => {
      if (blob) download(new Uint8Array(await blob.arrayBuffer()), 'geofit-view.png', 'image/png');
    }, 'image/png');
  });
  new ResizeObserver(() => state.history.length && drawChart(ui.chart, state.history, tolerances)).observe(ui.chart);
  schemeChanged();
  setFitState('idle');

  return {
    onScan(bytes, name, diagonal, preset = {}) {
      scan = { bytes, name, diagonal };
      if (preset.scheme) ui.scheme.value = preset.scheme;
      if (preset.closed !== undefined) ui.closed.checked = preset.closed;
      if (preset.tolMax !== undefined) ui.tolMax.value = String(preset.tolMax);
      schemeChanged();
      for (const update of tolUnits) update();
      clear();
    },
  };
}
