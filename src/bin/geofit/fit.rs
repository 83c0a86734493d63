//! `geofit fit FILE [--scheme S] [options]`: fit any scheme — a Loop, Catmull–Clark or Doo–Sabin
//! subdivision surface, one B-spline surface, or a B-spline / Chaikin curve — to a scan. The
//! flags fill a [`FitSpec`] (every default and range check is the core's); one line per
//! iteration, a summary, and the files asked for.

use crate::output::read_input;
use geofit::export::{self, EXPORT_RESOLUTION};
use geofit::fem::{self, FemOptions};
use geofit::fit::{Acceleration, FoldPolicy, TolMode};
use geofit::fit::{
    Cloud, FitData, FitError, FitReport, FitSpec, FitStatus, Fitter, Method, Scheme, Shape, Spline,
    Weighting, OPTION_TABLE,
};
use geofit::geom::Vec3;
use geofit::spline::BSplineSurface;
use serde::Serialize;
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `geofit fit`. Left out, an option takes the core's default for the scheme
/// (listed after the options by `geofit fit --help`).
#[derive(clap::Args)]
#[command(after_help = defaults_help())]
pub struct Args {
    /// Data file (PLY, OBJ, STL, XYZ/CSV/PTS). Every vertex is a data point, also those in no
    /// face; curves take an OBJ polyline or the points in file order.
    file: PathBuf,
    /// What is fitted: loop, catmull-clark, doo-sabin, bspline-surface (alias bspline),
    /// bspline-curve, chaikin-curve.
    #[arg(long, default_value = "loop", value_parser = parse::<Scheme>)]
    scheme: Scheme,
    /// How control points are found: geometric, least-squares (B-spline surface), knots
    /// (curves).
    #[arg(long, value_parser = parse::<Method>)]
    method: Option<Method>,
    /// Tolerance on E_avg, % of the bounding-box diagonal (giving any tolerance means only the
    /// given ones count).
    #[arg(long)]
    tol_avg: Option<f64>,
    /// Tolerance on E_max, %.
    #[arg(long)]
    tol_max: Option<f64>,
    /// Tolerance on E_rms, %.
    #[arg(long)]
    tol_rms: Option<f64>,
    /// Initial control points: vertices of the QEM-simplified control mesh (subdivision), or
    /// about that many in a square grid (B-spline surface).
    #[arg(long, conflicts_with = "control")]
    initial: Option<usize>,
    /// B-spline surface: exactly N control points in a √N × √N grid, knots kept fixed.
    #[arg(long, conflicts_with_all = ["ctrl_u", "ctrl_v", "initial"])]
    ctrl: Option<usize>,
    /// B-spline surface: control points along u (with --ctrl-v), knots kept fixed.
    #[arg(long, requires = "ctrl_v")]
    ctrl_u: Option<usize>,
    /// B-spline surface: control points along v (with --ctrl-u).
    #[arg(long, requires = "ctrl_u")]
    ctrl_v: Option<usize>,
    /// Subdivision: start from this control mesh instead of simplifying the data.
    #[arg(long)]
    control: Option<PathBuf>,
    /// Iteration cap (knot insertions for the knots method).
    #[arg(long)]
    max_iter: Option<usize>,
    /// Control-point budget of refinement.
    #[arg(long)]
    max_control: Option<usize>,
    /// Never split control faces / insert knots.
    #[arg(long)]
    no_refine: bool,
    /// Subdivision (Loop): no edge flips after a refinement.
    #[arg(long)]
    no_remesh: bool,
    /// Subdivision: error-vector weighting, basis or patent.
    #[arg(long, value_parser = parse::<Weighting>)]
    weights: Option<Weighting>,
    /// Acceleration of the geometric iteration: none, relax, anderson, cg.
    #[arg(long, value_parser = parse::<Acceleration>)]
    accel: Option<Acceleration>,
    /// Subdivision with cg: weight of the tangential error relative to the normal one, (0, 1].
    #[arg(long)]
    tangent_weight: Option<f64>,
    /// Subdivision: one refinement adds at most this fraction of the control points.
    #[arg(long)]
    refine_growth: Option<f64>,
    /// Subdivision, files without faces: auto, open or closed surface to reconstruct.
    #[arg(long, value_parser = parse::<Cloud>)]
    cloud: Option<Cloud>,
    /// Subdivision, files without faces: drop points whose mean neighbour distance is this
    /// many standard deviations above the mean (they are not fitted either).
    #[arg(long, alias = "remove-outliers")]
    outliers: Option<f64>,
    /// Subdivision, files without faces: ignore the file's range grid (triangulate by
    /// Delaunay).
    #[arg(long)]
    no_grid: bool,
    /// Curves: fit a closed (periodic) curve; implied by an OBJ polyline that ends where it
    /// starts.
    #[arg(long)]
    closed: bool,
    /// Degree (B-spline surface, B-spline curve).
    #[arg(long)]
    degree: Option<usize>,
    /// B-spline surface: how patches are judged against --tol-max, exact or noisy.
    #[arg(long, value_parser = parse::<TolMode>)]
    tol_mode: Option<TolMode>,
    /// B-spline surface, least squares: thin-plate weight β2.
    #[arg(long)]
    beta2: Option<f64>,
    /// B-spline surface, least squares: curvature-variation weight β3.
    #[arg(long)]
    beta3: Option<f64>,
    /// B-spline surface, least squares: solves (each with parameter correction) per knot
    /// vector.
    #[arg(long)]
    solves: Option<usize>,
    /// B-spline surface: view direction "x,y,z" of the projection.
    #[arg(long, value_parser = parse_vec3)]
    view: Option<Vec3>,
    /// B-spline surface: points on a fold-over of the projection, fail, exclude or keep.
    #[arg(long, value_parser = parse::<FoldPolicy>)]
    folded: Option<FoldPolicy>,
    /// Curves, knots method: angle that makes a corner, degrees.
    #[arg(long)]
    corner_angle: Option<f64>,
    /// Curves, knots method: second-derivative jump that makes a double knot, 1 / diagonal.
    #[arg(long)]
    curvature_jump: Option<f64>,
    /// B-spline surface, sections method: points per row of an XYZ file in rows (default: a
    /// row starts at every jump; a range scan's rows are its grid's).
    #[arg(long)]
    rows: Option<usize>,
    /// Subdivision and B-spline surfaces: find the data's sharp creases and keep them sharp
    /// (subdivision: QEM keeps them as edge chains of the control mesh, which tags them as
    /// creases; B-spline surface: creases that run along a parameter line become C0 knot lines)
    #[arg(long)]
    creases: bool,
    /// With --creases: dihedral angle above which a data edge is a crease, degrees.
    #[arg(long)]
    crease_angle: Option<f64>,
    /// Write the report (set-up, final errors, times, per-iteration history) as JSON.
    #[arg(long)]
    json: Option<PathBuf>,
    /// Write the final control net as OBJ (a curve's polygon as a polyline); a subdivision
    /// cage with creases gets their sidecar beside it (`NAME.creases.json`).
    #[arg(long)]
    cage: Option<PathBuf>,
    /// Loop and Catmull–Clark: write the final cage as USD (`.usda`), creases included, for
    /// OpenSubdiv-based tools.
    #[arg(long)]
    usda: Option<PathBuf>,
    /// Write the fitted surface, tessellated, as OBJ (a B-spline surface cut to its trim).
    #[arg(long)]
    limit: Option<PathBuf>,
    /// Segments per patch edge of the --limit tessellation.
    #[arg(long, default_value_t = EXPORT_RESOLUTION)]
    limit_segments: usize,
    /// B-spline surface: write the fitted surface (degree, knots, control grid, parameters) as
    /// JSON.
    #[arg(long)]
    surface_json: Option<PathBuf>,
    /// Surface: export as GLB (binary glTF: triangles, normals, the signed deviation as vertex
    /// colours and as `_DEVIATION`, the fit's figures in `extras`, metres when the input's unit
    /// is known).
    #[arg(long)]
    glb: Option<PathBuf>,
    /// B-spline surface or curve: export as IGES 5.3.
    #[arg(long)]
    iges: Option<PathBuf>,
    /// B-spline surface or curve: export as STEP AP214.
    #[arg(long)]
    step: Option<PathBuf>,
    /// B-spline or Catmull–Clark surface: write a quad mesh for finite-element analysis, as Gmsh
    /// MSH 4.1 ASCII, or as OBJ quads when the name ends in `.obj`; prints its element quality.
    #[arg(long)]
    fem: Option<PathBuf>,
    /// --fem: target element edge length (model units) where the surface is flat.
    #[arg(long, conflicts_with = "fem_count")]
    fem_size: Option<f64>,
    /// --fem: about this many elements instead of --fem-size (default 10000).
    #[arg(long)]
    fem_count: Option<usize>,
    /// --fem: curvature grading g, about g elements per radian where the surface is curved
    /// (0: uniform; default 4).
    #[arg(long)]
    fem_grading: Option<f64>,
    /// --fem of a B-spline surface: mesh the whole domain, not only the data's outline (the
    /// region the STEP and IGES exports are trimmed to).
    #[arg(long)]
    fem_untrimmed: bool,
    /// Print only the summary, not one line per iteration.
    #[arg(long, short)]
    quiet: bool,
}

