//! STEP (ISO 10303-21, AP214 `AUTOMOTIVE_DESIGN`) writer for B-spline and NURBS curves and
//! surfaces. The geometry sits in a `GEOMETRIC_SET` of a
//! `GEOMETRICALLY_BOUNDED_SURFACE_SHAPE_REPRESENTATION` attached to one product, in
//! millimetres. Polynomial geometry uses `B_SPLINE_CURVE_WITH_KNOTS` /
//! `B_SPLINE_SURFACE_WITH_KNOTS`; NURBS use the complex (rational) entity forms.
//!
//! A trimmed surface ([`SurfaceDesc::trim`]) becomes an `ADVANCED_FACE` on it, in an
//! `OPEN_SHELL` of a `SHELL_BASED_SURFACE_MODEL` (a `MANIFOLD_SURFACE_SHAPE_REPRESENTATION`).
//! Each trim loop is an `EDGE_LOOP` of four edges, each a `SURFACE_CURVE` whose 3D curve is the
//! degree-1 B-spline through the surface points at the loop's vertices and whose `PCURVE` is
//! that stretch of the loop as a degree-1 B-spline in (u, v), both parameterised alike (vertex
//! k at k).

use super::{real, CurveDesc, ExportError, ExportModel, SurfaceDesc};

/// Entity instances, numbered from 1 in the order they are added.
struct Data {
    lines: Vec<String>,
}

impl Data {
    fn add(&mut self, entity: String) -> usize {
        self.lines.push(entity);
        self.lines.len()
    }

    fn point(&mut self, p: crate::geom::Point3) -> usize {
        self.add(format!(
            "CARTESIAN_POINT('',({},{},{}))",
            real(p.x),
            real(p.y),
            real(p.z)
        ))
    }
}

fn refs(ids: &[usize]) -> String {
    let v: Vec<String> = ids.iter().map(|i| format!("#{i}")).collect();
    format!("({})", v.join(","))
}

fn reals(xs: &[f64]) -> String {
    let v: Vec<String> = xs.iter().map(|&x| real(x)).collect();
    format!("({})", v.join(","))
}

/// Distinct knot values and their multiplicities, as STEP lists knots.
fn knot_runs(knots: &[f64]) -> (Vec<f64>, Vec<usize>) {
    let mut values: Vec<f64> = Vec::new();
    let mut mults: Vec<usize> = Vec::new();
    for &k in knots {
        match values.last() {
            Some(&v) if v == k => *mults.last_mut().unwrap_or(&mut 0) += 1,
            _ => {
                values.push(k);
                mults.push(1);
            }
        }
    }
    (values, mults)
}

fn ints(xs: &[usize]) -> String {
    let v: Vec<String> = xs.iter().map(|x| x.to_string()).collect();
    format!("({})", v.join(","))
}

fn logical(b: bool) -> &'static str {
    if b {
        ".T."
    } else {
        ".F."
    }
}

fn curve(d: &mut Data, c: &CurveDesc) -> usize {
    let pts: Vec<usize> = c.control_points.iter().map(|&p| d.point(p)).collect();
    curve_on(d, c, &pts)
}

/// The curve entity of `c` over control point entities `pts`.
fn curve_on(d: &mut Data, c: &CurveDesc, pts: &[usize]) -> usize {
    let (values, mults) = knot_runs(&c.knots);
    let common = format!(
        "{},{},.UNSPECIFIED.,{},.F.",
        c.degree,
        refs(pts),
        logical(c.closed)
    );
    let knots = format!("{},{},.UNSPECIFIED.", ints(&mults), reals(&values));
    match c.weights.as_ref().filter(|_| !c.is_polynomial()) {
        None => d.add(format!("B_SPLINE_CURVE_WITH_KNOTS('',{common},{knots})")),
        Some(w) => d.add(format!(
            "(BOUNDED_CURVE()B_SPLINE_CURVE({common})B_SPLINE_CURVE_WITH_KNOTS({knots})\
             CURVE()GEOMETRIC_REPRESENTATION_ITEM()RATIONAL_B_SPLINE_CURVE({})\
             REPRESENTATION_ITEM(''))",
            reals(w)
        )),
    }
}

