//! IGES 5.3 writer: rational B-spline curves (entity 126) and surfaces (entity 128), trimmed
//! surfaces (entity 144).
//!
//! A trimmed surface is a 144 over its 128, with one 142 (curve on a parametric surface) per
//! trim loop; each 142 points to the loop as a planar degree-1 126 in (u, v) (z = 0, the
//! preferred representation) and to its image, the degree-1 126 through the surface points at
//! the loop's vertices. The surface and the curves are marked physically dependent, so readers
//! transfer the trimmed face only.
//!
//! Fixed 80-column records: columns 1–72 data, 73 the section letter (S, G, D, P, T), 74–80 the
//! sequence number. Parameter records keep columns 1–64 for data and 66–72 for the pointer back
//! to the entity's directory entry.

use super::{real, CurveDesc, ExportError, ExportModel, SurfaceDesc};

/// Fixed date stamp, so the same geometry always gives the same file.
const DATE: &str = "20260101.000000";

/// The IGES text of `model`; `name` goes into the global section's file-name field.
pub fn write_iges(model: &ExportModel, name: &str) -> Result<String, ExportError> {
    model.validate()?;
    let mut out = String::new();
    let start = section_lines(&["geofit B-spline export".to_string()], 72, 'S');
    let global = section_lines(&global_params(model, name), 72, 'G');
    let mut entities = Entities::default();
    for c in &model.curves {
        entities.add(126, curve_params(c), INDEPENDENT);
    }
    for s in &model.surfaces {
        match &s.trim {
            None => {
                entities.add(128, surface_params(s), INDEPENDENT);
            }
            Some(trim) => trimmed_surface(&mut entities, s, trim)?,
        }
    }
    let mut directory = Vec::new();
    let mut params = Vec::new();
    for (k, (kind, tokens, status)) in entities.list.iter().enumerate() {
        let de = 2 * k + 1;
        let lines = wrap(tokens, 64);
        let first = params.len() + 1;
        for line in &lines {
            params.push(format!("{line:<64} {de:>7}P{:>7}", params.len() + 1));
        }
        directory.push(format!(
            "{kind:>8}{first:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}D{:>7}",
            0, 0, 0, 0, 0, 0, status, de
        ));
        directory.push(format!(
            "{kind:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}D{:>7}",
            0,
            0,
            lines.len(),
            0,
            "",
            "",
            "",
            0,
            de + 1
        ));
    }
    for l in start.iter().chain(&global).chain(&directory).chain(&params) {
        out.push_str(l);
        out.push('\n');
    }
    let counts = format!(
        "S{:>7}G{:>7}D{:>7}P{:>7}",
        start.len(),
        global.len(),
        directory.len(),
        params.len()
    );
    out.push_str(&format!("{counts:<72}T{:>7}\n", 1));
    Ok(out)
}

/// Directory status of an entity that stands alone.
const INDEPENDENT: &str = "00000000";
/// Directory status of an entity another one is made of (physically dependent).
const DEPENDENT: &str = "00010000";
/// Directory status of a curve in a surface's parameter space (dependent, 2D parametric use).
const PARAMETRIC: &str = "00010500";

