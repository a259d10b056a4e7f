//! The PNG chart of `carom-bench scenes`: ms/step per scene as grouped bars (log scale), one
//! bar per engine, for one thread and sleeping off (the configuration every peer runs).

use super::stats::Summary;
use crate::plot::ensure_font;
use plotters::prelude::*;
use std::path::Path;

/// Engine order and colours in the chart.
const ENGINES: [(&str, RGBColor); 3] = [
    ("carom", RGBColor(214, 39, 40)),
    ("bullet", RGBColor(31, 119, 180)),
    ("rapier", RGBColor(44, 160, 44)),
];

/// Draws the chart of the single-threaded, sleeping-off summaries into `path`.
pub fn draw(all: &[Summary], path: &Path) -> Result<(), String> {
    ensure_font();
    let err = |e: &dyn std::fmt::Display| e.to_string();
    let rows: Vec<&Summary> = all
        .iter()
        .filter(|s| s.threads == 1 && !s.sleeping && s.ms_median.is_finite())
        .collect();
    let mut scenes: Vec<&str> = Vec::new();
    for r in &rows {
        if !scenes.contains(&r.scene.as_str()) {
            scenes.push(&r.scene);
        }
    }
    if rows.is_empty() {
        return Ok(());
    }
    let (lo, hi) = rows.iter().fold((f64::MAX, 0.0f64), |(a, b), r| {
        (a.min(r.ms_median), b.max(r.ms_median))
    });
    let root = BitMapBackend::new(path, (1200, 650)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let names = scenes.clone();
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "Bullet's benchmark scenes: ms per step (1 thread, sleeping off)",
            ("sans-serif", 24),
        )
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(
            0.0..scenes.len() as f64,
            ((lo * 0.5).max(1e-3)..(hi * 2.0)).log_scale(),
        )
        .map_err(|e| err(&e))?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_labels(scenes.len() * 2 + 1)
        .x_label_formatter(&|x| {
            let i = x.floor() as usize;
            if (x - i as f64 - 0.5).abs() < 0.01 && i < names.len() {
                names[i].to_string()
            } else {
                String::new()
            }
        })
        // Enough key points for plotters' log scale to place the light ones at 2..9 times
        // each power of ten (with its default of 10 it keeps the powers only)...
        .y_labels(40)
        // The key points are the log grid's lines; no lighter lines between them.
        .y_max_light_lines(0)
        // ...and labels at 1, 2 and 5 times a power of ten only (the key points also put two
        // labels a hair apart at each decade: "10.0" printed twice, overlapping).
        .y_label_formatter(&|y| {
            let decade = 10f64.powf(y.log10().floor());
            let m = y / decade;
            let nice = [1.0, 2.0, 5.0, 10.0]
                .iter()
                .any(|k| (m - k).abs() < 1e-6 * k);
            if nice && *y > 0.0 {
                format!("{}", (y * 1e3).round() / 1e3)
            } else {
                String::new()
            }
        })
        .y_desc("ms per step (median of runs)")
        .label_style(("sans-serif", 15))
        .draw()
        .map_err(|e| err(&e))?;
    let width = 0.8 / ENGINES.len() as f64;
    for (k, (engine, color)) in ENGINES.iter().enumerate() {
        let bars: Vec<Rectangle<(f64, f64)>> = scenes
            .iter()
            .enumerate()
            .filter_map(|(i, scene)| {
                let r = rows
                    .iter()
                    .find(|r| r.scene == *scene && r.engine == *engine)?;
                let x0 = i as f64 + 0.1 + k as f64 * width;
                Some(Rectangle::new(
                    [(x0, (lo * 0.5).max(1e-3)), (x0 + width * 0.9, r.ms_median)],
                    color.filled(),
                ))
            })
            .collect();
        if bars.is_empty() {
            continue;
        }
        let c = *color;
        chart
            .draw_series(bars)
            .map_err(|e| err(&e))?
            .label(*engine)
            .legend(move |(x, y)| Rectangle::new([(x, y - 6), (x + 16, y + 6)], c.filled()));
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
