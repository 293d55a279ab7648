//! The SVG charts: a document's structure (balanced tags, viewBox, one polyline per line series,
//! every coordinate finite), nice ticks, a limit line at its pixel, the pipeline's figures on a
//! smoothed zig-zag, and bad input refused.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

#[allow(dead_code)] // each test file uses some of the shared data
mod support;
use support::{feed_limits, ZIG_ZAG};

use kerf_toolpath::plot::chart::{HEIGHT, WIDTH};
use kerf_toolpath::plot::{nice_step, tick_label, Axis, Chart, Style};
use kerf_toolpath::{pipeline_plots, plan_feed, sample_path, smooth_polyline, ToolpathError};

/// The tags of a document in order: (name, closing, self-closing, the whole tag).
fn tags(svg: &str) -> Vec<(String, bool, bool, String)> {
    let mut out = Vec::new();
    let mut rest = svg;
    while let Some(open) = rest.find('<') {
        let close = rest[open..].find('>').expect("an unclosed tag") + open;
        let tag = &rest[open + 1..close];
        let closing = tag.starts_with('/');
        let self_closing = tag.ends_with('/');
        let name: String = tag
            .trim_start_matches('/')
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric())
            .collect();
        out.push((name, closing, self_closing, tag.to_string()));
        rest = &rest[close + 1..];
    }
    out
}

/// The value of attribute `name` in a tag.
fn attr<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let key = format!(" {name}=\"");
    let start = tag.find(&key)? + key.len();
    let end = tag[start..].find('"')? + start;
    Some(&tag[start..end])
}

/// Checks a document's structure; returns its tags.
fn check_structure(svg: &str) -> Vec<(String, bool, bool, String)> {
    assert!(svg.starts_with("<svg "), "{}", &svg[..40.min(svg.len())]);
    assert!(svg.trim_end().ends_with("</svg>"));
    let t = tags(svg);
    let mut stack: Vec<&str> = Vec::new();
    for (name, closing, self_closing, _) in &t {
        if *closing {
            assert_eq!(stack.pop(), Some(name.as_str()), "unbalanced </{name}>");
        } else if !self_closing {
            stack.push(name);
        }
    }
    assert!(stack.is_empty(), "unclosed: {stack:?}");
    assert_eq!(
        attr(&t[0].3, "viewBox"),
        Some(format!("0 0 {WIDTH} {HEIGHT}").as_str())
    );
    for (_, _, _, tag) in &t {
        for key in [
            "x", "y", "x1", "y1", "x2", "y2", "cx", "cy", "r", "width", "height",
        ] {
            if let Some(v) = attr(tag, key) {
                let v: f64 = v
                    .parse()
                    .unwrap_or_else(|_| panic!("{key}={v:?} in <{tag}>"));
                assert!(v.is_finite(), "{key} in <{tag}>");
            }
        }
        if let Some(points) = attr(tag, "points") {
            for pair in points.split(' ') {
                let (x, y) = pair.split_once(',').unwrap();
                assert!(
                    x.parse::<f64>().unwrap().is_finite() && y.parse::<f64>().unwrap().is_finite()
                );
            }
        }
    }
    t
}

fn count(t: &[(String, bool, bool, String)], name: &str, class: &str) -> usize {
    t.iter()
        .filter(|(n, c, _, tag)| n == name && !c && attr(tag, "class") == Some(class))
        .count()
}

