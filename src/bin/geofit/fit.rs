//! `geofit fit FILE --scheme loop|catmull-clark|doo-sabin ...`: fit a subdivision surface to a
//! scan by geometric iteration, print one line per iteration, optionally write a JSON report,
//! the control mesh and the limit surface.

use clap::ValueEnum;
use geofit::cloud::{ReconstructOptions, SurfaceKind};
use geofit::fit::{
    build_subdiv_fitter, Acceleration, FitReport, FitStatus, Fitter, SubdivFitOptions, SubdivSetup,
    Tolerances, Weighting,
};
use geofit::mesh::PolyMesh;
use geofit::subdiv::Scheme;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Surface kinds `geofit fit` can produce.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum SchemeArg {
    /// Loop subdivision surface (triangle control mesh).
    Loop,
    /// Catmull–Clark subdivision surface (quad control mesh).
    CatmullClark,
    /// Doo–Sabin subdivision surface.
    DooSabin,
    /// One tensor-product B-spline surface (options under "B-spline surface"; --tol-max
    /// defaults to 0.1 there, and the JSON report is printed).
    Bspline,
}

/// Error-vector weighting.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum WeightsArg {
    /// The patent's barycentric / bilinear weights over the 1-ring faces.
    Patent,
    /// Basis (limit-stencil) weights of every influencing control point (LSPIA).
    Basis,
}

/// Acceleration of the iteration.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum AccelArg {
    /// Plain iteration P ← P + d.
    None,
    /// Constant over-relaxation P ← P + 1.5 d.
    Relax,
    /// Anderson acceleration over the last 5 iterates.
    Anderson,
    /// 12 conjugate-gradient steps per iteration on the frozen foot parameters (basis weights).
    Cg,
}

/// How a point file without faces is turned into a mesh to start from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum CloudArg {
    /// Decide from the data (a range grid, or normals mostly facing one side, mean open).
    Auto,
    /// An open single-view scan: range grid or Delaunay on the best-fit plane.
    Open,
    /// A closed object: oriented normals and an implicit surface.
    Closed,
}

/// Arguments of `geofit fit`.
#[derive(clap::Args)]
#[command(after_help = "\
Without --initial the initial control mesh has n/60 vertices for n data points (at least 50, at \
most 20,000, and never more than the data mesh has), a density at which QEM keeps the shape of \
scans like the Stanford bunny (35,947 points -> 599). Point files without faces are first reconstructed into a mesh (see --cloud, --outliers; as `geofit reconstruct`), which QEM then simplifies; the fit runs on the original points. Tolerances are % of the data's bounding-box \
diagonal; a fit stops when every tolerance given is met (with none given: --tol-avg 0.01 \
--tol-max 0.05) or after --max-iter iterations.")]
pub struct Args {
    /// Data file (PLY, OBJ, STL, XYZ/CSV/PTS). Every vertex is a data point, also those in no face.
    file: PathBuf,
    /// Surface scheme.
    #[arg(long, value_enum, default_value = "loop")]
    scheme: SchemeArg,
    /// Vertex count of the initial control mesh made from the data by QEM simplification.
    #[arg(long, conflicts_with = "control")]
    initial: Option<usize>,
    /// Start from this control mesh instead of simplifying the data.
    #[arg(long)]
    control: Option<PathBuf>,
    /// Point files without faces: the kind of surface to reconstruct before simplifying.
    #[arg(long, value_enum, default_value = "auto")]
    cloud: CloudArg,
    /// Point files without faces: statistical outlier removal, dropping points whose mean
    /// neighbour distance is this many standard deviations above the mean (they are not
    /// fitted either).
    #[arg(long, alias = "remove-outliers")]
    outliers: Option<f64>,
    /// Point files without faces: ignore the file's range grid (triangulate by Delaunay).
    #[arg(long)]
    no_grid: bool,
    /// Tolerance on E_avg, % of the bounding-box diagonal.
    #[arg(long)]
    tol_avg: Option<f64>,
    /// Tolerance on E_max, %.
    #[arg(long)]
    tol_max: Option<f64>,
    /// Tolerance on E_rms, %.
    #[arg(long)]
    tol_rms: Option<f64>,
    /// Iteration cap.
    #[arg(long, default_value_t = 200)]
    max_iter: usize,
    /// Control-point budget for refinement (default: half the number of data points).
    #[arg(long)]
    max_control: Option<usize>,
    /// Never split control faces.
    #[arg(long)]
    no_refine: bool,
    /// No edge flips after a refinement (Loop).
    #[arg(long)]
    no_remesh: bool,
    /// Error-vector weighting.
    #[arg(long, value_enum, default_value = "basis")]
    weights: WeightsArg,
    /// Acceleration [default: cg with basis weights, none with patent weights].
    #[arg(long, value_enum)]
    accel: Option<AccelArg>,
    /// With --accel cg: weight of the tangential error relative to the normal one, in (0, 1]
    /// [default: 0.1].
    #[arg(long)]
    tangent_weight: Option<f64>,
    /// One refinement adds at most this fraction of the current control points [default: 3,
    /// so the out-of-tolerance faces decide; the budget caps it].
    #[arg(long)]
    refine_growth: Option<f64>,
    /// Write the report (setup, final errors, times, per-iteration history) as JSON.
    #[arg(long)]
    json: Option<PathBuf>,
    /// Write the final control mesh as OBJ.
    #[arg(long)]
    cage: Option<PathBuf>,
    /// Write the limit surface, tessellated, as OBJ.
    #[arg(long)]
    limit: Option<PathBuf>,
    /// Segments per patch edge of the --limit tessellation.
    #[arg(long, default_value_t = 4)]
    limit_segments: usize,
    /// Print only the summary, not one line per iteration.
    #[arg(long, short)]
    quiet: bool,
    #[command(flatten)]
    bspline: crate::fit_bspline::BsplineArgs,
}

