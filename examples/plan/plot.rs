//! `--plot OUT.svg`: the flight over the bottom with the `h_r` and `h_a`
//! envelopes, the waypoints and the reference depths (the paper's Figs. 8
//! and 10), and, when optimizing, the objective against iteration for each
//! track (Figs. 9 and 11).

use std::path::Path;

use plotters::element::DashedPathElement;
use plotters::prelude::*;

use crate::fail::Fail;
use crate::report::{Report, TrajRow};

/// What the figure needs.
pub struct Figure<'a> {
    pub title: String,
    pub profile_x: &'a [f32],
    pub profile_b: &'a [f32],
    pub waypoints: &'a [f32],
    pub reference_altitude: f32,
    pub min_altitude: f32,
    pub rows: &'a [TrajRow],
    pub report: &'a Report,
    /// The line on the map, (lon, lat) of its samples and of its
    /// waypoints, when known (`--grid/--line`, waypoints with lat/lon).
    pub map: Option<MapLine>,
}

/// (lon, lat) of a line's samples and of its waypoints.
pub type MapLine = (Vec<(f64, f64)>, Vec<(f64, f64)>);

const TRACK_COLORS: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
];

pub fn draw(path: &Path, fig: &Figure<'_>) -> Result<(), Fail> {
    draw_inner(path, fig).map_err(|e| Fail::input(format!("{}: cannot draw: {e}", path.display())))
}