/// A clap value parser for the core's named enums (one table of names).
fn parse<T: std::str::FromStr<Err = String>>(s: &str) -> Result<T, String> {
    s.parse()
}

fn parse_vec3(s: &str) -> Result<Vec3, String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>().map_err(|e| format!("{x:?}: {e}")))
        .collect::<Result<_, _>>()?;
    match v.as_slice() {
        [x, y, z] => Ok(Vec3::new(*x, *y, *z)),
        _ => Err(format!("expected x,y,z, got {s:?}")),
    }
}

/// The defaults of every scheme, from the core, for `--help`.
fn defaults_help() -> String {
    let mut out = String::from(
        "Defaults by scheme (the core's FitSpec::defaults; `--no-X` turns off a default-on X; \
         subdivision's initial count and budget come from the data: n/60 initial vertices (at least 200), \
         half the points as budget; a curve is closed when its polyline is):\n",
    );
    for &scheme in Scheme::ALL {
        let d = FitSpec::defaults(scheme);
        let value = serde_json::to_value(&d).unwrap_or_default();
        let fields: Vec<String> = FitSpec::options_for(scheme, d.method())
            .into_iter()
            .filter(|name| *name != "scheme")
            .filter_map(|name| {
                let v = value.get(name)?;
                let v = v.to_string();
                (v != "null").then(|| format!("{}={}", kebab(name), v.trim_matches('"')))
            })
            .collect();
        out.push_str(&format!("  {scheme}: {}\n", fields.join(" ")));
    }
    out
}

