//! The GPU context: WebGPU when the browser offers it, WebGL2 otherwise, chosen at run time.

use super::RenderError;
use std::sync::Arc;

/// The surface, device and queue the viewer draws with.
pub struct Gpu {
    /// The canvas surface.
    pub surface: wgpu::Surface<'static>,
    /// The logical device.
    pub device: wgpu::Device,
    /// Its command queue.
    pub queue: wgpu::Queue,
    /// The current surface configuration (size, format).
    pub config: wgpu::SurfaceConfiguration,
    /// Which backend the adapter uses.
    pub backend: wgpu::Backend,
    /// Largest texture side the device accepts: the canvas is clamped to it.
    pub max_side: u32,
}

impl Gpu {
    /// Opens a context on `canvas`. WebGPU is tried first when `navigator.gpu` gives an adapter;
    /// otherwise wgpu's WebGL2 backend draws, with the limits WebGL2 guarantees.
    pub async fn new(canvas: web_sys::HtmlCanvasElement) -> Result<Gpu, RenderError> {
        let (width, height) = (canvas.width().max(1), canvas.height().max(1));
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
        desc.backends = wgpu::Backends::BROWSER_WEBGPU | wgpu::Backends::GL;
        let instance = wgpu::util::new_instance_with_webgpu_detection(desc).await;
        let surface = instance
            .create_surface(wgpu::SurfaceTarget::Canvas(canvas))
            .map_err(|e| RenderError::Surface(e.to_string()))?;
        let adapter = instance
            .request_adapter(&wgpu::RequestAdapterOptions {
                power_preference: wgpu::PowerPreference::HighPerformance,
                force_fallback_adapter: false,
                compatible_surface: Some(&surface),
                ..Default::default()
            })
            .await
            .map_err(|e| RenderError::Adapter(e.to_string()))?;
        let backend = adapter.get_info().backend;
        let required_limits =
            wgpu::Limits::downlevel_webgl2_defaults().using_resolution(adapter.limits());
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("geofit viewer"),
                required_limits,
                ..Default::default()
            })
            .await
            .map_err(|e| RenderError::Device(e.to_string()))?;
        // wgpu's default handler panics; a GPU validation error must not take the page down.
        device.on_uncaptured_error(Arc::new(|e| {
            web_sys::console::error_1(&format!("geofit renderer: {e}").into());
        }));
        let config = surface_config(&surface, &adapter, width, height)?;
        surface.configure(&device, &config);
        let max_side = device.limits().max_texture_dimension_2d;
        Ok(Gpu {
            surface,
            device,
            queue,
            config,
            backend,
            max_side,
        })
    }

    /// Whether the colour target stores linear values that the shaders must encode to sRGB.
    pub fn encodes_srgb_by_hand(&self) -> bool {
        !self.config.format.is_srgb()
    }

    /// Resizes the drawing buffer to `width` × `height` device pixels (clamped to the device).
    pub fn resize(&mut self, width: u32, height: u32) {
        let (w, h) = (
            width.clamp(1, self.max_side),
            height.clamp(1, self.max_side),
        );
        if (w, h) != (self.config.width, self.config.height) {
            self.config.width = w;
            self.config.height = h;
            self.surface.configure(&self.device, &self.config);
        }
    }

    /// A short name for the page: "WebGPU" or "WebGL2".
    pub fn backend_name(&self) -> &'static str {
        match self.backend {
            wgpu::Backend::BrowserWebGpu => "WebGPU",
            wgpu::Backend::Gl => "WebGL2",
            _ => "other",
        }
    }
}

/// The surface's preferred format (sRGB or not: both work, see [`Gpu::encodes_srgb_by_hand`]),
/// opaque, with vsync.
fn surface_config(
    surface: &wgpu::Surface,
    adapter: &wgpu::Adapter,
    width: u32,
    height: u32,
) -> Result<wgpu::SurfaceConfiguration, RenderError> {
    let mut config = surface
        .get_default_config(adapter, width, height)
        .ok_or_else(|| RenderError::Surface("the adapter cannot present to it".into()))?;
    let caps = surface.get_capabilities(adapter);
    if caps.alpha_modes.contains(&wgpu::CompositeAlphaMode::Opaque) {
        config.alpha_mode = wgpu::CompositeAlphaMode::Opaque;
    }
    config.present_mode = wgpu::PresentMode::Fifo;
    Ok(config)
}
