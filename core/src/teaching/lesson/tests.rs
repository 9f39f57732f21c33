//! The lesson format, actions, expectations and runner, on small lessons written here.

use super::format::{reflow, resolve_scene};
use super::*;

fn parse(text: &str) -> Result<Lesson, LessonError> {
    Lesson::parse(Path::new("lessons/x.toml"), text)
}

#[test]
fn a_small_lesson_reads_and_runs() {
    let lesson = parse(
        r#"
title = "mirror"
scene = "tet"
[settings]
constraints = "edges"
gravity = 0
[[step]]
text = "mirror it"
actions = ["mirror"]
frames = 30
expect = ["inverted_tets == 1", "max_edge_strain < 1e-9"]
"#,
    )
    .unwrap();
    assert_eq!(
        lesson.settings.active,
        PerFamily::builtin_list("edges").unwrap()
    );
    assert!(!lesson.settings.ground);
    let mut run = LessonRun::new(&lesson);
    let outcome = run
        .run_step(&lesson.steps[0], |_| ControlFlow::Continue(()))
        .unwrap()
        .unwrap();
    assert!(
        outcome.checks.iter().all(|(_, _, holds)| *holds),
        "{outcome:?}"
    );
    assert_eq!(run.simulation.frame(), 30);
}

#[test]
fn mistakes_name_the_file_and_line() {
    let cases = [
        ("title = 1\nscene = \"tet\"\n", 1, "invalid type"),
        (
            "title = \"t\"\nscene = \"tet\"\n[[step]]\ntext = \"x\"\nactions = [\"mirror\", \"twirl\"]\n",
            5,
            "'twirl' is not an action",
        ),
        (
            "title = \"t\"\nscene = \"tet\"\n[[step]]\ntext = \"x\"\n\nexpect = [\"speed > 1\"]\n",
            6,
            "'speed' is not a metric",
        ),
        (
            "title = \"t\"\nscene = \"nowhere.node\"\n[[step]]\ntext = \"x\"\n",
            2,
            "scene 'nowhere.node'",
        ),
        (
            "title = \"t\"\nscene = \"tet\"\n[settings]\nconstraints = \"edges,glue\"\n[[step]]\ntext = \"x\"\n",
            4,
            "'glue' is not a constraint family",
        ),
        (
            "title = \"t\"\nscene = \"tet\"\n[[step]]\ntext = \"x\"\nactions = [\"select:4\"]\n",
            5,
            "tet 4 is out of range",
        ),
        (
            "title = \"t\"\nscene = \"tet\"\ncolour = \"red\"\n",
            3,
            "unknown field",
        ),
        (
            "title = \"t\"\nscene = \"tet\"\n",
            0,
            "at least one [[step]]",
        ),
        (
            "title = \"t\"\nscene = \"tet\"\n[settings]\ndt = nan\n[[step]]\ntext = \"x\"\n",
            4,
            "in [settings]: dt NaN is not a number",
        ),
        (
            "title = \"t\"\nscene = \"tet\"\n[settings]\n\nsubsteps = 0\n[[step]]\ntext = \"x\"\n",
            5,
            "in [settings]: substeps 0 is out of range: expected 1 <= substeps <= 1000",
        ),
        (
            "title = \"t\"\nscene = \"tet\"\n[settings]\ncompliance = { volume = inf }\n[[step]]\ntext = \"x\"\n",
            4,
            "compliance.volume: compliance inf is out of range",
        ),
        (
            "title = \"t\"\nscene = \"tet\"\n[settings]\ncompliance = { edges = nan }\n[[step]]\ntext = \"x\"\n",
            4,
            "compliance.edges: compliance NaN is not a number",
        ),
        (
            "title = \"t\"\nscene = \"tet\"\n[[step]]\ntext = \"x\"\nactions = [\"reset:whatever\"]\n",
            5,
            "'reset:whatever': reset takes no value",
        ),
        (
            "title = \"t\"\nscene = \"tet\"\n[[step]]\ntext = \"x\"\nactions = [\"compliance:edges=1e303\"]\n",
            5,
            "compliance 1e303 is out of range",
        ),
        (
            "title = \"t\"\nscene = \"ball\"\nresolution = 128\n[[step]]\ntext = \"x\"\n",
            3,
            "ball at resolution 128 would have 100663296 tets",
        ),
        (
            "\u{feff}title = \"t\"\nscene = \"tet\"\ncolour = 1\n",
            3,
            "unknown field `colour`",
        ),
    ];
    for (text, line, message) in cases {
        let error = parse(text).unwrap_err();
        assert_eq!(error.line.unwrap_or(0), line, "{error}");
        assert!(error.to_string().contains(message), "{error}");
        assert!(error.to_string().starts_with("lessons/x.toml:"), "{error}");
    }
}

