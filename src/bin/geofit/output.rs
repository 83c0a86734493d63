//! What every subcommand does at its edges: read the input file with errors naming it, and print
//! the JSON report (indented, or on one line with `--json`).

use geofit::export::{iges::write_iges, step::write_step, ExportModel};
use geofit::io::LoadedFile;
use serde::Serialize;
use std::path::Path;

/// Reads `path` with the project's readers; the error names the file.
pub fn read_input(path: &Path) -> Result<LoadedFile, String> {
    geofit::io::read_path(path).map_err(|e| format!("{}: {e}", path.display()))
}

/// Prints `report` as JSON: on one line when `compact`, else indented.
pub fn print_json(report: &impl Serialize, compact: bool) -> Result<(), String> {
    let text = if compact {
        serde_json::to_string(report)
    } else {
        serde_json::to_string_pretty(report)
    }
    .map_err(|e| e.to_string())?;
    write_line(format_args!("{text}"));
    Ok(())
}

/// Writes one line to standard output (what `outln!` expands to). A reader that has gone away
/// (a closed pipe, as in `geofit info scan.ply | head -1`) is not an error: the rest of the
/// output is not read, and the command still writes its files; `println!` would panic.
pub fn write_line(line: std::fmt::Arguments) {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    if let Err(e) = writeln!(out, "{line}") {
        if e.kind() != std::io::ErrorKind::BrokenPipe {
            eprintln!("geofit: standard output: {e}");
        }
    }
}

/// Writes `model` as IGES and STEP where paths are given, each named after its file.
pub fn write_exports(
    model: &ExportModel,
    iges: Option<&Path>,
    step: Option<&Path>,
) -> Result<(), String> {
    let name = |p: &Path| {
        p.file_name()
            .and_then(|n| n.to_str())
            .unwrap_or("geofit")
            .to_string()
    };
    if let Some(path) = iges {
        let text = write_iges(model, &name(path)).map_err(|e| e.to_string())?;
        std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    if let Some(path) = step {
        let text = write_step(model, &name(path)).map_err(|e| e.to_string())?;
        std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    Ok(())
}
