// The geofit demo page: loads a point or mesh file through the Rust readers (wasm, in the fitting
// worker, which reads and parses it once and keeps it for the fits) and draws it with the wgpu
// viewer. The page opens with a bundled sample; a file picker and drag-and-drop load others; a
// file that cannot be read leaves the previous one on screen and says why.
import init, { Viewer, loadFile } from '../pkg/geofit.js';
import { createFitUi } from './fit-ui.js';

// The bundled samples (www/samples/samples.json): file, label and the fit options that suit
// each, by file name.
let samplePresets = {};
// Height colours, low to high (sRGB): blue, teal, amber.
const PALETTE = [
  [0.15, 0.35, 0.95],
  [0.10, 0.75, 0.70],
  [1.00, 0.62, 0.10],
];

const el = (id) => document.getElementById(id);
const ui = {
  canvas: el('view'),
  file: el('file'),
  error: el('error'),
  fileName: el('file-name'),
  points: el('num-points'),
  triangles: el('num-triangles'),
  straysRow: el('strays-row'),
  strays: el('strays'),
  backend: el('backend'),
  showPoints: el('show-points'),
  showMesh: el('show-mesh'),
  showWireframe: el('show-wireframe'),
  showZebra: el('show-zebra'),
  sample: el('sample'),
};

let viewer = null;
let fitUi = null;
let frameRequest = 0;
let framesDrawn = 0;

/** Draws a frame at the next animation frame (once, however often it is asked for). */
function requestRender() {
  if (!viewer || frameRequest) return;
  frameRequest = requestAnimationFrame(() => {
    frameRequest = 0;
    viewer.render();
    framesDrawn += 1;
    document.body.dataset.frames = String(framesDrawn);
  });
}

function setState(state) {
  document.body.dataset.state = state;
}

function showError(message) {
  ui.error.textContent = message;
  ui.error.hidden = false;
}

function clearError() {
  ui.error.textContent = '';
  ui.error.hidden = true;
}

/** Colours each point by its height (y) through PALETTE. */
function heightColors(positions) {
  let lo = Infinity;
  let hi = -Infinity;
  for (let i = 1; i < positions.length; i += 3) {
    lo = Math.min(lo, positions[i]);
    hi = Math.max(hi, positions[i]);
  }
  const span = hi > lo ? hi - lo : 1;
  const colors = new Float32Array(positions.length);
  const last = PALETTE.length - 1;
  for (let i = 0; i < positions.length; i += 3) {
    const t = ((positions[i + 1] - lo) / span) * last;
    const k = Math.min(Math.floor(t), last - 1);
    const f = t - k;
    for (let c = 0; c < 3; c += 1) {
      colors[i + c] = PALETTE[k][c] * (1 - f) + PALETTE[k + 1][c] * f;
    }
  }
  return colors;
}

/**
 * Draws the points of a loaded scan (the worker's `loaded` message), coloured by height.
 * @param {import('./protocol.js').LoadedMessage} loaded
 */
function showPoints(loaded) {
  viewer?.setPoints(loaded.points, heightColors(loaded.points));
  requestRender();
}

/**
 * Has the worker read `file` (a File or Blob called `name`) and shows the result; on error
 * keeps what was shown. `preset`: the fit options of a bundled sample (a user's file has none:
 * the core's defaults). Returns whether the file is now the page's scan.
 * @param {Blob} file
 * @param {string} name
 */
async function show(file, name, preset = {}) {
  const before = document.body.dataset.state;
  setState('loading');
  let loaded;
  try {
    loaded = await fitUi.load(file, name, preset);
  } catch (e) {
    if (e?.superseded) return false;
    if (e?.cancelled) {
      // The scan shown before (if any) is still the page's.
      setState(before === 'loading' ? 'ready' : before);
      return false;
    }
    showError(`Could not load ${name}: ${e?.message ?? e}`);
    setState('error');
    return false;
  }
  try {
    if (viewer) {
      showPoints(loaded);
      const mesh = loaded.mesh ?? { positions: new Float32Array(), normals: new Float32Array(), indices: new Uint32Array() };
      viewer.setMesh(mesh.positions, mesh.normals, mesh.indices);
      viewer.setLines(new Float32Array(), new Float32Array());
      viewer.fitView();
    }
    ui.fileName.textContent = name;
    ui.points.textContent = loaded.numPoints.toLocaleString('en-US');
    ui.triangles.textContent = loaded.numTriangles.toLocaleString('en-US');
    showStrays(loaded.strays);
    clearError();
    setState('ready');
    requestRender();
    return true;
  } catch (e) {
    showError(`Could not show ${name}: ${e?.message ?? e}`);
    setState('error');
    return false;
  }
}

/** Lists the points left out as strays (the view and the fit leave them out), if any. */
function showStrays(strays) {
  const shown = [...strays.slice(0, 5)].join(', ') + (strays.length > 5 ? ', …' : '');
  ui.strays.textContent = `${strays.length.toLocaleString('en-US')} (point${strays.length > 1 ? 's' : ''} ${shown})`;
  ui.straysRow.hidden = strays.length === 0;
}