impl Args {
    fn options(&self) -> SubdivFitOptions {
        let tolerances = Tolerances::given_or_default(self.tol_avg, self.tol_max, self.tol_rms);
        let mut options = SubdivFitOptions::default()
            .with_tolerances(tolerances)
            .with_max_iter(self.max_iter)
            .with_max_control(self.max_control)
            .with_refine(!self.no_refine)
            .with_remesh(!self.no_remesh)
            .with_weighting(match self.weights {
                WeightsArg::Patent => Weighting::Patent,
                WeightsArg::Basis => Weighting::Basis,
            })
            .with_acceleration(
                match self.accel.unwrap_or(match self.weights {
                    WeightsArg::Basis => AccelArg::Cg,
                    WeightsArg::Patent => AccelArg::None,
                }) {
                    AccelArg::None => Acceleration::None,
                    AccelArg::Relax => Acceleration::Relax { omega: 1.5 },
                    AccelArg::Anderson => Acceleration::Anderson { depth: 5 },
                    AccelArg::Cg => Acceleration::cg(),
                },
            );
        if let Some(w) = self.tangent_weight {
            options = options.with_tangent_weight(w);
        }
        if let Some(g) = self.refine_growth {
            options.refine_growth = g;
        }
        options
    }

    fn cloud(&self) -> ReconstructOptions {
        ReconstructOptions::default()
            .with_kind(match self.cloud {
                CloudArg::Auto => None,
                CloudArg::Open => Some(SurfaceKind::Open),
                CloudArg::Closed => Some(SurfaceKind::Closed),
            })
            .with_outlier_std_ratio(self.outliers)
    }
}

fn read(path: &Path) -> Result<PolyMesh, String> {
    geofit::io::read_path(path)
        .map(|loaded| loaded.mesh)
        .map_err(|e| format!("{}: {e}", path.display()))
}

pub fn run(args: Args) -> Result<(), String> {
    let scheme = match args.scheme {
        SchemeArg::Loop => Scheme::Loop,
        SchemeArg::CatmullClark => Scheme::CatmullClark,
        SchemeArg::DooSabin => Scheme::DooSabin,
        SchemeArg::Bspline => return run_bspline(&args),
    };
    if let Some(flag) = args.bspline.first_given() {
        return Err(format!("{flag} applies to --scheme bspline only"));
    }
    let start = Instant::now();
    let file =
        geofit::io::read_path(&args.file).map_err(|e| format!("{}: {e}", args.file.display()))?;
    let control = args.control.as_deref().map(read).transpose()?;
    let grid = file.range_grid.as_ref().filter(|_| !args.no_grid);
    let setup = build_subdiv_fitter(
        &file.mesh,
        grid,
        &args.cloud(),
        scheme,
        control,
        args.initial,
        args.options(),
    )
    .map_err(|e| format!("{}: {e}", args.file.display()))?;
    // Reading, reconstruction and QEM count as precompute; the report adds the fitter's own
    // set-up time.
    let before_fitter =
        (start.elapsed().as_secs_f64() - setup.fitter.precompute_seconds()).max(0.0);
    drive(setup, before_fitter, &args)
}

