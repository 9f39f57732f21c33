//! The viewer's layout for a recording: the blueprint sent at the start.

use rerun::RecordingStream;
use tetlab_core::measures::metrics::Metrics;

/// The default layout: a 3D view per root (side by side) on the left, the four metrics and the
/// energy account stacked on the right (each plot shows the metric of every root), with `modes`
/// a plot of the eigenvalues `record --modes` logs below them, and with `exact_step` one of the
/// distance from the exact step `record --exact-step` logs.
pub fn send_layout(rec: &RecordingStream, roots: &[&str], modes: bool, exact_step: bool) {
    use rerun::blueprint::{
        Blueprint, BlueprintActivation, Horizontal, Spatial3DView, TimeSeriesView, Vertical,
    };
    let plots = Metrics::default().headline().map(|(name, _)| {
        let contents: Vec<String> = roots
            .iter()
            .map(|root| format!("+ {root}metrics/{name}"))
            .collect();
        TimeSeriesView::new(name.replace('_', " "))
            .with_contents(contents)
            .into()
    });
    // The eigenvalues of `record --modes`, one plot with a series per mode.
    let modes = modes.then(|| {
        TimeSeriesView::new("eigenvalues of the tet's energy Hessian")
            .with_contents(
                roots
                    .iter()
                    .map(|root| format!("+ {root}modes/eigenvalues"))
                    .collect::<Vec<_>>(),
            )
            .into()
    });
    // The energy account (`energy/*`), every part of it in one plot.
    let energy = TimeSeriesView::new("energy, J")
        .with_contents(
            roots
                .iter()
                .map(|root| format!("+ {root}energy/**"))
                .collect::<Vec<_>>(),
        )
        .into();
    // `record --exact-step`: each frame's distance from the exact one.
    let exact_step = exact_step.then(|| {
        TimeSeriesView::new("distance from the exact step, m")
            .with_contents(
                roots
                    .iter()
                    .map(|root| format!("+ {root}exact_step/distance"))
                    .collect::<Vec<_>>(),
            )
            .into()
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