fn draw_inner(path: &Path, fig: &Figure<'_>) -> Result<(), Box<dyn std::error::Error>> {
    let optimized = fig.report.tracks.iter().any(|t| !t.j_history.is_empty());
    let height = if optimized { 900 } else { 560 };
    let root = SVGBackend::new(path, (1100, height)).into_drawing_area();
    root.fill(&WHITE)?;
    let (top, bottom) = if optimized {
        root.split_vertically(560)
    } else {
        (root.clone(), root.split_vertically(height).1)
    };

    // The flight over the bottom. Depth is positive down: the y range is
    // reversed so that the sea surface is up.
    let x0 = fig.waypoints.first().copied().unwrap_or(0.0);
    let x1 = fig.waypoints.last().copied().unwrap_or(1.0);
    let in_line = |x: f32| x >= x0 && x <= x1;
    let bottom_pts: Vec<(f32, f32)> = fig
        .profile_x
        .iter()
        .zip(fig.profile_b)
        .filter(|(x, _)| in_line(**x))
        .map(|(&x, &b)| (x, b))
        .collect();
    let depths = fig.rows.iter().filter(|r| in_line(r.x)).map(|r| r.depth);
    let refs = fig.report.tracks.iter().map(|t| t.depth);
    let all = bottom_pts
        .iter()
        .map(|p| p.1)
        .chain(bottom_pts.iter().map(|p| p.1 - fig.reference_altitude))
        .chain(depths)
        .chain(refs);
    let (lo, hi) = all.fold((f32::INFINITY, f32::NEG_INFINITY), |(l, h), v| {
        (l.min(v), h.max(v))
    });
    let pad = 0.05 * (hi - lo).max(1.0);
    let mut chart = ChartBuilder::on(&top)
        .caption(&fig.title, ("sans-serif", 22))
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(x0..x1, (hi + pad)..(lo - pad))?;
    chart
        .configure_mesh()
        .x_desc("along-track distance x (m)")
        .y_desc("depth (m, positive down)")
        .light_line_style(WHITE.mix(0.0))
        .draw()?;

    let brown = RGBColor(120, 72, 30);
    chart
        .draw_series(AreaSeries::new(
            bottom_pts.iter().copied(),
            hi + pad,
            brown.mix(0.25),
        ))?
        .label("bottom b(x)")
        .legend(move |(x, y)| {
            Rectangle::new([(x, y - 5), (x + 20, y + 5)], brown.mix(0.4).filled())
        });
    chart.draw_series(LineSeries::new(
        bottom_pts.iter().copied(),
        brown.stroke_width(2),
    ))?;
    let green = RGBColor(0, 140, 70);
    chart
        .draw_series(LineSeries::new(
            bottom_pts
                .iter()
                .map(|&(x, b)| (x, b - fig.reference_altitude)),
            green.stroke_width(1),
        ))?
        .label(format!(
            "target depth b − h_r (h_r = {} m)",
            fig.reference_altitude
        ))
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], green));
    let red = RGBColor(200, 30, 30);
    chart
        .draw_series(DashedLineSeries::new(
            bottom_pts.iter().map(|&(x, b)| (x, b - fig.min_altitude)),
            6,
            4,
            red.stroke_width(1),
        ))?
        .label(format!(
            "minimum-altitude envelope b − h_a (h_a = {} m)",
            fig.min_altitude
        ))
        .legend(move |(x, y)| DashedPathElement::new(vec![(x, y), (x + 20, y)], 6, 4, red));
    // Reference depths, one step per track.
    let grey = RGBColor(90, 90, 90);
    for (i, (t, w)) in fig
        .report
        .tracks
        .iter()
        .zip(fig.waypoints.windows(2))
        .enumerate()
    {
        let s = chart.draw_series(DashedLineSeries::new(
            [(w[0], t.depth), (w[1], t.depth)],
            3,
            3,
            grey.stroke_width(1),
        ))?;
        if i == 0 {
            s.label("reference depth z_n").legend(move |(x, y)| {
                DashedPathElement::new(vec![(x, y), (x + 20, y)], 3, 3, grey)
            });
        }
    }
    // Waypoints.
    for &w in fig.waypoints {
        chart.draw_series(LineSeries::new(
            [(w, hi + pad), (w, lo - pad)],
            BLACK.mix(0.25),
        ))?;
    }
    chart.draw_series(fig.waypoints.iter().map(|&w| {
        let d = fig.rows.iter().find(|r| r.x >= w).map_or(lo, |r| r.depth);
        Circle::new((w, d), 4, BLACK.filled())
    }))?;
    let blue = RGBColor(20, 60, 200);
    // At most ~2000 points: a 0.15 m step is far below a pixel.
    let stride = (fig.rows.len() / 2000).max(1);
    let last = fig.rows.len().saturating_sub(1);
    let flight: Vec<(f32, f32)> = fig
        .rows
        .iter()
        .enumerate()
        .filter(|(i, r)| in_line(r.x) && (i % stride == 0 || *i == last))
        .map(|(_, r)| (r.x, r.depth))
        .collect();
    chart
        .draw_series(LineSeries::new(flight, blue.stroke_width(2)))?
        .label("AUV flight d(x)")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], blue.stroke_width(2)));
    below_min_altitude(&mut chart, fig, &in_line, (lo - pad, hi + pad))?;
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK.mix(0.3))
        .draw()?;

    if optimized {
        let max_len = fig
            .report
            .tracks
            .iter()
            .map(|t| t.j_history.len())
            .max()
            .unwrap_or(1)
            .max(2);
        let vals = fig
            .report
            .tracks
            .iter()
            .flat_map(|t| t.j_history.iter().copied())
            .filter(|v| *v > 0.0);
        let (jl, jh) = vals.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
            (l.min(f64::from(v)), h.max(f64::from(v)))
        });
        let (jl, jh) = if jl.is_finite() {
            (jl / 1.5, jh * 1.5)
        } else {
            (1.0, 10.0)
        };
        let mut c = ChartBuilder::on(&bottom)
            .caption(history_caption(fig.report.mode), ("sans-serif", 18))
            .margin(15)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d(0..(max_len - 1), (jl..jh).log_scale())?;
        c.configure_mesh()
            .x_desc("iteration")
            .y_desc("objective (m³)")
            .y_label_formatter(&|v| format!("{v:.1e}"))
            .draw()?;
        for (i, t) in fig.report.tracks.iter().enumerate() {
            let color = TRACK_COLORS[i % TRACK_COLORS.len()];
            c.draw_series(LineSeries::new(
                t.j_history
                    .iter()
                    .enumerate()
                    .filter(|(_, v)| **v > 0.0)
                    .map(|(k, &v)| (k, f64::from(v))),
                color.stroke_width(2),
            ))?
            .label(format!(
                "track {} ({} iterations, {})",
                i + 1,
                t.iterations,
                t.status
            ))
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
            });
        }
        c.configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.mix(0.3))
            .draw()?;
    }
    if let Some((line, wps)) = &fig.map {
        inset(&top, line, wps)?;
    }
    root.present()?;
    Ok(())
}