/// The `--scheme bspline` branch: the shared options that apply, then the B-spline fit.
fn run_bspline(args: &Args) -> Result<(), String> {
    let unsupported = [
        ("--tol-avg", args.tol_avg.is_some()),
        ("--tol-rms", args.tol_rms.is_some()),
        ("--initial", args.initial.is_some()),
        ("--control", args.control.is_some()),
        ("--cage", args.cage.is_some()),
        ("--limit", args.limit.is_some()),
    ];
    if let Some((flag, _)) = unsupported.iter().find(|f| f.1) {
        return Err(format!("{flag} does not apply to --scheme bspline"));
    }
    let common = crate::fit_bspline::Common {
        file: &args.file,
        tol_max: args.tol_max,
        max_iter: args.max_iter,
        max_control: args.max_control,
        json: args.json.as_deref(),
    };
    crate::fit_bspline::run(common, &args.bspline)
}

/// Iterates to the end, printing progress, then writes the outputs.
fn drive(setup: SubdivSetup, before_fitter: f64, args: &Args) -> Result<(), String> {
    let SubdivSetup {
        mut fitter,
        reconstruction,
    } = setup;
    if let (false, Some(r)) = (args.quiet, &reconstruction) {
        outln!(
            "reconstructed {} surface ({}): {} triangles, {} outliers removed, {:.3} s",
            r.kind,
            r.method,
            r.triangles,
            r.outliers,
            r.seconds
        );
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
            before_fitter + fitter.precompute_seconds()
        );
    }
    let fit_start = Instant::now();
    loop {
        let status = fitter.step().map_err(|e| e.to_string())?;
        if let (false, Some(r)) = (args.quiet, fitter.history().last()) {
            outln!(
                "iter {:>3}  ctrl {:>6}  E_avg {:.5}%  E_max {:.5}%  E_rms {:.5}%  {:7.1} ms{}",
                r.iter,
                r.control_points,
                r.e_avg_pct,
                r.e_max_pct,
                r.e_rms_pct,
                r.ms,
                if r.refined { "  refined" } else { "" }
            );
        }
        if status != FitStatus::Running {
            break;
        }
    }
    let mut report = FitReport::of(&fitter, before_fitter, fit_start.elapsed().as_secs_f64());
    report.reconstruction = reconstruction;
    let within = report.within_tolerance_pct.map_or(String::new(), |w| {
        format!(" ({w:.2}% of points within E_max tolerance)")
    });
    outln!(
        "{}: {} after {} iterations, {} -> {} control points, E_avg {:.5}% E_max {:.5}% E_rms {:.5}%{}, precompute {:.2} s, fit {:.2} s, total {:.2} s",
        report.scheme,
        if report.converged { "converged" } else { "stopped" },
        report.iterations,
        report.initial_control_points,
        report.final_control_points,
        report.e_avg_pct,
        report.e_max_pct,
        report.e_rms_pct,
        within,
        report.precompute_s,
        report.fit_s,
        report.total_s
    );
    if let Some(path) = &args.json {
        let text = serde_json::to_string_pretty(&report).map_err(|e| e.to_string())?;
        std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    if let Some(path) = &args.cage {
        write_obj(path, &fitter.control_mesh())?;
    }
    if let Some(path) = &args.limit {
        write_obj(path, &fitter.limit_mesh(args.limit_segments))?;
    }
    Ok(())
}

fn write_obj(path: &Path, mesh: &PolyMesh) -> Result<(), String> {
    let file = std::fs::File::create(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut out = std::io::BufWriter::new(file);
    geofit::io::write_obj(mesh, &mut out).map_err(|e| format!("{}: {e}", path.display()))
}
