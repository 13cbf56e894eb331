//! Animated GIFs: a sequence of [`MapView`] frames encoded with plotters' GIF backend (the pure-Rust
//! `gif` crate), text with the bundled font.

use std::path::{Path, PathBuf};

use plotters::prelude::{BitMapBackend, IntoDrawingArea};

use super::error::{DrawError, InputError, PlotError};
use super::map::MapView;
use super::output::Render;
use super::style::ensure_font;

/// What [`write_gif`] produced.
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub struct GifWritten {
    /// The GIF file.
    pub path: PathBuf,
    /// Frames written.
    pub frame_count: usize,
    /// Image width in pixels.
    pub width_px: u32,
    /// Image height in pixels.
    pub height_px: u32,
    /// Data items not drawn (summed over the frames), as in [`Written::skipped_count`](super::Written).
    pub skipped_count: usize,
}

/// Writes `frames` as an animated GIF at `path` (looping forever), each frame shown for
/// `frame_delay_ms` milliseconds (GIF stores hundredths of a second: the delay is rounded to the
/// nearest multiple of 10 ms, at least 10 ms).
///
/// Every frame is laid out like [`MapView`]'s PNG; all frames must come out the same pixel size
/// (same bounds, width and legend entries), and the file is created only after every frame has been
/// laid out, so bad input leaves nothing on disk.
///
/// # Errors
/// [`PlotError::NoData`] for no frames or a frame with nothing to draw,
/// [`PlotError::InvalidInput`] naming the frame whose size differs from the first's or whose layout
/// is invalid, [`PlotError::Render`] when encoding fails.
pub fn write_gif(
    frames: &[MapView],
    path: &Path,
    frame_delay_ms: u32,
) -> Result<GifWritten, PlotError> {
    ensure_font()?;
    if frames.is_empty() {
        return Err(InputError::NoData("no frames".into()).at(path));
    }
    let mut plans = Vec::with_capacity(frames.len());
    let mut skipped_count = 0;
    for (i, frame) in frames.iter().enumerate() {
        let prepared = frame.prepare().map_err(|e| match e {
            InputError::NoData(what) => InputError::NoData(format!("frame {i}: {what}")),
            InputError::Invalid {
                field,
                value,
                expected,
            } => InputError::Invalid {
                field: format!("frames[{i}].{field}"),
                value,
                expected,
            },
        });
        let prepared = prepared.map_err(|e| e.at(path))?;
        if let Some(first) = plans.first().map(|(_, size)| *size)
            && prepared.size != first
        {
            return Err(InputError::invalid(
                format!("frames[{i}] size"),
                prepared.size,
                "the first frame's pixel size (same bounds, width and legend entries)",
            )
            .at(path));
        }
        skipped_count += prepared.skipped_count;
        plans.push((prepared.plan, prepared.size));
    }
    let size = plans[0].1;
    let render = |message: String| PlotError::Render {
        path: path.to_path_buf(),
        message,
    };
    let root = BitMapBackend::gif(path, size, frame_delay_ms.max(10))
        .map_err(|e| render(e.to_string()))?
        .into_drawing_area();
    for (frame, (plan, _)) in frames.iter().zip(&plans) {
        frame
            .draw(plan, &root)
            .and_then(|()| root.present().map_err(DrawError::from))
            .map_err(|e| render(e.0))?;
    }
    Ok(GifWritten {
        path: path.to_path_buf(),
        frame_count: frames.len(),
        width_px: size.0,
        height_px: size.1,
        skipped_count,
    })
}