/// `tolAvg` as `tol-avg`.
fn kebab(name: &str) -> String {
    let mut out = String::new();
    for c in name.chars() {
        if c.is_ascii_uppercase() {
            out.push('-');
        }
        out.push(c.to_ascii_lowercase());
    }
    out
}

/// The command-line flag of a spec field.
fn flag_of(name: &str) -> &'static str {
    OPTION_TABLE
        .iter()
        .find(|o| o.name == name)
        .map_or("?", |o| o.flag)
}

impl Args {
    /// The spec the flags describe.
    fn spec(&self) -> Result<FitSpec, String> {
        let mut spec = FitSpec::new(self.scheme);
        spec.method = self.method;
        (spec.tol_avg, spec.tol_max, spec.tol_rms) = (self.tol_avg, self.tol_max, self.tol_rms);
        spec.initial = self.initial;
        spec.grid = self.ctrl_u.zip(self.ctrl_v).map(|(u, v)| [u, v]);
        if let Some(n) = self.ctrl {
            let side = (n as f64).sqrt().round() as usize;
            if side * side != n {
                return Err(format!(
                    "--ctrl {n} is not a square; use --ctrl-u and --ctrl-v"
                ));
            }
            spec.grid = Some([side, side]);
        }
        spec.refine = !self.no_refine && spec.grid.is_none();
        spec.max_iter = self.max_iter;
        spec.max_control = self.max_control;
        spec.remesh = !self.no_remesh;
        spec.weights = self.weights.unwrap_or(spec.weights);
        spec.acceleration = self.accel;
        spec.tangent_weight = self.tangent_weight;
        spec.refine_growth = self.refine_growth;
        spec.cloud = self.cloud.unwrap_or(spec.cloud);
        spec.outliers = self.outliers;
        spec.use_grid = !self.no_grid;
        spec.closed = self.closed.then_some(true);
        spec.degree = self.degree;
        spec.tol_mode = self.tol_mode.unwrap_or(spec.tol_mode);
        (spec.beta2, spec.beta3, spec.solves) = (self.beta2, self.beta3, self.solves);
        spec.view = self.view.map(|v| v.to_array());
        spec.folded = self.folded.unwrap_or(spec.folded);
        (spec.corner_angle, spec.curvature_jump) = (self.corner_angle, self.curvature_jump);
        spec.rows = self.rows;
        (spec.creases, spec.crease_angle) = (self.creases, self.crease_angle);
        self.check_outputs()?;
        Ok(spec)
    }