fn surface(d: &mut Data, s: &SurfaceDesc) -> usize {
    let mut rows = Vec::new();
    let mut wrows = Vec::new();
    for i in 0..s.num_u {
        let ids: Vec<usize> = (0..s.num_v).map(|j| d.point(s.point(i, j))).collect();
        rows.push(refs(&ids));
        let w: Vec<f64> = (0..s.num_v).map(|j| s.weight(i, j)).collect();
        wrows.push(reals(&w));
    }
    let (ku, mu) = knot_runs(&s.knots_u);
    let (kv, mv) = knot_runs(&s.knots_v);
    let common = format!(
        "{},{},({}),.UNSPECIFIED.,.F.,.F.,.F.",
        s.degree_u,
        s.degree_v,
        rows.join(",")
    );
    let knots = format!(
        "{},{},{},{},.UNSPECIFIED.",
        ints(&mu),
        ints(&mv),
        reals(&ku),
        reals(&kv)
    );
    if s.is_polynomial() {
        d.add(format!("B_SPLINE_SURFACE_WITH_KNOTS('',{common},{knots})"))
    } else {
        d.add(format!(
            "(BOUNDED_SURFACE()B_SPLINE_SURFACE({common})B_SPLINE_SURFACE_WITH_KNOTS({knots})\
             GEOMETRIC_REPRESENTATION_ITEM()RATIONAL_B_SPLINE_SURFACE(({}))\
             REPRESENTATION_ITEM('')SURFACE())",
            wrows.join(",")
        ))
    }
}

/// Edges a trim loop is cut into: OCCT's area integration mishandles a loop that is one
/// closed edge (the tessellation was right, `BRepGProp` was not).
const EDGES_PER_LOOP: usize = 4;

/// The face of trimmed surface `s` (entity `surf`), its loops' parameter curves in the 2D
/// context `ctx2`.
fn trimmed_face(
    d: &mut Data,
    s: &SurfaceDesc,
    trim: &crate::spline::TrimRegion,
    surf: usize,
    ctx2: usize,
) -> Result<usize, ExportError> {
    let mut bounds = Vec::new();
    for (k, l) in trim.loops().enumerate() {
        let (flat, image) = s.trim_loop(l)?;
        let n = flat.len();
        let pieces = n.min(EDGES_PER_LOOP);
        let cuts: Vec<usize> = (0..=pieces).map(|j| j * n / pieces).collect();
        let vertices: Vec<usize> = cuts[..pieces]
            .iter()
            .map(|&c| {
                let p = d.point(image[c]);
                d.add(format!("VERTEX_POINT('',#{p})"))
            })
            .collect();
        let mut edges = Vec::new();
        for j in 0..pieces {
            let range: Vec<usize> = (cuts[j]..=cuts[j + 1]).map(|i| i % n).collect();
            let uv = CurveDesc::polyline(range.iter().map(|&i| flat[i]).collect(), false);
            let pts2: Vec<usize> = uv
                .control_points
                .iter()
                .map(|p| d.add(format!("CARTESIAN_POINT('',({},{}))", real(p.x), real(p.y))))
                .collect();
            let c2 = curve_on(d, &uv, &pts2);
            let rep = d.add(format!("DEFINITIONAL_REPRESENTATION('',(#{c2}),#{ctx2})"));
            let pcurve = d.add(format!("PCURVE('',#{surf},#{rep})"));
            let c3 = curve(
                d,
                &CurveDesc::polyline(range.iter().map(|&i| image[i]).collect(), false),
            );
            let sc = d.add(format!("SURFACE_CURVE('',#{c3},(#{pcurve}),.PCURVE_S1.)"));
            let (v0, v1) = (vertices[j], vertices[(j + 1) % pieces]);
            let e = d.add(format!("EDGE_CURVE('',#{v0},#{v1},#{sc},.T.)"));
            edges.push(d.add(format!("ORIENTED_EDGE('',*,*,#{e},.T.)")));
        }
        let el = d.add(format!("EDGE_LOOP('',{})", refs(&edges)));
        let kind = if k == 0 {
            "FACE_OUTER_BOUND"
        } else {
            "FACE_BOUND"
        };
        bounds.push(d.add(format!("{kind}('',#{el},.T.)")));
    }
    Ok(d.add(format!("ADVANCED_FACE('',{},#{surf},.T.)", refs(&bounds))))
}

