use thiserror::Error;

/// Why the renderer could not start, or refused data.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum RenderError {
    /// Neither WebGPU nor WebGL2 gave a drawing surface for the canvas.
    #[error("cannot draw on the canvas: {0}")]
    Surface(String),
    /// No graphics adapter (WebGPU or WebGL2) is available.
    #[error("no WebGPU or WebGL2 adapter is available: {0}")]
    Adapter(String),
    /// The adapter refused to create a device.
    #[error("cannot open the graphics device: {0}")]
    Device(String),
    /// A flat array's length is not a multiple of its item size, or does not match another array.
    #[error("{what} has {len} values, expected {expected}")]
    BadLength {
        /// Which array.
        what: &'static str,
        /// Its length.
        len: usize,
        /// What the length should be (a multiple, or the exact count).
        expected: String,
    },
    /// A coordinate or colour is NaN or infinite.
    #[error("{what} value {index} is not finite")]
    NonFinite {
        /// Which array.
        what: &'static str,
        /// Index of the value in the flat array.
        index: usize,
    },
    /// A triangle or line refers to a vertex that does not exist.
    #[error("{what} index {index} (at position {at}) is out of range for {count} vertices")]
    IndexOutOfRange {
        /// Which array.
        what: &'static str,
        /// The bad index.
        index: u32,
        /// Where it is in the index array.
        at: usize,
        /// How many vertices there are.
        count: usize,
    },
}
