//! `FootPointBench`: the foot-point benchmark (`benches/foot_points.rs`) in the browser. The
//! page's script times the passes (`scripts/bench_wasm.mjs`); each pass returns a checksum.

use super::fitter::spec_from_js;
use super::scan::LoadedScan;
use crate::fit::FootPointBench as CoreBench;
use wasm_bindgen::prelude::*;

/// A finished subdivision fit of a scan, set up to time its foot points (see the core's
/// `FootPointBench`).
#[wasm_bindgen]
pub struct FootPointBench(CoreBench);

#[wasm_bindgen]
impl FootPointBench {
    /// Fits `scan` with `options` (a subdivision scheme) to the end. Throws on a bad option or
    /// a scheme that is not a subdivision surface.
    #[wasm_bindgen(constructor)]
    pub fn new(
        scan: &LoadedScan,
        #[wasm_bindgen(unchecked_param_type = "FitSpec | null | undefined")] options: JsValue,
    ) -> Result<FootPointBench, JsError> {
        let spec = spec_from_js(options)?;
        Ok(FootPointBench(CoreBench::from_fit(
            &spec,
            &scan.fit_data(),
        )?))
    }

    /// Foot points per pass (the scan's data points).
    #[wasm_bindgen(getter, js_name = numPoints)]
    pub fn num_points(&self) -> usize {
        self.0.num_points()
    }

    /// Control points of the final surface.
    #[wasm_bindgen(getter, js_name = controlPoints)]
    pub fn control_points(&self) -> usize {
        self.0.num_control_points()
    }

    /// One pass of cold foot points (from the spatial index); returns the sum of the distances.
    pub fn cold(&self) -> f64 {
        self.0.cold().distance_sum
    }

    /// One pass of warm foot points (from those before the fit's last move); returns the sum of
    /// the distances.
    pub fn warm(&self) -> f64 {
        self.0.warm().distance_sum
    }
}
