//! Writing a figure: validate, lay out, draw once to SVG and once to PNG.

use std::fs;
use std::path::{Path, PathBuf};

use plotters::coord::Shift;
use plotters::prelude::{BitMapBackend, DrawingArea, DrawingBackend, IntoDrawingArea, SVGBackend};

use super::error::{DrawError, InputError, PlotError};
use super::style::ensure_font;

/// A figure that can be written to disk as `NAME.svg` and `NAME.png`.
///
/// Implemented by [`MapView`](super::MapView), [`TimeSeries`](super::TimeSeries),
/// [`BarChart`](super::BarChart) and [`Distribution`](super::Distribution). Writing is a pure
/// function of the figure: the same figure gives byte-identical SVG.
pub trait Figure: Send + Sync {
    /// The figure's title (also drawn at its top).
    fn title(&self) -> &str;

    /// Writes `dir/base_name.svg` and `dir/base_name.png`, creating `dir` if needed.
    ///
    /// Items with non-finite coordinates (and negative radii) are skipped and counted in
    /// [`Written::skipped_count`]; a figure left with nothing to draw is [`PlotError::NoData`].
    fn write(&self, dir: &Path, base_name: &str) -> Result<Written, PlotError>;
}

/// What [`Figure::write`] produced.
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub struct Written {
    /// The SVG file.
    pub svg: PathBuf,
    /// The PNG file (same pixel size as the SVG).
    pub png: PathBuf,
    /// Image width in pixels.
    pub width_px: u32,
    /// Image height in pixels.
    pub height_px: u32,
    /// Data items not drawn because a coordinate was NaN or infinite (or a radius negative).
    pub skipped_count: usize,
    /// Point-cloud points not drawn because an earlier point already covers their pixel cell.
    pub thinned_count: usize,
}

/// A laid-out figure, ready to be drawn on any backend.
pub(crate) struct Prepared<P> {
    pub(crate) plan: P,
    pub(crate) size: (u32, u32),
    pub(crate) skipped_count: usize,
    pub(crate) thinned_count: usize,
}

/// Implemented by every figure: validation and layout, then drawing.
pub(crate) trait Render {
    type Plan;
    fn prepare(&self) -> Result<Prepared<Self::Plan>, InputError>;
    fn draw<DB: DrawingBackend>(
        &self,
        plan: &Self::Plan,
        root: &DrawingArea<DB, Shift>,
    ) -> Result<(), DrawError>;
}

fn check_name(base_name: &str) -> Result<(), PlotError> {
    let bad = base_name.is_empty()
        || base_name == "."
        || base_name == ".."
        || base_name.contains(['/', '\\', '\0'])
        || Path::new(base_name).components().count() != 1;
    if bad {
        Err(PlotError::InvalidName {
            name: base_name.to_string(),
        })
    } else {
        Ok(())
    }
}

fn ensure_dir(dir: &Path) -> Result<(), PlotError> {
    if dir.exists() && !dir.is_dir() {
        return Err(PlotError::NotADirectory {
            path: dir.to_path_buf(),
        });
    }
    fs::create_dir_all(dir).map_err(|source| PlotError::CreateDir {
        path: dir.to_path_buf(),
        source,
    })
}

pub(crate) fn write_figure<R: Render>(
    fig: &R,
    dir: &Path,
    base_name: &str,
) -> Result<Written, PlotError> {
    check_name(base_name)?;
    ensure_font()?;
    let prepared = fig.prepare().map_err(|e| e.at(&dir.join(base_name)))?;
    ensure_dir(dir)?;

    let svg_path = dir.join(format!("{base_name}.svg"));
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, prepared.size).into_drawing_area();
        fig.draw(&prepared.plan, &root)
            .and_then(|()| root.present().map_err(DrawError::from))
            .map_err(|e| PlotError::Render {
                path: svg_path.clone(),
                message: e.0,
            })?;
    }
    fs::write(&svg_path, svg).map_err(|source| PlotError::Write {
        path: svg_path.clone(),
        source,
    })?;

    let png_path = dir.join(format!("{base_name}.png"));
    {
        let root = BitMapBackend::new(&png_path, prepared.size).into_drawing_area();
        fig.draw(&prepared.plan, &root)
            .and_then(|()| root.present().map_err(DrawError::from))
            .map_err(|e| PlotError::Render {
                path: png_path.clone(),
                message: e.0,
            })?;
    }

    Ok(Written {
        svg: svg_path,
        png: png_path,
        width_px: prepared.size.0,
        height_px: prepared.size.1,
        skipped_count: prepared.skipped_count,
        thinned_count: prepared.thinned_count,
    })
}

#[cfg(test)]
mod tests {
    use super::check_name;

    #[test]
    fn base_names_must_be_plain() {
        for bad in ["", ".", "..", "a/b", "a\\b", "/abs"] {
            assert!(check_name(bad).is_err(), "{bad:?}");
        }
        for good in ["top_view", "e2.speed", "fig-1"] {
            assert!(check_name(good).is_ok(), "{good:?}");
        }
    }
}
