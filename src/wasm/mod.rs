//! JavaScript bindings: thin `#[wasm_bindgen]` handles over the core, one file per handle.
//! Names are camelCase on the JavaScript side; bulk data crosses as typed arrays; every error
//! reaches JavaScript as a thrown `Error` carrying the Rust error's message.

mod bench;
mod fitter;
mod scan;
mod viewer;

pub use bench::FootPointBench;
pub use fitter::{default_spec, exports_for, methods_for, options_for, Fitter, MeshArrays};
pub use scan::{load_file, LoadedScan};
pub use viewer::Viewer;

use crate::progress;
use wasm_bindgen::prelude::{wasm_bindgen, JsValue};

/// Runs `f` with the JavaScript callback `on_progress`, when given, called as
/// `onProgress(phase, done)` (see [`crate::progress`]) while `f` runs. An exception the
/// callback throws is dropped: a progress display must not abort the work it displays.
pub(crate) fn with_progress<R>(on_progress: Option<js_sys::Function>, f: impl FnOnce() -> R) -> R {
    let Some(callback) = on_progress else {
        return f();
    };
    let sink = move |phase: progress::Phase, done: f64| {
        let phase = JsValue::from_str(phase.name());
        let _ = callback.call2(&JsValue::NULL, &phase, &JsValue::from_f64(done));
    };
    progress::watch(Box::new(sink), f)
}

/// The TypeScript interfaces of the plain objects the bindings take and give (`FitSpec`,
/// `FitStats`, `HistoryEntry`, `FitReport`, ...), written once in `types.d.ts` and copied into
/// `geofit.d.ts`; the functions name them with `unchecked_param_type` / `unchecked_return_type`.
#[wasm_bindgen(typescript_custom_section)]
const TYPES: &str = include_str!("types.d.ts");

/// Runs once when the module is instantiated: panics (which no code path relies on) at least
/// reach the console with their message.
#[wasm_bindgen(start)]
pub fn start() {
    console_error_panic_hook::set_once();
}
