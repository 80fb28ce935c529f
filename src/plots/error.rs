//! What drawing a figure refuses or fails on, each a line naming the
//! figure or the file.

use std::path::PathBuf;

/// A figure that cannot be drawn or written.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PlotError {
    /// Data the figure cannot show (nothing to draw, a value that is not
    /// finite): which figure, and what.
    #[error("{0}")]
    Data(String),
    /// The drawing backend or the PNG encoder failed.
    #[error("{0}")]
    Backend(String),
    /// Drawing one file of a figure failed.
    #[error("{}: drawing failed: {error}", path.display())]
    Drawing {
        /// The file being drawn.
        path: PathBuf,
        /// Why.
        error: Box<PlotError>,
    },
    /// A folder or file could not be written.
    #[error("{}: {message}", path.display())]
    Write {
        /// The folder or file.
        path: PathBuf,
        /// The system's message.
        message: String,
    },
    /// The font embedded in the binary.
    #[error("assets/fonts/DejaVuSans-subset.ttf: not a usable font")]
    Font,
}

impl PlotError {
    /// Writing `path` failed with `e`.
    pub fn write(path: &std::path::Path, e: impl std::fmt::Display) -> Self {
        PlotError::Write {
            path: path.to_path_buf(),
            message: e.to_string(),
        }
    }
}