/** Loads a picked or dropped file: the worker reads it (the page never holds its bytes). */
function openFile(file) {
  show(file, file.name);
}

function updateLayers() {
  viewer?.setZebra(ui.showZebra.checked);
  viewer?.setLayers(
    ui.showPoints.checked,
    ui.showMesh.checked,
    ui.showWireframe.checked,
    true,
  );
  requestRender();
}

function resize() {
  if (!viewer) return;
  const { clientWidth, clientHeight } = ui.canvas;
  viewer.resize(clientWidth, clientHeight, window.devicePixelRatio || 1);
  requestRender();
}

/** Orbit camera: drag rotates, shift-drag or right-drag pans, the wheel zooms, double-click or F fits. */
function bindCamera() {
  const c = ui.canvas;
  let last = null;
  // A press released within CLICK_SLOP CSS pixels of where it started is a click: it picks
  // the data point there (fit-ui.js shows its deviation); a drag moves the camera.
  const CLICK_SLOP = 3;
  let down = null;
  c.addEventListener('contextmenu', (e) => e.preventDefault());
  c.addEventListener('pointerdown', (e) => {
    c.setPointerCapture(e.pointerId);
    c.focus();
    last = { x: e.clientX, y: e.clientY };
    down = e.button === 0 ? last : null;
  });
  c.addEventListener('click', (e) => {
    if (!down || Math.hypot(e.clientX - down.x, e.clientY - down.y) > CLICK_SLOP) return;
    const r = c.getBoundingClientRect();
    fitUi?.pick(e.clientX - r.left, e.clientY - r.top);
  });
  c.addEventListener('pointermove', (e) => {
    if (!last || !viewer) return;
    const dx = e.clientX - last.x;
    const dy = e.clientY - last.y;
    last = { x: e.clientX, y: e.clientY };
    if (down && Math.hypot(e.clientX - down.x, e.clientY - down.y) > CLICK_SLOP) el('pick-label').hidden = true;
    const panning = e.shiftKey || (e.buttons & 2) !== 0 || (e.buttons & 4) !== 0;
    if (panning) viewer.pan(dx, dy);
    else viewer.orbit(dx, dy);
    requestRender();
  });
  const end = () => {
    last = null;
  };
  c.addEventListener('pointerup', end);
  c.addEventListener('pointercancel', end);
  c.addEventListener(
    'wheel',
    (e) => {
      e.preventDefault();
      const scale = e.deltaMode === 1 ? 33 : e.deltaMode === 2 ? 400 : 1;
      viewer?.zoom(e.deltaY * scale);
      requestRender();
    },
    { passive: false },
  );
  const fit = () => {
    viewer?.fitView();
    requestRender();
  };
  c.addEventListener('dblclick', fit);
  window.addEventListener('keydown', (e) => {
    const typing = e.target instanceof HTMLInputElement && e.target.type !== 'checkbox';
    if (!typing && (e.key === 'f' || e.key === 'F') && !e.ctrlKey && !e.metaKey) fit();
  });
  // With the view focused: arrow keys rotate (shift + arrows pan), + and − zoom.
  const KEY_STEP = 20;
  const arrows = { ArrowLeft: [-KEY_STEP, 0], ArrowRight: [KEY_STEP, 0], ArrowUp: [0, -KEY_STEP], ArrowDown: [0, KEY_STEP] };
  c.addEventListener('keydown', (e) => {
    if (!viewer) return;
    if (arrows[e.key]) {
      const [dx, dy] = arrows[e.key];
      if (e.shiftKey) viewer.pan(dx, dy);
      else viewer.orbit(dx, dy);
    } else if (e.key === '+' || e.key === '=') viewer.zoom(-100);
    else if (e.key === '-') viewer.zoom(100);
    else return;
    e.preventDefault();
    requestRender();
  });
}

function bindFiles() {
  ui.file.addEventListener('change', () => {
    const [file] = ui.file.files;
    if (file) openFile(file);
    ui.file.value = '';
  });
  let depth = 0;
  window.addEventListener('dragenter', (e) => {
    e.preventDefault();
    depth += 1;
    document.body.classList.add('dragging');
  });
  window.addEventListener('dragleave', () => {
    depth = Math.max(0, depth - 1);
    if (depth === 0) document.body.classList.remove('dragging');
  });
  window.addEventListener('dragover', (e) => e.preventDefault());
  window.addEventListener('drop', (e) => {
    e.preventDefault();
    depth = 0;
    document.body.classList.remove('dragging');
    const file = e.dataTransfer?.files?.[0];
    if (file) openFile(file);
  });
}