/// The STEP text of `model`; `name` goes into the header and the product.
pub fn write_step(model: &ExportModel, name: &str) -> Result<String, ExportError> {
    model.validate()?;
    let name: String = name
        .chars()
        .filter(|c| c.is_ascii_graphic() && *c != '\'' && *c != '\\')
        .collect();
    let mut d = Data { lines: Vec::new() };
    let app = d.add("APPLICATION_CONTEXT('automotive design')".into());
    d.add(format!(
        "APPLICATION_PROTOCOL_DEFINITION('international standard','automotive_design',2000,#{app})"
    ));
    let pc = d.add(format!("PRODUCT_CONTEXT('',#{app},'mechanical')"));
    let product = d.add(format!("PRODUCT('{name}','{name}','',(#{pc}))"));
    let pdf = d.add(format!("PRODUCT_DEFINITION_FORMATION('','',#{product})"));
    let pdc = d.add(format!(
        "PRODUCT_DEFINITION_CONTEXT('part definition',#{app},'design')"
    ));
    let pd = d.add(format!("PRODUCT_DEFINITION('design','',#{pdf},#{pdc})"));
    let pds = d.add(format!("PRODUCT_DEFINITION_SHAPE('','',#{pd})"));
    let len = d.add("(LENGTH_UNIT()NAMED_UNIT(*)SI_UNIT(.MILLI.,.METRE.))".into());
    let ang = d.add("(NAMED_UNIT(*)PLANE_ANGLE_UNIT()SI_UNIT($,.RADIAN.))".into());
    let sol = d.add("(NAMED_UNIT(*)SI_UNIT($,.STERADIAN.)SOLID_ANGLE_UNIT())".into());
    let unc = d.add(format!(
        "UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE(1.0E-7),#{len},'distance_accuracy_value','confusion accuracy')"
    ));
    let ctx = d.add(format!(
        "(GEOMETRIC_REPRESENTATION_CONTEXT(3)GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT((#{unc}))\
         GLOBAL_UNIT_ASSIGNED_CONTEXT((#{len},#{ang},#{sol}))REPRESENTATION_CONTEXT('',''))"
    ));
    let mut items: Vec<usize> = model.curves.iter().map(|c| curve(&mut d, c)).collect();
    let mut faces = Vec::new();
    let mut ctx2 = None;
    for s in &model.surfaces {
        let surf = surface(&mut d, s);
        match &s.trim {
            None => items.push(surf),
            Some(trim) => {
                let c2 = *ctx2.get_or_insert_with(|| {
                    d.add(
                        "(GEOMETRIC_REPRESENTATION_CONTEXT(2)PARAMETRIC_REPRESENTATION_CONTEXT()\
                         REPRESENTATION_CONTEXT('2D SPACE',''))"
                            .into(),
                    )
                });
                faces.push(trimmed_face(&mut d, s, trim, surf, c2)?);
            }
        }
    }
    if !faces.is_empty() {
        let shell = d.add(format!("OPEN_SHELL('',{})", refs(&faces)));
        let model = d.add(format!("SHELL_BASED_SURFACE_MODEL('',(#{shell}))"));
        let rep = d.add(format!(
            "MANIFOLD_SURFACE_SHAPE_REPRESENTATION('{name}',(#{model}),#{ctx})"
        ));
        d.add(format!("SHAPE_DEFINITION_REPRESENTATION(#{pds},#{rep})"));
    }
    if !items.is_empty() || faces.is_empty() {
        let set = d.add(format!("GEOMETRIC_SET('',{})", refs(&items)));
        let rep = d.add(format!(
            "GEOMETRICALLY_BOUNDED_SURFACE_SHAPE_REPRESENTATION('{name}',(#{set}),#{ctx})"
        ));
        d.add(format!("SHAPE_DEFINITION_REPRESENTATION(#{pds},#{rep})"));
    }
    let mut out = String::from("ISO-10303-21;\nHEADER;\n");
    out.push_str("FILE_DESCRIPTION(('geofit B-spline export'),'2;1');\n");
    out.push_str(&format!(
        "FILE_NAME('{name}','2026-01-01T00:00:00',('geofit'),('geofit'),'geofit {}','geofit','');\n",
        env!("CARGO_PKG_VERSION")
    ));
    out.push_str("FILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }'));\nENDSEC;\nDATA;\n");
    for (i, l) in d.lines.iter().enumerate() {
        out.push_str(&format!("#{}={l};\n", i + 1));
    }
    out.push_str("ENDSEC;\nEND-ISO-10303-21;\n");
    Ok(out)
}