    /// The output files the scheme cannot write are errors, not silently skipped.
    fn check_outputs(&self) -> Result<(), String> {
        let s = self.scheme;
        let spline = s == Scheme::BsplineSurface || s.is_curve();
        for (flag, given, ok) in [
            ("--iges", self.iges.is_some(), spline),
            ("--step", self.step.is_some(), spline),
            ("--limit", self.limit.is_some(), !s.is_curve()),
            ("--glb", self.glb.is_some(), !s.is_curve()),
            (
                "--fem",
                self.fem.is_some(),
                matches!(s, Scheme::BsplineSurface | Scheme::CatmullClark),
            ),
            (
                "--surface-json",
                self.surface_json.is_some(),
                s == Scheme::BsplineSurface,
            ),
            (
                "--control",
                self.control.is_some(),
                s.subdivision().is_some(),
            ),
            (
                "--ctrl",
                self.ctrl.is_some() || self.ctrl_u.is_some(),
                s == Scheme::BsplineSurface,
            ),
        ] {
            if given && !ok {
                return Err(format!("{flag} does not apply to --scheme {s}"));
            }
        }
        let fem_flags = [
            self.fem_size.is_some(),
            self.fem_count.is_some(),
            self.fem_grading.is_some(),
            self.fem_untrimmed,
        ];
        if self.fem.is_none() && fem_flags.contains(&true) {
            return Err(
                "--fem-size, --fem-count, --fem-grading and --fem-untrimmed need --fem FILE".into(),
            );
        }
        Ok(())
    }
}

/// A spec error in the command line's words: flags, not field names.
fn cli_error(e: FitError) -> String {
    match e {
        FitError::NotApplicable {
            name,
            scheme,
            method: Some(method),
        } => {
            let info = OPTION_TABLE.iter().find(|o| o.name == name);
            let methods: Vec<String> = scheme
                .methods()
                .iter()
                .filter(|m| info.is_some_and(|o| o.applies(scheme, **m)))
                .map(|m| m.to_string())
                .collect();
            format!(
                "--{} does not apply to --scheme {scheme} --method {method} (with --scheme {scheme} it applies to --method {})",
                flag_of(name),
                methods.join(", ")
            )
        }
        FitError::NotApplicable { name, scheme, .. } => {
            let info = OPTION_TABLE.iter().find(|o| o.name == name);
            let schemes: Vec<&str> = Scheme::ALL
                .iter()
                .filter(|s| info.is_some_and(|o| o.applies(**s, s.default_method())))
                .map(|s| s.name())
                .collect();
            format!(
                "--{} does not apply to --scheme {scheme} (it applies to {})",
                flag_of(name),
                schemes.join(", ")
            )
        }
        FitError::InvalidOption { name, reason } => format!("--{}: {reason}", flag_of(name)),
        other => other.to_string(),
    }
}