#[test]
fn a_chart_is_a_well_formed_svg_document() {
    let xs: Vec<f64> = (0..200).map(|k| k as f64 * 0.05).collect();
    let chart = Chart::new("Two waves & <markers>", "t [s]", "y [m]")
        .line("sin", xs.iter().map(|x| [*x, x.sin()]).collect())
        .line("cos", xs.iter().map(|x| [*x, x.cos()]).collect())
        .with_series(
            "samples",
            vec![[1.0, 0.5], [2.0, -0.5], [3.0, 0.25]],
            Style::Markers,
            Some("#d62728"),
        )
        .limit("upper", 0.9);
    let svg = chart.render().unwrap();
    let t = check_structure(&svg);
    assert_eq!(
        count(&t, "polyline", "series"),
        2,
        "one polyline per line series"
    );
    assert_eq!(count(&t, "line", "limit"), 1);
    assert_eq!(count(&t, "g", "markers"), 1);
    let circles = t
        .iter()
        .filter(|(n, c, _, tag)| n == "circle" && !c && attr(tag, "r") == Some("2.5"))
        .count();
    assert_eq!(circles, 3);
    assert!(
        svg.contains("Two waves &amp; &lt;markers&gt;"),
        "the title is escaped"
    );
    for text in ["t [s]", "y [m]", "sin", "cos", "samples", "upper"] {
        assert!(svg.contains(&format!(">{text}</text>")), "{text}");
    }
}

#[test]
fn ticks_are_nice_numbers() {
    assert_eq!(nice_step(10.0, 5), 2.0);
    assert_eq!(nice_step(10.0, 10), 1.0);
    assert_eq!(nice_step(7.0, 2), 5.0);
    assert_eq!(nice_step(0.0036, 6), 0.001);
    assert_eq!(nice_step(3.0e4, 6), 5000.0);
    let a = Axis::covering(0.3, 9.7, 5);
    assert_eq!((a.lo, a.hi, a.step), (0.0, 10.0, 2.0));
    assert_eq!(a.ticks(), vec![0.0, 2.0, 4.0, 6.0, 8.0, 10.0]);
    let b = Axis::covering(-0.00123, 0.00456, 6);
    assert_eq!(b.step, 0.001);
    assert_eq!(b.ticks().len(), 8, "{:?}", b.ticks());
    assert!((b.lo + 0.002).abs() < 1e-15 && (b.hi - 0.005).abs() < 1e-15);
    // A constant series still gets a range.
    let c = Axis::covering(3.0, 3.0, 6);
    assert!(c.lo < 3.0 && c.hi > 3.0);
    assert_eq!(tick_label(0.1 + 0.2, 0.1), "0.3");
    assert_eq!(tick_label(-4.0, 2.0), "-4");
    assert_eq!(tick_label(0.0, 1e-7), "0");
    assert_eq!(tick_label(1e-7, 5e-8), "1e-7");
    assert_eq!(tick_label(2.5e6, 5e5), "2.5e6");
}

#[test]
fn a_limit_line_is_drawn_at_its_value() {
    let chart = Chart::new("limit", "x [m]", "y [m]")
        .line("ramp", (0..=10).map(|k| [k as f64, k as f64]).collect())
        .limit("at 7.5", 7.5);
    let (_, y) = chart.axes().unwrap();
    // 0..10 padded by 5 % (not below 0), then to nice multiples of 2.
    assert_eq!((y.lo, y.hi), (0.0, 12.0));
    let svg = chart.render().unwrap();
    let t = check_structure(&svg);
    let frame = &t
        .iter()
        .find(|x| attr(&x.3, "class") == Some("frame"))
        .unwrap()
        .3;
    let f = |k: &str| attr(frame, k).unwrap().parse::<f64>().unwrap();
    let (fx, fy, fw, fh) = (f("x"), f("y"), f("width"), f("height"));
    let limit = &t
        .iter()
        .find(|x| attr(&x.3, "class") == Some("limit"))
        .unwrap()
        .3;
    let l = |k: &str| attr(limit, k).unwrap().parse::<f64>().unwrap();
    let expected = fy + fh * (1.0 - 7.5 / 12.0);
    assert!(
        (l("y1") - expected).abs() < 0.006 && (l("y2") - expected).abs() < 0.006,
        "{limit}"
    );
    assert!((l("x1") - fx).abs() < 0.006 && (l("x2") - (fx + fw)).abs() < 0.006);
    // The ramp's last point (10, 10) is at 10/12 of the height.
    let poly = &t
        .iter()
        .find(|x| attr(&x.3, "class") == Some("series"))
        .unwrap()
        .3;
    let last = attr(poly, "points")
        .unwrap()
        .split(' ')
        .next_back()
        .unwrap();
    let (x, y) = last.split_once(',').unwrap();
    assert!((x.parse::<f64>().unwrap() - (fx + fw)).abs() < 0.006);
    assert!((y.parse::<f64>().unwrap() - (fy + fh * (1.0 - 10.0 / 12.0))).abs() < 0.006);
}