async function main() {
  await init();
  bindFiles();
  bindCamera();
  fitUi = createFitUi({ viewer: () => viewer, requestRender, showError, showPoints, canvas: ui.canvas });
  // Test hook (read by tests/e2e, not an API): the fitting panel's figures.
  window.geofitFit = fitUi.figures;
  for (const box of [ui.showPoints, ui.showMesh, ui.showWireframe, ui.showZebra]) {
    box.addEventListener('change', updateLayers);
  }
  const ratio = window.devicePixelRatio || 1;
  ui.canvas.width = Math.max(1, Math.round(ui.canvas.clientWidth * ratio));
  ui.canvas.height = Math.max(1, Math.round(ui.canvas.clientHeight * ratio));
  try {
    viewer = await Viewer.create(ui.canvas);
    ui.backend.textContent = viewer.backend;
    // Test hook (read by tests/e2e and handy in the console, not an API).
    window.geofit = { viewer, loadFile, requestRender };
    document.body.dataset.backend = viewer.backend;
  } catch (e) {
    ui.backend.textContent = 'unavailable';
    showError(`Cannot draw: ${e?.message ?? e}. Files can still be read.`);
  }
  new ResizeObserver(resize).observe(ui.canvas);
  window.addEventListener('resize', resize);
  resize();
  updateLayers();
  await listSamples();
  ui.sample.addEventListener('change', () => openSample(ui.sample.value));
  const params = new URLSearchParams(location.search);
  if (params.has('src')) await openLink(params);
  else await openSample(ui.sample.value);
}

/**
 * The fit options of a page link: every parameter but `src` names a FitSpec field by its
 * camelCase name (as the form does: `scheme`, `tolMax`, `refine`, ...) and is read as the
 * form's control reads it. Throws naming a parameter the form has no field for or a value that
 * is not of its kind; the core checks the values' ranges when it builds the fit.
 * @param {URLSearchParams} params
 */
function linkPreset(params) {
  const form = /** @type {HTMLFormElement} */ (el('fit-form'));
  /** @type {Object<string, unknown>} */
  const preset = {};
  for (const [name, text] of params) {
    if (name === 'src') continue;
    const control = form.elements.namedItem(name);
    if (!(control instanceof HTMLInputElement || control instanceof HTMLSelectElement)) {
      throw new Error(`unknown page parameter '${name}' (the fit options are ${[...form.querySelectorAll('[name]')].map((c) => c.getAttribute('name')).join(', ')})`);
    }
    if (control instanceof HTMLSelectElement && name !== 'method' && ![...control.options].some((o) => o.value === text)) {
      throw new Error(`page parameter ${name}=${text}: not one of ${[...control.options].map((o) => o.value).filter(Boolean).join(', ')}`);
    }
    if (control instanceof HTMLInputElement && control.type === 'checkbox') {
      if (!['true', 'false', '1', '0'].includes(text)) throw new Error(`page parameter ${name}=${text}: not true or false`);
      preset[name] = text === 'true' || text === '1';
    } else if (control instanceof HTMLInputElement && control.type === 'number') {
      const value = Number(text);
      if (text.trim() === '' || !Number.isFinite(value)) throw new Error(`page parameter ${name}=${text}: not a number`);
      preset[name] = value;
    } else {
      preset[name] = text;
    }
  }
  return preset;
}

/**
 * Opens the file of a page link `?src=URL&scheme=…&tolMax=…` (teaching links, embedding): a
 * file of this site only, with the link's fit options. On a refused link or a bad file the
 * page opens the first sample and shows why.
 * @param {URLSearchParams} params
 */
async function openLink(params) {
  const src = params.get('src') ?? '';
  let problem;
  try {
    const url = new URL(src, location.href);
    if (url.origin !== location.origin) {
      throw new Error(`the page opens files of its own site only (${location.origin}), not of ${url.origin}`);
    }
    const preset = linkPreset(params);
    const response = await fetch(url);
    if (!response.ok) throw new Error(`HTTP ${response.status}`);
    const name = decodeURIComponent(url.pathname.split('/').pop() || 'file');
    if (await show(await response.blob(), name, preset)) return;
    problem = ui.error.textContent;
  } catch (e) {
    problem = `Could not open ?src=${src}: ${e?.message ?? e}`;
  }
  await openSample(ui.sample.value);
  showError(problem);
}

/** Fills the sample list from the manifest; the first sample opens at start. */
async function listSamples() {
  const response = await fetch('samples/samples.json');
  if (!response.ok) throw new Error(`samples/samples.json: HTTP ${response.status}`);
  const { samples } = await response.json();
  ui.sample.replaceChildren(...samples.map((s) => new Option(s.label, s.file)));
  samplePresets = Object.fromEntries(samples.map((s) => [s.file, s.preset]));
}

/** Fetches a bundled sample from www/samples/ and shows it. */
async function openSample(name) {
  const response = await fetch(`samples/${name}`);
  if (!response.ok) {
    showError(`Could not fetch the sample ${name}: HTTP ${response.status}`);
    setState('error');
    return;
  }
  await show(await response.blob(), name, samplePresets[name]);
}

main().catch((e) => {
  showError(`The page failed to start: ${e?.message ?? e}`);
  setState('error');
});
