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

use wasm_bindgen::prelude::wasm_bindgen;

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
