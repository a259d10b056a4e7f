//! PNG plots with `plotters` (bitmap backend). Text uses the DejaVu Sans font shipped in
//! `crates/bench/assets` (registered once), so no system fonts are needed.

use crate::broadphase::Row;
use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};
use std::path::Path;
use std::sync::Once;

static FONT: Once = Once::new();

/// Registers the bundled font (once).
pub fn ensure_font() {
    FONT.call_once(|| {
        let bytes: &'static [u8] = include_bytes!("../assets/DejaVuSans.ttf");
        let _ = register_font("sans-serif", FontStyle::Normal, bytes);
    });
}

/// Log-log plot of median ms/frame against N, one line per method.
pub fn cost_vs_n(rows: &[Row], path: &Path, title: &str) -> Result<(), String> {
    ensure_font();
    let err = |e: &dyn std::fmt::Display| e.to_string();
    let mut methods: Vec<&str> = Vec::new();
    for r in rows {
        if !methods.contains(&r.method.as_str()) {
            methods.push(&r.method);
        }
    }
    let (nmin, nmax) = rows.iter().fold((f64::MAX, 0.0f64), |(a, b), r| {
        (a.min(r.n as f64), b.max(r.n as f64))
    });
    let (tmin, tmax) = rows.iter().fold((f64::MAX, 0.0f64), |(a, b), r| {
        (a.min(r.median_ms), b.max(r.median_ms))
    });
    if rows.is_empty() {
        return Ok(());
    }
    let root = BitMapBackend::new(path, (1000, 700)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 24))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(
            ((nmin * 0.8)..(nmax * 1.25)).log_scale(),
            ((tmin * 0.5).max(1e-4)..(tmax * 2.0)).log_scale(),
        )
        .map_err(|e| err(&e))?;
    chart
        .configure_mesh()
        .x_desc("N boxes")
        .y_desc("ms per frame (median)")
        .label_style(("sans-serif", 15))
        .draw()
        .map_err(|e| err(&e))?;
    for (k, m) in methods.iter().enumerate() {
        let color = Palette99::pick(k).to_rgba();
        let pts: Vec<(f64, f64)> = rows
            .iter()
            .filter(|r| r.method == *m)
            .map(|r| (r.n as f64, r.median_ms))
            .collect();
        let width = if *m == "rapier" { 4 } else { 2 };
        chart
            .draw_series(LineSeries::new(pts.clone(), color.stroke_width(width)))
            .map_err(|e| err(&e))?
            .label(*m)
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(3))
            });
        chart
            .draw_series(pts.iter().map(|&p| Circle::new(p, 4, color.filled())))
            .map_err(|e| err(&e))?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 16))
        .draw()
        .map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))?;
    Ok(())
}
