//! The histogram of the per-tet minimum dihedral angle (the fourth row of
//! Figure 12 of the √3 paper (Burkhart, Hamann and Umlauf)) as CSV, SVG or PNG.
//!
//! The plots are drawn with plotters. Text is rasterised by `ab_glyph` from
//! the DejaVu Sans font embedded in the binary (`assets/DejaVuSans.ttf`), so
//! nothing depends on the fonts of the machine.

use super::Histogram;
use crate::file::{write_atomic, IoError};
use plotters::prelude::*;
use std::io::Write;
use std::path::Path;
use std::sync::Once;

/// Width of the plots in pixels (SVG user units).
pub const PLOT_WIDTH: u32 = 1024;
/// Height of the plots in pixels (SVG user units).
pub const PLOT_HEIGHT: u32 = 640;
/// Label of the horizontal axis.
pub const X_LABEL: &str = "minimum dihedral angle (degrees)";
/// Label of the vertical axis.
pub const Y_LABEL: &str = "tetrahedra";

/// The output of a histogram file, chosen by its extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HistogramFormat {
    /// `bin_lo_deg,bin_hi_deg,count` rows.
    Csv,
    /// A vector plot.
    Svg,
    /// A raster plot.
    Png,
}

impl HistogramFormat {
    /// The format of `path` from its extension (case-insensitive), or a
    /// one-line error naming the file.
    pub fn from_path(path: &Path) -> Result<HistogramFormat, IoError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .unwrap_or("")
            .to_ascii_lowercase();
        match ext.as_str() {
            "csv" => Ok(HistogramFormat::Csv),
            "svg" => Ok(HistogramFormat::Svg),
            "png" => Ok(HistogramFormat::Png),
            "" => Err(IoError::file(
                path,
                "histogram file has no extension; use .csv, .svg or .png",
            )),
            other => Err(IoError::file(
                path,
                format!("unknown histogram extension '.{other}'; use .csv, .svg or .png"),
            )),
        }
    }
}

/// A bin edge without float noise: at most 6 decimals, trailing zeros dropped.
fn edge_text(x: f64) -> String {
    let s = format!("{x:.6}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.to_string()
    }
}

/// The histogram as CSV: a `bin_lo_deg,bin_hi_deg,count` header and one row
/// per bin.
pub fn to_csv(h: &Histogram) -> String {
    let mut out = String::from("bin_lo_deg,bin_hi_deg,count\n");
    for (i, c) in h.counts.iter().enumerate() {
        out.push_str(&format!(
            "{},{},{}\n",
            edge_text(h.edges_deg[i]),
            edge_text(h.edges_deg[i + 1]),
            c
        ));
    }
    out
}

static FONT: Once = Once::new();

/// Registers the embedded font as plotters' `sans-serif` (once per process).
fn register_font() {
    FONT.call_once(|| {
        // The bytes are a valid TrueType font checked in with the sources; a
        // failure here would be a build defect, and then text is simply missing.
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            include_bytes!("../../assets/DejaVuSans.ttf"),
        );
    });
}

/// Draws the bars, axes, labels and title onto `root`.
fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    h: &Histogram,
    title: &str,
) -> Result<(), String> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| format!("cannot draw the histogram: {e}");
    root.fill(&WHITE).map_err(err)?;
    let n = h.counts.len();
    let (x0, x1) = (h.edges_deg[0], h.edges_deg[n]);
    let top = h.counts.iter().copied().max().unwrap_or(0).max(1);
    // Head room above the tallest bar.
    let y_top = top + top.div_ceil(12).max(1);

    let mut chart = ChartBuilder::on(root)
        .caption(title, ("sans-serif", 26))
        .margin(18)
        .x_label_area_size(60)
        .y_label_area_size(80)
        .build_cartesian_2d(x0..x1, 0u64..y_top)
        .map_err(err)?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_desc(X_LABEL)
        .y_desc(Y_LABEL)
        .axis_desc_style(("sans-serif", 20))
        .label_style(("sans-serif", 16))
        .x_labels(16)
        .x_label_formatter(&|x| format!("{x:.0}"))
        .y_labels(10)
        .draw()
        .map_err(err)?;
    let fill = RGBColor(54, 104, 168);
    chart
        .draw_series((0..n).filter(|&i| h.counts[i] > 0).map(|i| {
            let mut bar = Rectangle::new(
                [(h.edges_deg[i], 0), (h.edges_deg[i + 1], h.counts[i])],
                fill.filled(),
            );
            // A one-pixel gap on each side keeps neighbouring bars apart.
            bar.set_margin(0, 0, 1, 1);
            bar
        }))
        .map_err(err)?;
    root.present().map_err(err)?;
    Ok(())
}

/// The histogram drawn as an SVG document, with labelled axes and `title`.
pub fn to_svg(h: &Histogram, title: &str) -> Result<String, String> {
    register_font();
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (PLOT_WIDTH, PLOT_HEIGHT)).into_drawing_area();
        draw(&root, h, title)?;
    }
    Ok(svg)
}

