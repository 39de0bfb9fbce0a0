//! SVG drawing for the figures of `tet-bench tables` (plotters, SVG
//! backend only: no system font libraries; text is left to the SVG
//! viewer): scatter plots ([`scatter_svg`]) and grouped bars ([`bars_svg`])
//! of plain points; which figures a run draws is [`super::figures`]' business.
//!
//! Every data point is exactly one mark (`<circle>` in scatter plots,
//! `<rect>` in bar charts besides the white background); legends are
//! coloured text, so a reader (or a test) can count marks.

use std::fmt::Display;

use anyhow::{Result, anyhow};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// Plot size in pixels.
const SIZE: (u32, u32) = (960, 640);

/// One scatter point.
#[derive(Clone, Debug, PartialEq)]
pub struct Point {
    /// Series (colour), e.g. the method.
    pub series: String,
    /// Text written beside the point.
    pub label: String,
    /// x value.
    pub x: f64,
    /// y value.
    pub y: f64,
}

/// One group of bars (e.g. a scene) with `(series, value)` bars.
#[derive(Clone, Debug, PartialEq)]
pub struct BarGroup {
    /// Group name (x-axis label).
    pub name: String,
    /// Bars: series and value.
    pub bars: Vec<(String, f64)>,
}

/// A plotters error as ours.
fn err(e: impl Display) -> anyhow::Error {
    anyhow!("cannot draw the plot: {e}")
}

/// The `i`-th series colour (a ten-colour cycle).
fn colour(i: usize) -> RGBColor {
    const C: [RGBColor; 10] = [
        RGBColor(31, 119, 180),
        RGBColor(255, 127, 14),
        RGBColor(44, 160, 44),
        RGBColor(214, 39, 40),
        RGBColor(148, 103, 189),
        RGBColor(140, 86, 75),
        RGBColor(227, 119, 194),
        RGBColor(127, 127, 127),
        RGBColor(188, 189, 34),
        RGBColor(23, 190, 207),
    ];
    C[i % C.len()]
}

/// Distinct series names in order of first appearance.
fn series_of<'a>(names: impl Iterator<Item = &'a str>) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for n in names {
        if !out.iter().any(|s| s == n) {
            out.push(n.to_string());
        }
    }
    out
}

/// The top of an axis that holds `max`, with room above it.
fn upper(max: f64) -> f64 {
    if max.is_finite() && max > 0.0 {
        max * 1.15
    } else {
        1.0
    }
}