#[test]
fn bad_chart_data_is_refused() {
    let named = |e: ToolpathError, what: &str| {
        let ToolpathError::InvalidParameter { name, .. } = &e else {
            panic!("{e:?}")
        };
        assert!(name.contains(what), "{name}");
    };
    let nan = Chart::new("c", "x", "y").line("s", vec![[0.0, 1.0], [1.0, f64::NAN]]);
    named(nan.render().unwrap_err(), "series \"s\", point 1");
    let inf = Chart::new("c", "x", "y").line("s", vec![[f64::INFINITY, 1.0]]);
    assert!(inf.render().is_err());
    let limit = Chart::new("c", "x", "y")
        .line("s", vec![[0.0, 1.0]])
        .limit("l", f64::NAN);
    named(limit.render().unwrap_err(), "limit \"l\"");
    assert!(Chart::new("empty", "x", "y").render().is_err());
    assert!(Chart::new("c", "x", "y")
        .line("s", vec![])
        .render()
        .is_err());
}

/// The zig-zag smoothed, sampled and planned under seed 003's limits, at T = 2 ms.
fn zig_zag() -> (
    kerf_toolpath::SmoothedPath,
    Vec<kerf_toolpath::PathSample>,
    Vec<kerf_toolpath::FeedSample>,
) {
    let path = smooth_polyline(&ZIG_ZAG, 1e-4).unwrap();
    let samples = sample_path(&path, 1e-5);
    let plan = plan_feed(&samples, &feed_limits()).unwrap();
    let feed = plan.sample(0.002);
    (path, samples, feed)
}

#[test]
fn the_pipelines_figures() {
    let (path, samples, feed) = zig_zag();
    let limits = feed_limits();
    let plots = pipeline_plots(&path, &samples, &feed, &limits, 0.002).unwrap();
    let names: Vec<&str> = plots.iter().map(|p| p.0.as_str()).collect();
    assert_eq!(
        names,
        [
            "path_xy.svg",
            "feed.svg",
            "chord_error.svg",
            "normal_acceleration.svg",
            "normal_jerk.svg",
            "contour_error.svg",
            "tangential_acceleration.svg",
            "tangential_jerk.svg"
        ]
    );
    let lines = [2, 2, 2, 1, 2, 1, 1, 1];
    let limit_lines = [0, 1, 1, 1, 1, 1, 2, 2];
    for (k, (name, svg)) in plots.iter().enumerate() {
        let t = check_structure(svg);
        assert_eq!(count(&t, "polyline", "series"), lines[k], "{name}");
        assert_eq!(count(&t, "line", "limit"), limit_lines[k], "{name}");
    }
    // The XY plot's red dots are the polyline's points.
    let t = tags(&plots[0].1);
    let dots = t
        .iter()
        .filter(|(n, c, _, tag)| n == "circle" && !c && attr(tag, "r") == Some("2.5"))
        .count();
    assert_eq!(dots, ZIG_ZAG.len());
    // The planned feed never rises above the line of F (SVG y grows downwards).
    let t = tags(&plots[1].1);
    let f = attr(
        &t.iter()
            .find(|x| attr(&x.3, "class") == Some("limit"))
            .unwrap()
            .3,
        "y1",
    )
    .unwrap()
    .parse::<f64>()
    .unwrap();
    let v = &t
        .iter()
        .find(|x| attr(&x.3, "data-name") == Some("planned feed v"))
        .unwrap()
        .3;
    for pair in attr(v, "points").unwrap().split(' ') {
        let y: f64 = pair.split_once(',').unwrap().1.parse().unwrap();
        assert!(y >= f - 0.01, "feed above F: {y} < {f}");
    }
    // Without a servo there is no contour error to plot.
    let mut no_servo = limits;
    no_servo.curvature.servo = None;
    let plots = pipeline_plots(&path, &samples, &feed, &no_servo, 0.002).unwrap();
    assert_eq!(plots.len(), 7);
    assert!(plots.iter().all(|p| p.0 != "contour_error.svg"));
}

