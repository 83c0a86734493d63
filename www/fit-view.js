// @ts-check
// Drawing helpers of the fitting panel: the error colour scale, line sets for the viewer and
// the convergence chart. Pure functions of their inputs; no state.

// Diverging map for signed distance: inside the E_max tolerance pale tints, outside saturated.
const INSIDE_NEG = [0.62, 0.78, 1.0];
const INSIDE_ZERO = [0.92, 0.92, 0.9];
const INSIDE_POS = [1.0, 0.74, 0.62];
const OUTSIDE_NEG = [0.05, 0.25, 0.95];
const OUTSIDE_POS = [0.9, 0.08, 0.05];
// A surface vertex over a hole of the data or beyond its outline: no distance is measured there.
const UNMEASURED = [0.45, 0.49, 0.56];
export const VECTOR_COLOR = [1.0, 0.85, 0.2];
export const CAGE_COLOR = [0.35, 0.95, 0.55];
export const CREASE_COLOR = [1.0, 0.3, 0.35];
export const DATA_CREASE_COLOR = [1.0, 0.4, 0.95];
export const ISO_COLOR = [0.3, 0.85, 1.0];
export const INITIAL_COLOR = [0.75, 0.55, 1.0];
export const CURVE_COLOR = [1.0, 0.55, 0.1];
// The chart is drawn on the CPU: a GPU-accelerated 2D canvas makes the main thread wait for the
// GPU process (seconds under software rendering on a loaded machine) when the page is composited.
export const CHART_CONTEXT = { willReadFrequently: true };
const CHART_COLORS = { eAvgPct: '#4ea1ff', eMaxPct: '#ff6b5b', eRmsPct: '#7ee07e' };

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

/**
 * One sRGB colour per surface vertex from its distance to the data `d` (model units; negative:
 * not measured, over a hole) and the distance `far` (units) beyond which the surface strays:
 * pale to warm within it, saturated red beyond, grey where unmeasured.
 * @param {Float32Array} distances
 * @param {number} far
 */
export function distanceColors(distances, far) {
  const colors = new Float32Array(distances.length * 3);
  for (let i = 0; i < distances.length; i += 1) {
    const d = distances[i];
    const t = far > 0 ? d / far : 0;
    colors.set(d < 0 ? UNMEASURED : t > 1 ? OUTSIDE_POS : mix(INSIDE_ZERO, INSIDE_POS, t), i * 3);
  }
  return colors;
}

/** Segment end points (two per edge) of the indexed `edges` over flat `positions`. */
export function edgeSegments(positions, edges) {
  const out = new Float32Array(edges.length * 3);
  for (let k = 0; k < edges.length; k += 1) out.set(positions.subarray(edges[k] * 3, edges[k] * 3 + 3), k * 3);
  return out;
}

/** One line set from `[segments, colour]` parts: flat positions and a colour per vertex. */
export function lineSet(parts) {
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

export function fmtPct(v) {
  return `${v.toPrecision(4)} %`;
}

export function fmtUnits(v) {
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

/**
 * Draws the histogram of signed deviations `dev` (the package's `Deviation`): one bar per
 * bin in the point colour of its centre, the tolerance band ±`dev.tolerance` shaded, 0 and the
 * range's ends labelled. 64 bars: cheap enough for every frame.
 * @param {HTMLCanvasElement} canvas
 * @param {import('../pkg/geofit.js').Deviation} dev
 */
export function drawHistogram(canvas, dev) {
  const ratio = window.devicePixelRatio || 1;
  const w = Math.max(1, Math.round(canvas.clientWidth * ratio));
  const h = Math.max(1, Math.round(canvas.clientHeight * ratio));
  if (canvas.width !== w || canvas.height !== h) {
    canvas.width = w;
    canvas.height = h;
  }
  const g = /** @type {CanvasRenderingContext2D} */ (canvas.getContext('2d', CHART_CONTEXT));
  g.setTransform(ratio, 0, 0, ratio, 0, 0);
  const cw = w / ratio;
  const ch = h / ratio;
  g.fillStyle = '#10141b';
  g.fillRect(0, 0, cw, ch);
  const pad = { l: 8, r: 8, t: 6, b: 16 };
  const n = dev.counts.length;
  const top = Math.max(1, ...dev.counts);
  const x = (d) => pad.l + ((d + dev.halfWidth) / (2 * dev.halfWidth)) * (cw - pad.l - pad.r);
  const tol = dev.tolerance ?? 0;
  if (tol > 0) {
    g.fillStyle = 'rgba(126, 224, 126, 0.18)';
    const a = x(Math.max(-tol, -dev.halfWidth));
    g.fillRect(a, pad.t, x(Math.min(tol, dev.halfWidth)) - a, ch - pad.t - pad.b);
  }
  const binWidth = (2 * dev.halfWidth) / n;
  const centres = Float32Array.from(dev.counts, (_, k) => -dev.halfWidth + (k + 0.5) * binWidth);
  const colors = errorColors(centres, tol);
  const barW = (cw - pad.l - pad.r) / n;
  dev.counts.forEach((count, k) => {
    if (count === 0) return;
    const [r, gg, b] = colors.subarray(k * 3, k * 3 + 3);
    g.fillStyle = `rgb(${Math.round(r * 255)}, ${Math.round(gg * 255)}, ${Math.round(b * 255)})`;
    const bh = Math.max(1, (count / top) * (ch - pad.t - pad.b));
    g.fillRect(pad.l + k * barW, ch - pad.b - bh, Math.max(1, barW - 1), bh);
  });
  g.strokeStyle = '#9aa3ad';
  g.beginPath();
  g.moveTo(x(0), pad.t);
  g.lineTo(x(0), ch - pad.b);
  g.stroke();
  g.font = '10px system-ui, sans-serif';
  g.fillStyle = '#9aa3ad';
  g.fillText(`−${fmtUnits(dev.halfWidth)}`, pad.l, ch - 4);
  g.fillText('0', x(0) - 3, ch - 4);
  const right = `+${fmtUnits(dev.halfWidth)}`;
  g.fillText(right, cw - pad.r - g.measureText(right).width, ch - 4);
}

/**
 * The per-point deviations as CSV text: `#` header lines with the figures of `dev`, then
 * `index,x,y,z,deviation` per point (model units; the deviation signed, + above the surface).
 * @param {Float32Array} positions  x, y, z per point
 * @param {Float32Array} errors  signed deviation per point, in the order of `positions`
 * @param {import('../pkg/geofit.js').Deviation} dev
 */
export function deviationCsv(positions, errors, dev) {
  const figure = (v) => (v == null ? '' : String(v));
  const lines = [
    `# points,${dev.points}`,
    ...['mean', 'sigma', 'p50', 'p90', 'p95', 'p99', 'max', 'tolerance', 'withinTolerancePct']
      .map((k) => `# ${k},${figure(dev[k])}`),
    'index,x,y,z,deviation',
  ];
  for (let i = 0; i < errors.length; i += 1) {
    lines.push(`${i},${positions[3 * i]},${positions[3 * i + 1]},${positions[3 * i + 2]},${errors[i]}`);
  }
  return `${lines.join('\n')}\n`;
}
