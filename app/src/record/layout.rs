//! The viewer's layout for a recording: the blueprint sent at the start.

use rerun::RecordingStream;
use tetlab_core::measures::metrics::Metrics;

/// The default layout: a 3D view per root (side by side) on the left, the four metrics and the
/// energy account stacked on the right (each plot shows the metric of every root), with `modes`
/// a plot of the eigenvalues `record --modes` logs below them, and with `exact_step` one of the
/// distance from the exact step `record --exact-step` logs. Each plot also shows the series of
/// each body of `bodies` (`bodies/<name>/`, [`super::body_parts::body_plots`]) under every root.
pub fn send_layout(
    rec: &RecordingStream,
    roots: &[&str],
    bodies: &[String],
    modes: bool,
    exact_step: bool,
) {
    use rerun::blueprint::{
        Blueprint, BlueprintActivation, Horizontal, Spatial3DView, TimeSeriesView, Vertical,
    };
    // One plot of the entity at `path` under every root.
    let plot = |title: String, path: &str| -> rerun::blueprint::ContainerLike {
        let contents: Vec<String> = (roots.iter())
            .flat_map(|root| {
                let each = bodies
                    .iter()
                    .map(move |body| format!("+ {root}{body}{path}"));
                std::iter::once(format!("+ {root}{path}")).chain(each)
            })
            .collect();
        TimeSeriesView::new(title).with_contents(contents).into()
    };
    let plots = Metrics::default()
        .headline()
        .map(|(name, _)| plot(name.replace('_', " "), &format!("metrics/{name}")));
    // The energy account (`energy/*`), every part of it in one plot.
    let energy = plot("energy, J".into(), "energy/**");
    // The eigenvalues of `record --modes`, one plot with a series per mode.
    let modes = modes.then(|| {
        plot(
            "eigenvalues of the tet's energy Hessian".into(),
            "modes/eigenvalues",
        )
    });
    // `record --exact-step`: each frame's distance from the exact one.
    let exact_step = exact_step.then(|| {
        plot(
            "distance from the exact step, m".into(),
            "exact_step/distance",
        )
    });
    let plots: Vec<_> = plots
        .into_iter()
        .chain(std::iter::once(energy))
        .chain(modes)
        .chain(exact_step)
        .collect();
    let views = roots.iter().map(|root| {
        let title = if root.is_empty() {
            "soft body"
        } else {
            root.trim_end_matches('/')
        };
        Spatial3DView::new(title)
            .with_origin(format!("{root}world"))
            .into()
    });
    let layout = Horizontal::new([Horizontal::new(views).into(), Vertical::new(plots).into()])
        .with_column_shares([3.0, 2.0]);
    Blueprint::new(layout)
        .send(rec, BlueprintActivation::default())
        .ok();
}