/// What the lower panel's curves are: the planner's objective at each
/// iteration of each track's planning call.
fn history_caption(mode: &str) -> &'static str {
    if mode == "horizon" {
        "J against iteration, per planning call: the horizon objective ΣJ (+ μΣV when constrained) over the tracks it optimizes"
    } else {
        "J against iteration, per track (+ μV, the penalty, when constrained)"
    }
}

type Chart<'a, 'b> = ChartContext<
    'a,
    SVGBackend<'b>,
    Cartesian2d<plotters::coord::types::RangedCoordf32, plotters::coord::types::RangedCoordf32>,
>;

/// Shades and marks the stretches where the flight is below `h_a` above
/// the bottom.
fn below_min_altitude(
    chart: &mut Chart<'_, '_>,
    fig: &Figure<'_>,
    in_line: &dyn Fn(f32) -> bool,
    (top, bottom): (f32, f32),
) -> Result<(), Box<dyn std::error::Error>> {
    let mut spans: Vec<(f32, f32)> = Vec::new();
    let mut open: Option<f32> = None;
    let mut last_x = 0.0;
    for r in fig.rows.iter().filter(|r| in_line(r.x)) {
        let below = r.bottom.is_some_and(|b| b - r.depth < fig.min_altitude);
        match (below, open) {
            (true, None) => open = Some(r.x),
            (false, Some(x0)) => {
                spans.push((x0, last_x));
                open = None;
            }
            _ => {}
        }
        last_x = r.x;
    }
    if let Some(x0) = open {
        spans.push((x0, last_x));
    }
    let orange = RGBColor(255, 140, 0);
    for (i, &(x0, x1)) in spans.iter().enumerate() {
        let s = chart.draw_series(std::iter::once(Rectangle::new(
            [(x0, top), (x1.max(x0), bottom)],
            orange.mix(0.25).filled(),
        )))?;
        if i == 0 {
            s.label(format!(
                "below h_a ({} stretch{})",
                spans.len(),
                if spans.len() == 1 { "" } else { "es" }
            ))
            .legend(move |(x, y)| {
                Rectangle::new([(x, y - 5), (x + 20, y + 5)], orange.mix(0.5).filled())
            });
        }
    }
    Ok(())
}

/// A small map of the line (lon, lat), bottom right of the flight panel
/// (over the seabed's fill more often than over the flight).
fn inset(
    area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    line: &[(f64, f64)],
    wps: &[(f64, f64)],
) -> Result<(), Box<dyn std::error::Error>> {
    let (w, h) = area.dim_in_pixel();
    let sub = area
        .clone()
        .shrink(((w as i32) - 300, (h as i32) - 250), (270, 190));
    sub.fill(&WHITE.mix(0.9))?;
    let (lo0, lo1, la0, la1) = line.iter().fold(
        (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ),
        |(a, b, c, d), &(x, y)| (a.min(x), b.max(x), c.min(y), d.max(y)),
    );
    // Equal scales on the ground: a degree of longitude is cos(lat) of one
    // of latitude.
    let k = ((la0 + la1) / 2.0).to_radians().cos().max(0.05);
    let half = ((lo1 - lo0) * k).max(la1 - la0).max(1e-4) * 0.6;
    let (cx, cy) = ((lo0 + lo1) / 2.0, (la0 + la1) / 2.0);
    let mut c = ChartBuilder::on(&sub)
        .caption("the line (lon, lat)", ("sans-serif", 13))
        .margin(4)
        .x_label_area_size(18)
        .y_label_area_size(48)
        .build_cartesian_2d((cx - half / k)..(cx + half / k), (cy - half)..(cy + half))?;
    c.configure_mesh()
        .x_labels(3)
        .y_labels(3)
        .x_label_formatter(&|v| format!("{v:.3}"))
        .y_label_formatter(&|v| format!("{v:.3}"))
        .label_style(("sans-serif", 10))
        .light_line_style(WHITE.mix(0.0))
        .draw()?;
    c.draw_series(LineSeries::new(
        line.iter().copied(),
        RGBColor(20, 60, 200).stroke_width(2),
    ))?;
    c.draw_series(wps.iter().map(|&p| Circle::new(p, 3, BLACK.filled())))?;
    c.draw_series(
        wps.iter()
            .enumerate()
            .map(|(i, &p)| Text::new(format!("{i}"), p, ("sans-serif", 11))),
    )?;
    Ok(())
}