/// Runs `f` showing the phase under way and how far it is on one line of stderr, when stderr
/// is a terminal and the run is not quiet (a big scan's set-up takes seconds to minutes).
fn with_progress_line<R>(quiet: bool, f: impl FnOnce() -> R) -> R {
    use std::io::{IsTerminal, Write};
    if quiet || !std::io::stderr().is_terminal() {
        return f();
    }
    let sink = |phase: geofit::progress::Phase, done: f64| {
        let mut err = std::io::stderr();
        let _ = write!(err, "\r\x1b[2K{} {:3.0} %", phase.name(), 100.0 * done);
        let _ = err.flush();
    };
    let result = geofit::progress::watch(Box::new(sink), f);
    eprint!("\r\x1b[2K");
    result
}

/// Reads the file, builds the fitter, iterates and writes the outputs asked for.
///
/// The file's mesh (and a `--control` mesh) is dropped as soon as the fitter is built: the
/// fitter owns its own copy of the points and its own reference surface for E_back and never
/// reads the file's mesh again, so holding it through the iterations was a second copy of the
/// data in memory. On the 2.2-million-point scan of `scripts/bench_big.sh` its f64 positions
/// and face lists are 125 MB resident (56 bytes a data point); the peak RSS of the default fit
/// there, which comes at the end of the set-up while the mesh is still read, fell from 1,545 to
/// 1,461 MB.
pub fn run(args: Args) -> Result<(), String> {
    let start = Instant::now();
    let spec = args.spec()?;
    spec.validate().map_err(cli_error)?;
    let file = with_progress_line(args.quiet, || read_input(&args.file))?;
    let control = match &args.control {
        Some(path) => Some(read_input(path)?.mesh),
        None => None,
    };
    let data = FitData {
        control: control.as_ref(),
        ..FitData::from(&file)
    };
    let read_s = start.elapsed().as_secs_f64();
    let mut fitter = with_progress_line(args.quiet, || spec.build(&data))
        .map_err(|e| format!("{}: {}", args.file.display(), cli_error(e)))?;
    fitter.log_mut().add_precompute(read_s);
    let unit_to_metres = file.unit_to_metres;
    drop((file, control));
    drive(fitter.as_mut(), &args)?;
    write_outputs(fitter.as_ref(), &args, unit_to_metres)
}