/// The histogram drawn as a PNG image (RGB, `PLOT_WIDTH` × `PLOT_HEIGHT`),
/// with labelled axes and `title`; returns the encoded file bytes.
pub fn to_png(h: &Histogram, title: &str) -> Result<Vec<u8>, String> {
    register_font();
    let mut rgb = vec![0u8; (PLOT_WIDTH * PLOT_HEIGHT * 3) as usize];
    {
        let root =
            BitMapBackend::with_buffer(&mut rgb, (PLOT_WIDTH, PLOT_HEIGHT)).into_drawing_area();
        draw(&root, h, title)?;
    }
    let mut png = Vec::new();
    image::ImageEncoder::write_image(
        image::codecs::png::PngEncoder::new(&mut png),
        &rgb,
        PLOT_WIDTH,
        PLOT_HEIGHT,
        image::ColorType::Rgb8,
    )
    .map_err(|e| format!("cannot encode the PNG: {e}"))?;
    Ok(png)
}

/// Writes the histogram to `path` as CSV, SVG or PNG according to its
/// extension; plots carry `title`. The file is rendered in memory first and
/// written atomically, so an error never leaves a partial file.
pub fn write_histogram(path: &Path, h: &Histogram, title: &str) -> Result<(), IoError> {
    let bytes = match HistogramFormat::from_path(path)? {
        HistogramFormat::Csv => to_csv(h).into_bytes(),
        HistogramFormat::Svg => to_svg(h, title)
            .map_err(|e| IoError::file(path, e))?
            .into_bytes(),
        HistogramFormat::Png => to_png(h, title).map_err(|e| IoError::file(path, e))?,
    };
    write_atomic(path, |w| w.write_all(&bytes))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Histogram {
        let mut h = Histogram::new(0.0, 71.0, 71);
        for (i, c) in h.counts.iter_mut().enumerate() {
            // A bump around 45°.
            let d = i as f64 - 45.0;
            *c = (1000.0 * (-d * d / 60.0).exp()) as u64;
        }
        h
    }

    #[test]
    fn csv_has_header_and_one_row_per_bin() {
        let h = Histogram::new(0.0, 71.0, 10);
        let csv = to_csv(&h);
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines[0], "bin_lo_deg,bin_hi_deg,count");
        assert_eq!(lines.len(), 11);
        // 71/10 = 7.1: the edges print without float noise.
        assert_eq!(lines[1], "0,7.1,0");
        assert_eq!(lines[3], "14.2,21.3,0");
        assert_eq!(lines[10], "63.9,71,0");
    }

    #[test]
    fn extension_decides_the_format() {
        assert_eq!(
            HistogramFormat::from_path(Path::new("a/b.CSV")),
            Ok(HistogramFormat::Csv)
        );
        assert_eq!(
            HistogramFormat::from_path(Path::new("b.svg")),
            Ok(HistogramFormat::Svg)
        );
        assert_eq!(
            HistogramFormat::from_path(Path::new("b.png")),
            Ok(HistogramFormat::Png)
        );
        let e = HistogramFormat::from_path(Path::new("b.jpg")).unwrap_err();
        assert_eq!(
            e.to_string(),
            "b.jpg: unknown histogram extension '.jpg'; use .csv, .svg or .png"
        );
        assert!(HistogramFormat::from_path(Path::new("b")).is_err());
    }

    #[test]
    fn svg_carries_labels_and_title_as_text() {
        let svg = to_svg(&sample(), "a title").unwrap();
        assert!(svg.starts_with("<svg"));
        assert!(svg.contains(X_LABEL));
        assert!(svg.contains(Y_LABEL));
        assert!(svg.contains("a title"));
        assert!(svg.contains(&format!("width=\"{PLOT_WIDTH}\"")));
    }

    #[test]
    fn png_decodes_with_the_chosen_size_and_has_ink() {
        let png = to_png(&sample(), "a title").unwrap();
        let img = image::load_from_memory_with_format(&png, image::ImageFormat::Png)
            .unwrap()
            .to_rgb8();
        assert_eq!(img.dimensions(), (PLOT_WIDTH, PLOT_HEIGHT));
        // Bars in the fill colour, and dark text pixels (labels, ticks).
        let bar = img.pixels().filter(|p| p.0 == [54, 104, 168]).count();
        let dark = img.pixels().filter(|p| p.0.iter().all(|&c| c < 80)).count();
        assert!(bar > 10_000, "{bar} bar pixels");
        assert!(dark > 1_000, "{dark} dark pixels");
    }

    #[test]
    fn empty_histogram_still_draws() {
        let h = Histogram::new(0.0, 71.0, 71);
        assert!(to_svg(&h, "empty").is_ok());
        assert!(to_png(&h, "empty").is_ok());
    }
}
