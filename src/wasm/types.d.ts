// The shapes of the plain objects the bindings take and give (options, statistics, history,
// report, file format), spelt as serde writes them: the JavaScript API's objects in camelCase,
// the fit report (the CLI's `--json`) in snake_case. wasm-bindgen copies this file into
// pkg/geofit.d.ts (src/wasm/mod.rs); tests/e2e/package.test.mjs type-checks real outputs
// against it, so a field renamed in Rust fails there.

/** What is fitted. `bspline` is accepted as another name of `bspline-surface`. */
export type Scheme =
  | 'loop' | 'catmull-clark' | 'doo-sabin' | 'bspline-surface' | 'bspline-curve' | 'chaikin-curve';
/** How control points are found (`methodsFor(scheme)` lists a scheme's, its default first). */
export type Method = 'geometric' | 'least-squares' | 'knots' | 'sections';
/** How a fit stands: still iterating, or why it stopped. */
export type FitStatus = 'running' | 'converged' | 'max_iterations' | 'stalled';
/** The exports of a fit; `exportsFor(scheme)` says which a scheme offers. */
export type ExportName = 'cage' | 'creases' | 'usda' | 'json' | 'obj' | 'ply' | 'stl' | 'glb' | 'iges' | 'step' | 'msh';
/** A stage of the work that `loadFile`, `new Fitter`, `step` and `run` report progress of. */
export type Phase = 'reading' | 'repair' | 'reconstruction' | 'simplification' | 'setup' | 'iteration';
/**
 * Hears progress: `done` runs from 0 to 1 within each phase (about a hundred calls per phase
 * at most). Called synchronously from inside the work: a worker can post it to the page,
 * which stays free to draw it. An exception it throws is ignored.
 */
export type ProgressCallback = (phase: Phase, done: number) => void;
/** The file formats `loadFile` reads. */
export type FileFormat =
  | 'ply' | 'obj' | 'stl' | 'xyz' | 'e57' | 'las' | 'laz' | 'pcd' | 'ptx' | 'gltf' | 'glb';

/**
 * The options of a fit (the core's `FitSpec`). Every field may be left out (or `null`): the
 * scheme's default applies, and `defaultSpec(scheme, method)` lists them. Unknown names are
 * rejected. Tolerances are % of the bounding-box diagonal; docs/options.md says
 * which scheme and method each option applies to.
 */
export interface FitSpec {
  scheme?: Scheme | 'bspline';
  method?: Method | null;
  tolAvg?: number | null;
  tolMax?: number | null;
  tolRms?: number | null;
  initial?: number | null;
  grid?: [number, number] | null;
  maxIter?: number | null;
  refine?: boolean;
  maxControl?: number | null;
  weights?: 'basis' | 'patent';
  acceleration?: 'none' | 'relax' | 'anderson' | 'cg' | null;
  tangentWeight?: number | null;
  refineGrowth?: number | null;
  remesh?: boolean;
  cloud?: 'auto' | 'open' | 'closed';
  outliers?: number | null;
  useGrid?: boolean;
  closed?: boolean | null;
  degree?: number | null;
  tolMode?: 'exact' | 'noisy';
  beta2?: number | null;
  beta3?: number | null;
  solves?: number | null;
  view?: [number, number, number] | null;
  folded?: 'fail' | 'exclude' | 'keep';
  cornerAngle?: number | null;
  curvatureJump?: number | null;
  rows?: number | null;
  creases?: boolean;
  creaseAngle?: number | null;
}

/** A `FitSpec` with every field written out, as `defaultSpec` gives it (`null`: the data decides). */
export type ResolvedFitSpec = { [K in keyof FitSpec]-?: Exclude<FitSpec[K], undefined> } & {
  scheme: Scheme;
};