#[test]
fn bad_pipeline_input_is_refused() {
    let (path, samples, feed) = zig_zag();
    let limits = feed_limits();
    let mut bad = feed.clone();
    bad[3].v = f64::NAN;
    let e = pipeline_plots(&path, &samples, &bad, &limits, 0.002).unwrap_err();
    assert!(
        matches!(&e, ToolpathError::InvalidParameter { name, .. } if name == "feed sample 3"),
        "{e:?}"
    );
    let mut bad = feed.clone();
    bad[5].s = f64::NAN;
    assert!(
        pipeline_plots(&path, &samples, &bad, &limits, 0.002).is_err(),
        "a NaN arc length"
    );
    assert!(pipeline_plots(&path, &samples, &feed[..1], &limits, 0.002).is_err());
    assert!(pipeline_plots(&path, &samples[..1], &feed, &limits, 0.002).is_err());
    assert!(pipeline_plots(&path, &samples, &feed, &limits, 0.0).is_err());
    let mut bad_limits = limits;
    bad_limits.tangential_jerk = -1.0;
    assert!(pipeline_plots(&path, &samples, &feed, &bad_limits, 0.002).is_err());
    // A non-finite point of the path itself reaches the XY chart's check.
    let mut bad_path = path.clone();
    bad_path.polyline[2][1] = f64::INFINITY;
    let e = pipeline_plots(&bad_path, &samples, &feed, &limits, 0.002).unwrap_err();
    assert!(
        matches!(&e, ToolpathError::InvalidParameter { name, .. } if name.contains("G01 polyline")),
        "{e:?}"
    );
}

#[test]
fn dense_series_are_thinned_within_a_quarter_pixel() {
    let n = 100_000;
    let points: Vec<[f64; 2]> = (0..n)
        .map(|k| {
            let x = k as f64 / n as f64 * 10.0;
            [x, (3.0 * x).sin() + 0.2 * (40.0 * x).sin()]
        })
        .collect();
    let chart = Chart::new("dense", "x [m]", "y [m]").line("wave", points.clone());
    let (xa, ya) = chart.axes().unwrap();
    let svg = chart.render().unwrap();
    let t = check_structure(&svg);
    let frame = &t
        .iter()
        .find(|x| attr(&x.3, "class") == Some("frame"))
        .unwrap()
        .3;
    let f = |k: &str| attr(frame, k).unwrap().parse::<f64>().unwrap();
    let (fx, fy, fw, fh) = (f("x"), f("y"), f("width"), f("height"));
    let poly = &t
        .iter()
        .find(|x| attr(&x.3, "class") == Some("series"))
        .unwrap()
        .3;
    let drawn: Vec<(f64, f64)> = attr(poly, "points")
        .unwrap()
        .split(' ')
        .map(|p| {
            let (x, y) = p.split_once(',').unwrap();
            (x.parse().unwrap(), y.parse().unwrap())
        })
        .collect();
    assert!(drawn.len() < n / 4, "{} points drawn", drawn.len());
    // Every point of the data is within a quarter pixel (plus rounding) of a drawn one, in
    // order: a walk along the drawn points finds each; the last point is drawn exactly.
    let mut j = 0;
    for p in &points {
        let px = fx + (p[0] - xa.lo) / (xa.hi - xa.lo) * fw;
        let py = fy + (1.0 - (p[1] - ya.lo) / (ya.hi - ya.lo)) * fh;
        let near = |q: (f64, f64)| (q.0 - px).abs() < 0.26 && (q.1 - py).abs() < 0.26;
        while !near(drawn[j]) {
            j += 1;
            assert!(j < drawn.len(), "({px}, {py}) is not drawn");
        }
    }
    let last = points[n - 1];
    let end = drawn[drawn.len() - 1];
    assert!((end.0 - (fx + (last[0] - xa.lo) / (xa.hi - xa.lo) * fw)).abs() < 0.006);
    assert!((end.1 - (fy + (1.0 - (last[1] - ya.lo) / (ya.hi - ya.lo)) * fh)).abs() < 0.006);
}

