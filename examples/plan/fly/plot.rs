//! `plan fly --plot OUT.svg`: flight 0 of each guidance over the true
//! bottom of that flight's world, the map beside it, the stretches below
//! `h_a` marked (red) and, for the sonar guidances, the samples without
//! bottom lock (grey ticks at the top).

use std::path::Path;

use plotters::prelude::*;

use crate::fail::Fail;

/// One guidance's sample flight: name and path (true x, depth, true
/// bottom, bottom lock).
pub struct Track<'a> {
    pub name: &'static str,
    pub sonar: bool,
    pub path: &'a [(f64, f64, f64, bool)],
}

const COLORS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
];

pub fn draw(
    path: &Path,
    title: &str,
    h_a: f64,
    map: (&[f64], &[f64]),
    tracks: &[Track<'_>],
) -> Result<(), Fail> {
    inner(path, title, h_a, map, tracks)
        .map_err(|e| Fail::input(format!("{}: cannot draw: {e}", path.display())))
}

fn inner(
    path: &Path,
    title: &str,
    h_a: f64,
    map: (&[f64], &[f64]),
    tracks: &[Track<'_>],
) -> Result<(), Box<dyn std::error::Error>> {
    let panel = 300;
    let root =
        SVGBackend::new(path, (1100, panel * tracks.len().max(1) as u32 + 40)).into_drawing_area();
    root.fill(&WHITE)?;
    let (head, body) = root.split_vertically(40);
    head.draw(&Text::new(title.to_string(), (10, 10), ("sans-serif", 20)))?;
    for (i, (t, area)) in tracks
        .iter()
        .zip(body.split_evenly((tracks.len().max(1), 1)))
        .enumerate()
    {
        let (x0, x1) = t
            .path
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
                (a.min(p.0), b.max(p.0))
            });
        let (lo, hi) = t
            .path
            .iter()
            .flat_map(|p| [p.1, p.2])
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v), b.max(v))
            });
        if !(x0 < x1 && lo <= hi) {
            continue;
        }
        let pad = 0.05 * (hi - lo).max(1.0);
        let mut chart = ChartBuilder::on(&area)
            .caption(t.name, ("sans-serif", 16))
            .margin(8)
            .x_label_area_size(30)
            .y_label_area_size(60)
            .build_cartesian_2d(x0..x1, (hi + pad)..(lo - 2.0 * pad))?;
        chart
            .configure_mesh()
            .x_desc("x (m)")
            .y_desc("depth (m)")
            .draw()?;
        chart.draw_series(LineSeries::new(
            map.0
                .iter()
                .zip(map.1)
                .filter(|(x, _)| **x >= x0 && **x <= x1)
                .map(|(&x, &b)| (x, b)),
            BLACK.mix(0.3),
        ))?;
        chart.draw_series(LineSeries::new(
            t.path.iter().step_by(10).map(|p| (p.0, p.2)),
            BLACK.stroke_width(2),
        ))?;
        chart.draw_series(LineSeries::new(
            t.path.iter().step_by(10).map(|p| (p.0, p.2 - h_a)),
            BLACK.mix(0.4),
        ))?;
        chart.draw_series(LineSeries::new(
            t.path.iter().step_by(10).map(|p| (p.0, p.1)),
            COLORS[i % COLORS.len()].stroke_width(2),
        ))?;
        chart.draw_series(
            t.path
                .iter()
                .step_by(20)
                .filter(|p| p.2 - p.1 < h_a)
                .map(|p| Circle::new((p.0, p.1), 2, RED.filled())),
        )?;
        if t.sonar {
            chart.draw_series(t.path.iter().step_by(20).filter(|p| !p.3).map(|p| {
                Circle::new((p.0, lo - 1.5 * pad), 2, RGBColor(120, 120, 120).filled())
            }))?;
        }
    }
    root.present()?;
    Ok(())
}