/** `Fitter.stats()`: the current errors (in % of the diagonal and in model units), the last iteration's time and flags, the tolerances in force. */
export interface FitStats {
  /** Iterations run. */
  iter: number;
  controlPoints: number;
  eAvgPct: number;
  eMaxPct: number;
  eRmsPct: number;
  eAvg: number;
  eMax: number;
  eRms: number;
  /** Bounding-box diagonal of the data, model units. */
  diagonal: number;
  /** Wall time of the last iteration. */
  ms: number;
  /** Wall time of all iterations. */
  totalMs: number;
  status: FitStatus;
  /** Whether the last iteration refined the control net. */
  refined: boolean;
  scheme: Scheme;
  method: Method;
  tolAvgPct: number | null;
  tolMaxPct: number | null;
  tolRmsPct: number | null;
  /** Surface → data: largest and 99th-percentile distance, % (`null` where not measured). */
  eBackMaxPct: number | null;
  eBackP99Pct: number | null;
  /** The E_back a converged fit stays within (twice the E_max tolerance), % (`null` without an E_max tolerance). */
  tolBackPct: number | null;
}

/** One entry of `Fitter.history()`. */
export interface HistoryEntry {
  iter: number;
  controlPoints: number;
  eAvgPct: number;
  eMaxPct: number;
  eRmsPct: number;
  ms: number;
  refined: boolean;
}

/** One entry of `FitReport.history` (snake_case, as the CLI's `--json` writes it). */
export interface IterationRecord {
  iter: number;
  control_points: number;
  e_avg_pct: number;
  e_max_pct: number;
  e_rms_pct: number;
  ms: number;
  refined: boolean;
  e_back_max_pct?: number;
  e_back_p99_pct?: number;
  /** Where a subdivision fit's iteration spent its time; the rest of `ms` is bookkeeping. */
  phases?: PhaseTimes;
}

/** One iteration's time by phase, ms (`IterationRecord.phases`). */
export interface PhaseTimes {
  /** Stencils and conjugate gradients (or the weighted error sums). */
  moves_ms: number;
  /** Refilling the patch data for the moved control points. */
  refill_ms: number;
  /** Foot points on the moved surface, damping retries included. */
  feet_ms: number;
  /** The surface → data measure. */
  back_ms: number;
  /** Splits, flips, rebuilt patches and their foot points. */
  refine_ms: number;
}

/** How many, and the first few of them. */
export interface Found<T> {
  count: number;
  first: T[];
}

/** What repairing the data mesh changed (`FitReport.simplification.repair`). */
export interface RepairReport {
  summary: string;
  non_manifold_vertices: Found<number>;
  vertices_added: number;
  non_manifold_edges: Found<[number, number]>;
  detached_faces: Found<number>;
  dropped_faces: Found<number>;
  degenerate_faces: Found<number>;
  zero_area_faces: Found<number>;
  duplicate_faces: Found<number>;
  flipped_faces: Found<number>;
  non_orientable_components: number;
  cut_edges: Found<[number, number]>;
  unreferenced_vertices: Found<number>;
  polygons: number;
  components: {
    count: number;
    largest_faces: number[];
    data_only: Found<number>;
    data_only_faces: number;
  };
}

/** How the initial control mesh was made by QEM simplification. */
export interface SimplifyReport {
  target: number;
  vertices: number;
  triangles: number;
  passes: number;
  relaxations: { at_vertices: number; max_normal_change_deg: number; min_triangle_quality: number }[];
  floor_note: string | null;
  max_valence: number;
  repair: RepairReport;
  /** Crease edges given to QEM (found on the data, `creases` on) and kept on the result. */
  creases: { input: number; output: number };
}

/** The sharp features found on the data and kept sharp on the initial control mesh
 * (`creases` on). */
export interface CreaseReport {
  angle_deg: number;
  summary: string;
  edges: number;
  lines: number;
  corners: number;
  darts: number;
  length: number;
  control_edges: number;
}

/** What was reconstructed from bare points. */
export interface ReconstructionReport {
  kind: string;
  method: string;
  outliers: number;
  vertices: number;
  triangles: number;
  /** Closed objects: triangles of the implicit surface dropped where no point was near. */
  stray_triangles: number;
  /** Points taken for an open scan that its triangulation in projection left in no triangle
   * (too many), so they were reconstructed as a closed object instead. */
  open_uncovered?: number;
  seconds: number;
}