/// A scatter plot, one filled circle per finite point, labelled.
pub fn scatter_svg(title: &str, x_desc: &str, y_desc: &str, points: &[Point]) -> Result<String> {
    let points: Vec<&Point> = points
        .iter()
        .filter(|p| p.x.is_finite() && p.y.is_finite())
        .collect();
    let series = series_of(points.iter().map(|p| p.series.as_str()));
    let xmax = upper(points.iter().map(|p| p.x).fold(0.0, f64::max));
    let ymax = upper(points.iter().map(|p| p.y).fold(0.0, f64::max));
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(16)
            .x_label_area_size(48)
            .y_label_area_size(64)
            .build_cartesian_2d(0f64..xmax, 0f64..ymax)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc(x_desc)
            .y_desc(y_desc)
            .draw()
            .map_err(err)?;
        for (i, s) in series.iter().enumerate() {
            let c = colour(i);
            let mine: Vec<&&Point> = points.iter().filter(|p| &p.series == s).collect();
            chart
                .draw_series(mine.iter().map(|p| Circle::new((p.x, p.y), 5, c.filled())))
                .map_err(err)?;
            chart
                .draw_series(mine.iter().map(|p| {
                    Text::new(
                        p.label.clone(),
                        (p.x, p.y),
                        ("sans-serif", 12).into_font().color(&c),
                    )
                }))
                .map_err(err)?;
        }
        legend(&root, &series)?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

/// Series names as coloured text in the top-right corner (no marks).
fn legend(
    root: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    series: &[String],
) -> Result<()> {
    for (i, s) in series.iter().enumerate() {
        root.draw(&Text::new(
            s.clone(),
            (SIZE.0 as i32 - 190, 48 + 18 * i as i32),
            ("sans-serif", 14).into_font().color(&colour(i)),
        ))
        .map_err(err)?;
    }
    Ok(())
}

/// A grouped bar chart: one filled rectangle per finite bar, groups side
/// by side, bars coloured by series.
pub fn bars_svg(title: &str, y_desc: &str, groups: &[BarGroup]) -> Result<String> {
    let series = series_of(
        groups
            .iter()
            .flat_map(|g| g.bars.iter().map(|(s, _)| s.as_str())),
    );
    let ymax = upper(
        groups
            .iter()
            .flat_map(|g| g.bars.iter().map(|b| b.1))
            .filter(|v| v.is_finite())
            .fold(0.0, f64::max),
    );
    let n = groups.len().max(1);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(16)
            .x_label_area_size(48)
            .y_label_area_size(64)
            .build_cartesian_2d(0f64..n as f64, 0f64..ymax)
            .map_err(err)?;
        chart
            .configure_mesh()
            .disable_x_mesh()
            .x_labels(0)
            .y_desc(y_desc)
            .draw()
            .map_err(err)?;
        // Group names under the axis, centred on their group.
        let centred = ("sans-serif", 14)
            .into_font()
            .color(&BLACK)
            .pos(Pos::new(HPos::Center, VPos::Top));
        for (i, g) in groups.iter().enumerate() {
            let (px, py) = chart.backend_coord(&(i as f64 + 0.5, 0.0));
            root.draw(&Text::new(g.name.clone(), (px, py + 8), centred.clone()))
                .map_err(err)?;
        }
        for (gi, g) in groups.iter().enumerate() {
            let k = g.bars.len().max(1) as f64;
            let width = 0.8 / k;
            for (bi, (s, v)) in g.bars.iter().enumerate() {
                if !v.is_finite() {
                    continue;
                }
                let x0 = gi as f64 + 0.1 + bi as f64 * width;
                let si = series.iter().position(|x| x == s).unwrap_or(0);
                chart
                    .draw_series(std::iter::once(Rectangle::new(
                        [(x0, 0.0), (x0 + width * 0.9, *v)],
                        colour(si).filled(),
                    )))
                    .map_err(err)?;
            }
        }
        legend(&root, &series)?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Parses the SVG and returns `(circles, rects other than the full
    /// background)`.
    fn marks(svg: &str) -> (usize, usize) {
        let doc = roxmltree::Document::parse(svg).expect("the SVG is well-formed XML");
        let root = doc.root_element();
        assert_eq!(root.tag_name().name(), "svg");
        let w = root.attribute("width").unwrap();
        let h = root.attribute("height").unwrap();
        let circles = doc
            .descendants()
            .filter(|n| n.has_tag_name("circle"))
            .count();
        let rects = doc
            .descendants()
            .filter(|n| n.has_tag_name("rect"))
            .filter(|n| !(n.attribute("width") == Some(w) && n.attribute("height") == Some(h)))
            .count();
        (circles, rects)
    }

    #[test]
    fn scatter_has_one_circle_per_finite_point() {
        let pts: Vec<Point> = (0..7)
            .map(|i| Point {
                series: ["tet20", "tet80", "obvhs"][i % 3].into(),
                label: format!("p{i} <&>"),
                x: i as f64 * 0.5,
                y: 10.0 - i as f64,
            })
            .chain(std::iter::once(Point {
                series: "nan".into(),
                label: "skipped".into(),
                x: f64::NAN,
                y: 1.0,
            }))
            .collect();
        let svg = scatter_svg("t", "x", "y", &pts).unwrap();
        assert_eq!(marks(&svg), (7, 0));
        // All-zero failure rates still give a valid plot.
        let zero = vec![Point {
            series: "a".into(),
            label: "a".into(),
            x: 0.0,
            y: 0.0,
        }];
        assert_eq!(marks(&scatter_svg("t", "x", "y", &zero).unwrap()), (1, 0));
    }

    #[test]
    fn bars_have_one_rect_per_finite_bar() {
        let groups = vec![
            BarGroup {
                name: "torus-knots".into(),
                bars: vec![("a".into(), 3.0), ("b".into(), 4.5), ("c".into(), 0.5)],
            },
            BarGroup {
                name: "box".into(),
                bars: vec![("a".into(), 1.0), ("b".into(), f64::NAN)],
            },
        ];
        let svg = bars_svg("title", "Mrays/s", &groups).unwrap();
        assert_eq!(marks(&svg), (0, 4));
        assert!(bars_svg("empty", "y", &[]).is_ok());
    }
}