#[test]
fn geometry_is_drawn_at_equal_scales() {
    let chart = Chart::new("xy", "x [mm]", "y [mm]")
        .line("tall", vec![[0.0, 0.0], [1.0, 30.0], [2.0, 0.0]])
        .with_equal_aspect();
    let (x, y) = chart.axes().unwrap();
    let (w, h) = kerf_toolpath::plot::chart::plot_size();
    assert!(
        ((x.hi - x.lo) / w - (y.hi - y.lo) / h).abs() < 1e-12,
        "units per pixel: x {} y {}",
        (x.hi - x.lo) / w,
        (y.hi - y.lo) / h
    );
    assert!(x.lo <= 0.0 && x.hi >= 2.0 && y.lo <= 0.0 && y.hi >= 30.0);
    assert!(x.ticks().len() >= 3 && y.ticks().len() >= 3);
}

#[test]
fn the_whole_normal_jerk_matches_a_difference_of_the_normal_acceleration() {
    // The plan at 20 µs: d(a_n n)/dt by central differences in time of v² d²p/ds² against the
    // chart's |d(a_n n)/dt| (2 v a κ + v³ dκ/ds along n, v³ κ² along t).
    let (path, samples, _) = zig_zag();
    let limits = feed_limits();
    let dt = 2e-5;
    let feed = plan_feed(&samples, &limits).unwrap().sample(dt);
    let charts = kerf_toolpath::plot::pipeline_charts(&path, &samples, &feed, &limits, dt).unwrap();
    let jerk = &charts.iter().find(|c| c.0 == "normal_jerk.svg").unwrap().1;
    let whole = &jerk
        .series
        .iter()
        .find(|s| s.name == "|d(a_n n)/dt|")
        .unwrap()
        .points;
    let an: Vec<[f64; 3]> = feed
        .iter()
        .map(|p| {
            let n = kerf_toolpath::derivatives_at(&path, &samples, p.s).2;
            [p.v * p.v * n[0], p.v * p.v * n[1], p.v * p.v * n[2]]
        })
        .collect();
    let mut errors = Vec::new();
    for k in 1..feed.len() - 1 {
        let d: Vec<f64> = (0..3)
            .map(|i| (an[k + 1][i] - an[k - 1][i]) / (2.0 * dt))
            .collect();
        let fd = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() * 1e3; // mm/s³
        let plotted = whole[k][1];
        if plotted > 1e4 {
            errors.push((fd - plotted).abs() / plotted);
        }
    }
    errors.sort_by(f64::total_cmp);
    assert!(errors.len() > 100, "{} points on corners", errors.len());
    let median = errors[errors.len() / 2];
    let p90 = errors[errors.len() * 9 / 10];
    println!("relative difference: median {median:.2e}, 90th percentile {p90:.2e}");
    assert!(median < 1e-3 && p90 < 1e-2, "median {median}, p90 {p90}");
}