/** The fields only a B-spline surface fit reports. */
export interface SurfaceDetails {
  control_points_u: number;
  control_points_v: number;
  folded_points: number;
  /** The face the STEP and IGES exports write: the outline of the data's parameters. */
  trim: TrimReport | { untrimmed: string };
  /** Sections method: rows fitted, σ of the signed distances (model units and %) at the end
   * and with the multiple knots only. */
  rows?: number;
  sigma?: number;
  sigma_pct?: number;
  sigma_features?: number;
  sigma_features_pct?: number;
}

/** A surface fit's trim: its loops and vertices, loops left out, and areas (model units²). */
export interface TrimReport {
  loops: number;
  vertices: number;
  dropped_loops: number;
  trimmed_area: number;
  data_area: number;
}

/** The fields only a curve fit reports (`features`, `corners`, `std_pct` for the knots method). */
export interface CurveDetails {
  degree: number;
  closed: boolean;
  domain: [number, number];
  /** 101 samples `[u, x, y, z]`. */
  samples: [number, number, number, number][];
  clamped?: { degree: number; knots: number[]; control_points: [number, number, number][] };
  features?: number;
  corners?: number;
  std_pct?: number;
}

/** The fields every fit report has. */
export interface FitReportCommon {
  scheme: Scheme;
  method: Method;
  points: number;
  initial_control_points: number;
  final_control_points: number;
  iterations: number;
  e_avg_pct: number;
  e_max_pct: number;
  e_rms_pct: number;
  e_back_max_pct?: number;
  e_back_p99_pct?: number;
  converged: boolean;
  status: FitStatus;
  within_tolerance_pct: number | null;
  deviation: DeviationReport;
  reconstruction?: ReconstructionReport;
  simplification?: SimplifyReport;
  creases?: CreaseReport;
  strays?: { indices: number[] };
  /** The iteration whose control points a fit that stopped unconverged went back to. */
  ended_at_iteration?: number;
  intake: string[];
  precompute_s: number;
  fit_s: number;
  total_s: number;
  history: IterationRecord[];
}

/** The report's `deviation`: the signed point deviations' figures (model units, percentiles of |d|). */
export interface DeviationReport {
  points: number;
  mean: number;
  sigma: number;
  p50: number;
  p90: number;
  p95: number;
  p99: number;
  max: number;
  tolerance: number | null;
  within_tolerance_pct: number | null;
}

/** `JSON.parse(fitter.reportJson())`: set-up, final errors, times and history of a fit. */
export type FitReport = FitReportCommon & (SurfaceDetails | CurveDetails | {});

/** The options of `Fitter.exportFem`: element size (`size`, model units) or count, not both. */
export interface FemExportOptions {
  /** Target edge length in flat parts, model units. */
  size?: number | null;
  /** Number of elements (default 10,000 when no size is given). */
  count?: number | null;
  /** How much curvature shrinks the elements (default 4). */
  grading?: number | null;
  /** `'msh'` (Gmsh 4.1 ASCII, default) or `'obj'` (OBJ quads). */
  format?: 'msh' | 'obj' | null;
  /** A B-spline surface is meshed over its data's outline (as STEP/IGES are trimmed); `true` meshes the whole domain. */
  untrimmed?: boolean | null;
}

/** Element quality of a FEM quad mesh (`FemQuality` in the core). */
export interface FemQuality {
  elements: number;
  nodes: number;
  aspectMin: number;
  aspectMean: number;
  aspectMax: number;
  skewMaxDeg: number;
  skewMeanDeg: number;
  jacobianMin: number;
  inverted: number;
  onFolds: number;
  invertedOffFolds: number;
}

/** What `Fitter.exportFem` returns: the file and the mesh's quality. */
export interface FemExport {
  bytes: Uint8Array;
  quality: FemQuality;
}

/**
 * `Fitter.deviations(bins)`: the signed errors' figures (model units; percentiles of |d|) and
 * their histogram over -halfWidth..halfWidth (the end bins also hold the points beyond).
 */
export interface Deviation {
  points: number;
  mean: number;
  sigma: number;
  p50: number;
  p90: number;
  p95: number;
  p99: number;
  max: number;
  tolerance: number | null;
  withinTolerancePct: number | null;
  halfWidth: number;
  counts: number[];
  below: number;
  above: number;
}