/// Entities in directory order: type number, parameter tokens, status.
#[derive(Default)]
struct Entities {
    list: Vec<(u32, Vec<String>, &'static str)>,
}

impl Entities {
    /// Adds an entity and returns the sequence number of its directory entry.
    fn add(&mut self, kind: u32, params: Vec<String>, status: &'static str) -> usize {
        self.list.push((kind, params, status));
        2 * self.list.len() - 1
    }
}

/// Entity 144 over `s` bounded by `trim`, with the 128, 142 and 126 entities it refers to.
fn trimmed_surface(
    e: &mut Entities,
    s: &SurfaceDesc,
    trim: &crate::spline::TrimRegion,
) -> Result<(), ExportError> {
    let surf = e.add(128, surface_params(s), DEPENDENT);
    let mut bounds = Vec::new();
    for l in trim.loops() {
        let (flat, image) = s.trim_loop(l)?;
        let uv = e.add(
            126,
            curve_params(&CurveDesc::polyline(flat, true)),
            PARAMETRIC,
        );
        let model = e.add(
            126,
            curve_params(&CurveDesc::polyline(image, true)),
            DEPENDENT,
        );
        let fields = [
            "142",
            "0",
            &surf.to_string(),
            &uv.to_string(),
            &model.to_string(),
            "1",
        ];
        bounds.push(e.add(
            142,
            terminate(fields.iter().map(|f| f.to_string()).collect()),
            DEPENDENT,
        ));
    }
    let mut fields = vec![
        "144".to_string(),
        surf.to_string(),
        "1".into(),
        bounds.len().saturating_sub(1).to_string(),
    ];
    fields.extend(bounds.iter().map(|b| b.to_string()));
    e.add(144, terminate(fields), INDEPENDENT);
    Ok(())
}

/// A Hollerith string `nHtext`.
fn hollerith(s: &str) -> String {
    format!("{}H{s}", s.len())
}

fn global_params(model: &ExportModel, name: &str) -> Vec<String> {
    let name: String = name
        .chars()
        .filter(|c| c.is_ascii_graphic() || *c == ' ')
        .collect();
    let fields = [
        hollerith(","),
        hollerith(";"),
        hollerith("geofit"),
        hollerith(&name),
        hollerith("geofit"),
        hollerith(env!("CARGO_PKG_VERSION")),
        "32".into(),
        "38".into(),
        "6".into(),
        "308".into(),
        "15".into(),
        hollerith("geofit"),
        real(1.0),
        "2".into(),
        hollerith("MM"),
        "1".into(),
        real(1.0),
        hollerith(DATE),
        real(1e-10),
        real(model.max_coordinate().max(1.0)),
        hollerith("geofit"),
        hollerith("geofit"),
        "11".into(),
        "0".into(),
        hollerith(DATE),
    ];
    terminate(fields.to_vec())
}

/// Adds the parameter delimiter after every field and the record delimiter after the last.
fn terminate(mut fields: Vec<String>) -> Vec<String> {
    let n = fields.len();
    for (i, f) in fields.iter_mut().enumerate() {
        f.push(if i + 1 == n { ';' } else { ',' });
    }
    fields
}

fn curve_params(c: &CurveDesc) -> Vec<String> {
    let n = c.control_points.len();
    let planar = c
        .control_points
        .iter()
        .all(|p| p.z == c.control_points[0].z);
    let mut f = vec![
        "126".to_string(),
        (n - 1).to_string(),
        c.degree.to_string(),
        u8::from(planar).to_string(),
        u8::from(c.closed).to_string(),
        u8::from(c.is_polynomial()).to_string(),
        "0".to_string(),
    ];
    f.extend(c.knots.iter().map(|&k| real(k)));
    f.extend((0..n).map(|i| real(c.weights.as_ref().map_or(1.0, |w| w[i]))));
    for p in &c.control_points {
        f.extend([real(p.x), real(p.y), real(p.z)]);
    }
    let (a, b) = c.domain();
    f.extend([real(a), real(b)]);
    let normal = if planar { [0.0, 0.0, 1.0] } else { [0.0; 3] };
    f.extend(normal.iter().map(|&x| real(x)));
    terminate(f)
}

fn surface_params(s: &SurfaceDesc) -> Vec<String> {
    let mut f = vec![
        "128".to_string(),
        (s.num_u - 1).to_string(),
        (s.num_v - 1).to_string(),
        s.degree_u.to_string(),
        s.degree_v.to_string(),
        "0".into(),
        "0".into(),
        u8::from(s.is_polynomial()).to_string(),
        "0".into(),
        "0".into(),
    ];
    f.extend(s.knots_u.iter().map(|&k| real(k)));
    f.extend(s.knots_v.iter().map(|&k| real(k)));
    // IGES orders the grid with the u index varying fastest.
    for j in 0..s.num_v {
        for i in 0..s.num_u {
            f.push(real(s.weight(i, j)));
        }
    }
    for j in 0..s.num_v {
        for i in 0..s.num_u {
            let p = s.point(i, j);
            f.extend([real(p.x), real(p.y), real(p.z)]);
        }
    }
    let du = (s.knots_u[s.degree_u], s.knots_u[s.num_u]);
    let dv = (s.knots_v[s.degree_v], s.knots_v[s.num_v]);
    f.extend([real(du.0), real(du.1), real(dv.0), real(dv.1)]);
    terminate(f)
}

/// Packs delimited tokens into lines of at most `width` characters without splitting one.
fn wrap(tokens: &[String], width: usize) -> Vec<String> {
    let mut lines = vec![String::new()];
    for t in tokens {
        let last = lines.len() - 1;
        if !lines[last].is_empty() && lines[last].len() + t.len() > width {
            lines.push(String::new());
        }
        let last = lines.len() - 1;
        lines[last].push_str(t);
    }
    lines
}

/// Start or global section records: wrapped data, padded, with letter and sequence number.
fn section_lines(tokens: &[String], width: usize, letter: char) -> Vec<String> {
    wrap(tokens, width)
        .into_iter()
        .enumerate()
        .map(|(i, l)| format!("{l:<72}{letter}{:>7}", i + 1))
        .collect()
}