/// Iterates to the end, printing one line per iteration unless quiet, then the summary.
fn drive(fitter: &mut dyn Fitter, args: &Args) -> Result<(), String> {
    if !args.quiet {
        for note in fitter.log().intake_notes() {
            outln!("{note}");
        }
    }
    let s = fitter.stats();
    if !args.quiet {
        outln!(
            "start  ctrl {:>6}  E_avg {:.5}%  E_max {:.5}%  E_rms {:.5}%  ({} points, precompute {:.3} s)",
            fitter.num_control_points(),
            s.e_avg_pct,
            s.e_max_pct,
            s.e_rms_pct,
            fitter.data().len(),
            fitter.log().precompute_seconds()
        );
    }
    loop {
        let before = fitter.history().len();
        let status = fitter.step().map_err(|e| e.to_string())?;
        match fitter.history().last() {
            Some(r) if !args.quiet && fitter.history().len() > before => {
                outln!(
                "iter {:>3}  ctrl {:>6}  E_avg {:.5}%  E_max {:.5}%  E_rms {:.5}%{}  {:7.1} ms{}",
                r.iter,
                r.control_points,
                r.e_avg_pct,
                r.e_max_pct,
                r.e_rms_pct,
                r.e_back_max_pct.zip(r.e_back_p99_pct).map_or(String::new(), |(b, p)| {
                    format!("  E_back {b:.4}% (p99 {p:.4}%)")
                }),
                r.ms,
                if r.refined { "  refined" } else { "" }
            )
            }
            _ => {}
        }
        if status != FitStatus::Running {
            break;
        }
    }
    let report = FitReport::of(fitter);
    let within = report.within_tolerance_pct.map_or(String::new(), |w| {
        format!(" ({w:.2}% of points within E_max tolerance)")
    });
    let back = report
        .e_back_max_pct
        .map_or(String::new(), |b| format!(", E_back {b:.4}%"));
    let back = match report.ended_at_iteration {
        Some(k) => format!("{back} (iteration {k}'s control points: the best)"),
        None => back,
    };
    outln!(
        "{}: {} after {} iterations, {} -> {} control points, E_avg {:.5}% E_max {:.5}% E_rms {:.5}%{}{}, precompute {:.2} s, fit {:.2} s, total {:.2} s",
        report.scheme,
        match report.status {
            FitStatus::Converged => "converged",
            FitStatus::Stalled => "stalled",
            _ => "stopped",
        },
        report.iterations,
        report.initial_control_points,
        report.final_control_points,
        report.e_avg_pct,
        report.e_max_pct,
        report.e_rms_pct,
        within,
        back,
        report.precompute_s,
        report.fit_s,
        report.total_s
    );
    Ok(())
}

/// Writes the files asked for.
fn write_outputs(
    fitter: &dyn Fitter,
    args: &Args,
    unit_to_metres: Option<f64>,
) -> Result<(), String> {
    let name = args
        .file
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("geofit");
    let text = |r: Result<String, export::ExportError>| r.map(String::into_bytes);
    type Make<'a> = Box<dyn Fn() -> Result<Vec<u8>, String> + 'a>;
    let sidecar = args
        .cage
        .as_ref()
        .filter(|_| has_creases(fitter))
        .map(|p| p.with_extension("creases.json"));
    let outputs: [(&Option<PathBuf>, Make); 9] = [
        (
            &args.json,
            Box::new(|| json_text(&FitReport::of(fitter), true)),
        ),
        (
            &args.cage,
            Box::new(|| export::cage_obj(fitter).map_err(|e| e.to_string())),
        ),
        (
            &sidecar,
            Box::new(|| text(export::cage_creases_json(fitter)).map_err(|e| e.to_string())),
        ),
        (
            &args.usda,
            Box::new(|| text(export::cage_usda(fitter)).map_err(|e| e.to_string())),
        ),
        (
            &args.limit,
            Box::new(|| limit_obj(fitter, args.limit_segments)),
        ),
        (
            &args.iges,
            Box::new(|| text(export::iges_of(fitter, name)).map_err(|e| e.to_string())),
        ),
        (
            &args.step,
            Box::new(|| text(export::step_of(fitter, name)).map_err(|e| e.to_string())),
        ),
        (&args.surface_json, Box::new(|| surface_json(fitter))),
        (
            &args.glb,
            Box::new(|| export::glb_of(fitter, unit_to_metres).map_err(|e| e.to_string())),
        ),
    ];
    for (path, make) in outputs {
        if let Some(path) = path {
            let bytes = make()?;
            std::fs::write(path, bytes).map_err(|e| format!("{}: {e}", path.display()))?;
        }
    }
    if let Some(path) = &args.fem {
        write_fem(fitter, args, path)?;
    }
    Ok(())
}

/// Whether the fit's cage has crease edges.
fn has_creases(fitter: &dyn Fitter) -> bool {
    fitter
        .subdiv_surface()
        .is_some_and(|s| !s.control_mesh().creases().is_empty())
}

