//! The `Viewer` handle: the wgpu renderer on a canvas, driven by the page.

use crate::render::{PickSpot, Renderer};
use wasm_bindgen::prelude::*;

/// Draws points, a triangle mesh and line sets on a canvas with WebGPU or WebGL2.
///
/// Data may be replaced every frame; nothing is drawn until `render()` is called.
///
/// Holds WebAssembly memory until `free()` is called, or the scope of a `using` declaration
/// ends (`[Symbol.dispose]()` is `free()`); the garbage collector does not free it in time.
#[wasm_bindgen]
pub struct Viewer {
    renderer: Renderer,
}

#[wasm_bindgen]
impl Viewer {
    /// Opens a viewer on `canvas`: WebGPU when the browser offers it, WebGL2 otherwise.
    pub async fn create(canvas: web_sys::HtmlCanvasElement) -> Result<Viewer, JsError> {
        let renderer = Renderer::new(canvas).await?;
        Ok(Viewer { renderer })
    }

    /// The graphics backend in use: "WebGPU" or "WebGL2".
    #[wasm_bindgen(getter)]
    pub fn backend(&self) -> String {
        self.renderer.backend_name().to_owned()
    }

    /// Replaces the points: `x, y, z` per point and `r, g, b` (sRGB, 0..1) per point.
    #[wasm_bindgen(js_name = setPoints)]
    pub fn set_points(&mut self, positions: &[f32], colors: &[f32]) -> Result<(), JsError> {
        Ok(self.renderer.set_points(positions, colors)?)
    }

    /// Replaces the mesh: `x, y, z` positions and normals per vertex, three indices per
    /// triangle, and optionally `r, g, b` (sRGB, 0..1) per vertex (left out: a clay colour).
    #[wasm_bindgen(js_name = setMesh)]
    pub fn set_mesh(
        &mut self,
        positions: &[f32],
        normals: &[f32],
        indices: &[u32],
        colors: Option<Vec<f32>>,
    ) -> Result<(), JsError> {
        Ok(self
            .renderer
            .set_mesh(positions, normals, indices, colors.as_deref())?)
    }

    /// Replaces the line set: two `x, y, z` vertices per segment, `r, g, b` (sRGB) per vertex.
    #[wasm_bindgen(js_name = setLines)]
    pub fn set_lines(&mut self, positions: &[f32], colors: &[f32]) -> Result<(), JsError> {
        Ok(self.renderer.set_lines(positions, colors)?)
    }

    /// Chooses which layers are drawn.
    #[wasm_bindgen(js_name = setLayers)]
    pub fn set_layers(&mut self, points: bool, mesh: bool, wireframe: bool, lines: bool) {
        self.renderer.set_layers(points, mesh, wireframe, lines);
    }

    /// Shades the mesh with zebra stripes (reflection lines, to judge fairness) when `on`,
    /// else with the lit clay colour.
    #[wasm_bindgen(js_name = setZebra)]
    pub fn set_zebra(&mut self, on: bool) {
        self.renderer.set_zebra(on);
    }

    /// Point diameter in CSS pixels.
    #[wasm_bindgen(js_name = setPointSize)]
    pub fn set_point_size(&mut self, css_pixels: f32) {
        self.renderer.set_point_size(css_pixels);
    }

    /// Matches the drawing buffer to the canvas: its CSS size and `window.devicePixelRatio`.
    pub fn resize(&mut self, css_width: f32, css_height: f32, pixel_ratio: f32) {
        self.renderer.resize(css_width, css_height, pixel_ratio);
    }

    /// Rotates the camera by a drag of `dx`, `dy` CSS pixels.
    pub fn orbit(&mut self, dx: f32, dy: f32) {
        self.renderer.camera.orbit(dx, dy);
    }

    /// Pans the camera by a drag of `dx`, `dy` CSS pixels.
    pub fn pan(&mut self, dx: f32, dy: f32) {
        let height = self.renderer.css_height();
        self.renderer.camera.pan(dx, dy, height);
    }

    /// Zooms by a wheel `delta` (positive: farther).
    pub fn zoom(&mut self, delta: f32) {
        self.renderer.camera.zoom(delta);
    }

    /// The index of the point of `positions` (flat `x, y, z`, the points given to
    /// `setPoints`) seen at CSS pixel `x`, `y` of the canvas: the one nearest the eye within
    /// `radius` CSS pixels, or `undefined`. Throws when `positions` is not whole points.
    pub fn pick(
        &self,
        positions: &[f32],
        x: f32,
        y: f32,
        radius: f32,
    ) -> Result<Option<u32>, JsError> {
        if positions.len() % 3 != 0 {
            return Err(JsError::new(&format!(
                "pick: {} position values are not a multiple of 3",
                positions.len()
            )));
        }
        let spot = PickSpot {
            x,
            y,
            width: self.renderer.css_width(),
            height: self.renderer.css_height(),
            radius,
        };
        Ok(self.renderer.camera.pick(positions, spot).map(|i| i as u32))
    }

    /// Frames everything shown.
    #[wasm_bindgen(js_name = fitView)]
    pub fn fit_view(&mut self) {
        self.renderer.fit_view();
    }

    /// Draws one frame.
    pub fn render(&mut self) {
        self.renderer.render();
    }
}