#[test]
fn a_lesson_file_that_is_not_text_names_the_line() {
    let path = std::env::temp_dir().join(format!("tetlab-lesson-{}.toml", std::process::id()));
    std::fs::write(&path, b"title = \"t\"\nscene = \"tet\xff\"\n").unwrap();
    let error = Lesson::load(&path).unwrap_err();
    std::fs::remove_file(&path).ok();
    assert_eq!(error.line, Some(2), "{error}");
    assert!(error.message.contains("not text"), "{error}");
}

/// The comparison is checked like the main simulation: when it diverges the step is an
/// error, never "observed" (a NaN metric holds no expectation either).
#[test]
fn a_comparison_that_diverges_stops_the_step() {
    let lesson = parse(
        r#"
title = "t"
scene = "tet"
[settings]
constraints = "edges"
[[step]]
text = "x"
actions = ["compare:edges,volume", "invert"]
frames = 30
expect = ["compare.volume_error < 0.001"]
"#,
    )
    .unwrap();
    let mut run = LessonRun::new(&lesson);
    // What no accepted setting can do: a compliance past the limits, so α / h² is infinite.
    run.apply(Action::Compare(Some(
        PerFamily::builtin_list("edges,volume").unwrap(),
    )));
    let comparison = run.comparison.as_mut().unwrap();
    let mut settings = *comparison.settings();
    settings.compliance[Family::VOLUME] = 1e305;
    comparison.set_settings(settings);
    let step = Step {
        actions: vec![Action::Perturb(Perturbation::Invert)],
        ..lesson.steps[0].clone()
    };
    let divergence = run
        .run_step(&step, |_| ControlFlow::Continue(()))
        .unwrap_err();
    assert_eq!(divergence.subject, "the comparison", "{divergence}");
    let nan = Metrics {
        volume_error: f64::NAN,
        ..Metrics::default()
    };
    let families = Families::builtin();
    let expectation = Expectation::parse(&families, "volume_error != 0").unwrap();
    let measured = Measured {
        simulation: &run.simulation,
        tet: 0,
        metrics: &nan,
        comparison: None,
    };
    assert!(!expectation.check(measured).unwrap().1);
}

/// A lesson can be listed, and its missing mesh named, even when it cannot be opened.
#[test]
fn a_lesson_whose_mesh_is_missing_still_has_a_title() {
    let text = "title = \"t\"\nscene = \"../nowhere/bunny.node\"\n[[step]]\ntext = \"x\"\n";
    let header = LessonHeader::parse(Path::new("lessons/x.toml"), text).unwrap();
    assert_eq!(header.title, "t");
    assert_eq!(header.missing_mesh(), Some("lessons/../nowhere/bunny.node"));
    assert!(parse(text).unwrap_err().message.contains("bunny.node"));
    let cube = LessonHeader::parse(Path::new("x.toml"), "title = \"c\"\nscene = \"cube\"\n");
    assert_eq!(cube.unwrap().missing_mesh(), None);
}

#[test]
fn paragraphs_are_reflowed_into_lines() {
    assert_eq!(reflow("\n one\ntwo  \n\n\nthree\n"), "one two\n\nthree");
}

#[test]
fn a_mesh_scene_is_found_next_to_the_lesson() {
    assert_eq!(
        resolve_scene(Path::new("assets/lessons/6.toml"), "../meshes/a.node"),
        "assets/lessons/../meshes/a.node"
    );
    assert_eq!(
        resolve_scene(Path::new("assets/lessons/6.toml"), "cube"),
        "cube"
    );
}

#[test]
fn the_comparison_gets_the_same_edits_and_keeps_its_families() {
    let lesson = parse(
            "title = \"t\"\nscene = \"cube\"\n[settings]\nconstraints = \"edges\"\n[[step]]\ntext = \"x\"\n",
        )
        .unwrap();
    let mut run = LessonRun::new(&lesson);
    run.apply(Action::Compare(Some(PerFamily::splat(true))));
    run.apply(Action::Perturb(Perturbation::Mirror));
    run.apply(Action::Substeps(3));
    let comparison = run.comparison.as_ref().unwrap();
    assert_eq!(comparison.positions(), run.simulation.positions());
    // Every family of the table: a simulation keeps its active families to its table's.
    let every = comparison.families().per_family(|_| true);
    assert_eq!(*comparison.active(), every);
    assert_eq!(comparison.settings().substeps, 3);
    run.apply(Action::Compare(None));
    assert!(run.comparison.is_none());
}