/// The FEM quad mesh of the fitted surface, written as MSH (OBJ for a `.obj` name), and its
/// quality printed.
fn write_fem(fitter: &dyn Fitter, args: &Args, path: &std::path::Path) -> Result<(), String> {
    let mut options = FemOptions::default().with_trim(!args.fem_untrimmed);
    if let Some(l) = args.fem_size {
        options = options.with_edge(l);
    }
    if let Some(n) = args.fem_count {
        options = options.with_count(n);
    }
    if let Some(g) = args.fem_grading {
        options = options.with_grading(g);
    }
    let start = Instant::now();
    let fem = fem::mesh_fit(fitter, &options).map_err(|e| format!("--fem: {e}"))?;
    let mesh_s = start.elapsed().as_secs_f64();
    let obj = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("obj"));
    let bytes = if obj {
        geofit::io::to_obj_bytes(fem.mesh())
    } else {
        geofit::io::to_msh_bytes(fem.mesh())
    };
    let bytes = bytes.map_err(|e| format!("--fem: {e}"))?;
    std::fs::write(path, bytes).map_err(|e| format!("{}: {e}", path.display()))?;
    let q = fem.quality();
    outln!(
        "FEM mesh: {} quads, {} nodes in {:.3} s; aspect ratio {:.2} / {:.2} / {:.2} (min / mean / max), skew max {:.1}°, scaled Jacobian min {:.3}, {} inverted ({} across {} elements on folds of the surface) -> {}",
        q.elements,
        q.nodes,
        mesh_s,
        q.aspect_min,
        q.aspect_mean,
        q.aspect_max,
        q.skew_max_deg,
        q.jacobian_min,
        q.inverted,
        q.inverted - q.inverted_off_folds,
        q.on_folds,
        path.display()
    );
    Ok(())
}

/// `value` as JSON text, indented when `pretty`.
fn json_text(value: &impl Serialize, pretty: bool) -> Result<Vec<u8>, String> {
    let text = if pretty {
        serde_json::to_string_pretty(value)
    } else {
        serde_json::to_string(value)
    };
    text.map(String::into_bytes).map_err(|e| e.to_string())
}

/// The fitted surface tessellated with `segments` per patch edge, as OBJ: a B-spline surface
/// cut to its trim, as the page draws it and every other export writes it (the rectangle
/// beyond the data curls away from it: bun000's least-squares fit at E_max 0.05 % reached
/// 23 % of the diagonal from the data there).
fn limit_obj(fitter: &dyn Fitter, segments: usize) -> Result<Vec<u8>, String> {
    match geofit::export::surface_shape(fitter, segments) {
        Shape::Mesh(mesh) => geofit::io::to_obj_bytes(&mesh).map_err(|e| e.to_string()),
        Shape::Polyline { .. } => Err("--limit: a curve has no surface".into()),
    }
}

/// A B-spline surface fit's surface and the data points' parameters on it, as JSON.
fn surface_json(fitter: &dyn Fitter) -> Result<Vec<u8>, String> {
    let Some(Spline::Surface { surface, params }) = fitter.spline() else {
        return Err("--surface-json: the fit has no B-spline surface".into());
    };
    json_text(&SurfaceJson::of(surface, params), false)
}

/// The fitted surface as plain data.
#[derive(Serialize)]
struct SurfaceJson<'a> {
    degree_u: usize,
    degree_v: usize,
    knots_u: &'a [f64],
    knots_v: &'a [f64],
    control_points_u: usize,
    control_points_v: usize,
    /// Row-major in u: index i · control_points_v + j.
    control_points: Vec<[f64; 3]>,
    /// Foot-point parameters (u, v) of every data point, in data order.
    parameters: &'a [[f64; 2]],
}

impl<'a> SurfaceJson<'a> {
    fn of(s: &'a BSplineSurface, parameters: &'a [[f64; 2]]) -> SurfaceJson<'a> {
        let (nu, nv) = s.num_control();
        SurfaceJson {
            degree_u: s.knots_u().degree(),
            degree_v: s.knots_v().degree(),
            knots_u: s.knots_u().knots(),
            knots_v: s.knots_v().knots(),
            control_points_u: nu,
            control_points_v: nv,
            control_points: s.control_points().iter().map(|p| p.to_array()).collect(),
            parameters,
        }
    }
}
