//! The application's tests: preferences, links and the report.

use super::*;
use tetlab_core::constraints::Family;
use tetlab_core::simulation::Method;

/// What `save` writes, `new` reads back: the preferences as JSON text.
#[test]
fn preferences_survive_a_save_and_load() {
    let mut preferences = Preferences::default();
    preferences.scene.builtin = "ball".into();
    preferences.scene.resolution = 2;
    preferences.settings.method = Method::Pbd;
    preferences.settings.active[Family::HEIGHT] = true;
    preferences.settings.substeps = 7;
    preferences.view.see_through = true;
    let text = serde_json::to_string(&preferences).unwrap();
    let restored: Preferences = serde_json::from_str(&text).unwrap();
    assert_eq!(restored, preferences);
    let app = TetlabApp::with_preferences(restored);
    assert_eq!(app.bench.scene.name, "ball");
    assert_eq!(*app.bench.simulation.settings(), preferences.settings);
}

#[test]
fn missing_or_old_preferences_fall_back_to_defaults() {
    let restored: Preferences = serde_json::from_str(r#"{"scene": {"builtin": "tet"}}"#).unwrap();
    assert_eq!(restored.scene.builtin, "tet");
    assert_eq!(restored.settings, Preferences::default().settings);
    assert!(restored.settings.settle_edits);
}

/// A link made on one workbench shows the same state on another: the scene, the settings,
/// the edits (the same positions, bit for bit), the camera; and a lesson at its step.
#[test]
fn a_link_shows_the_same_state_on_another_workbench() {
    let mut teacher = TetlabApp::with_preferences(Preferences::default());
    teacher.request(SceneRequest::Builtin(Builtin::Cube, 2));
    let mut settings = *teacher.bench.simulation.settings();
    settings.active[Family::HEIGHT] = true;
    settings.substeps = 12;
    teacher.set_settings(settings);
    teacher.act(Action::Mirror);
    teacher.bench.select_tet(5);
    teacher.act(Action::InvertSelected);
    teacher.viewport.camera.yaw = 2.0;
    let url = teacher.link_url();
    let (_, fragment) = url.split_once('#').unwrap();

    let mut student = TetlabApp::with_preferences(Preferences::default());
    student.open_fragment(fragment);
    assert_eq!(student.error, None);
    assert_eq!(student.bench.scene.name, "cube");
    assert_eq!(student.bench.simulation.tets().len(), 48);
    assert_eq!(
        student.bench.simulation.settings(),
        teacher.bench.simulation.settings()
    );
    assert_eq!(
        student.bench.simulation.positions(),
        teacher.bench.simulation.positions()
    );
    assert_eq!(student.viewport.camera, teacher.viewport.camera);
    assert_eq!(student.link(), teacher.link());

    teacher.lesson_request(LessonRequest::Builtin(2));
    teacher.lesson_request(LessonRequest::Next);
    let mut student = TetlabApp::with_preferences(Preferences::default());
    student.open_fragment(&teacher.link().fragment());
    let state = student.lesson.as_ref().expect("the lesson is open");
    assert_eq!(state.step, 1);
    assert_eq!(
        state.lesson.title,
        teacher.lesson.as_ref().unwrap().lesson.title
    );
}

/// A scene file that comes with tetlab is loaded from the scene section and named in a link,
/// which opens it on another workbench; one that needs a mesh that is not there says so.
#[test]
fn a_link_names_a_shipped_scene_file() {
    let mut teacher = TetlabApp::with_preferences(Preferences::default());
    teacher.request(SceneRequest::Shipped("folded-bar.toml"));
    assert_eq!(teacher.error, None);
    assert_eq!(teacher.bench.scene.bodies.len(), 1);
    let fragment = teacher.link().fragment();
    assert!(fragment.starts_with("scene=folded-bar.toml"), "{fragment}");

    let mut student = TetlabApp::with_preferences(Preferences::default());
    student.open_fragment(&fragment);
    assert_eq!(student.error, None);
    assert_eq!(student.bench.scene.name, "folded bar");
    assert_eq!(
        student.bench.simulation.positions(),
        teacher.bench.simulation.positions()
    );
    assert_eq!(student.link(), teacher.link());
    // A scene file of the user's is not a link's: the link names no scene.
    student.load(teacher.bench.scene.clone());
    assert_eq!(student.link().scene, None);
    assert_eq!(
        student.load_shipped("teapot.toml"),
        Err("teapot.toml: not a scene file that comes with tetlab".to_owned())
    );
}

/// "Add a body" adds the chosen built-in to the scene shown, over it: a scene of one body
/// becomes one of two, measured body by body, and with contact on the new body lands on the
/// old one rather than passing through it.
#[test]
fn add_a_body_drops_one_more_onto_the_scene() {
    let mut app = TetlabApp::with_preferences(Preferences::default());
    app.request(SceneRequest::Builtin(Builtin::Cube, 2));
    app.request(SceneRequest::AddBody(Builtin::Cube, 1));
    assert_eq!(app.error, None);
    let names: Vec<&str> = app
        .bench
        .scene
        .bodies
        .iter()
        .map(|b| b.name.as_str())
        .collect();
    assert_eq!(names, ["cube", "cube2"]);
    assert_eq!(app.bench.simulation.positions().len(), 27 + 8);
    let mut settings = *app.bench.simulation.settings();
    settings.active = app
        .bench
        .simulation
        .families()
        .parse_list("edges,volume,contact")
        .unwrap();
    app.set_settings(settings);
    for _ in 0..60 {
        app.bench.simulation.step();
    }
    let bodies = tetlab_core::measures::metrics::Metrics::measure_bodies(&app.bench.simulation);
    let upper = bodies[1].1.centre_of_mass.y;
    assert!(
        upper > 1.0,
        "the added cube rests on the first: its centre at {upper}"
    );
}

/// The report a browser test reads: the scene, the inversions, the lesson step and its
/// checks, the error.
#[test]
fn the_report_says_what_the_workbench_shows() {
    let mut app = TetlabApp::with_preferences(Preferences::default());
    app.lesson_request(LessonRequest::Builtin(3));
    app.lesson_request(LessonRequest::Next);
    let report = app.report();
    assert_eq!((report.scene.as_str(), report.tets), ("tet", 1));
    let lesson = report.lesson.expect("the lesson");
    assert_eq!((lesson.step, lesson.steps), (2, 4));
    assert_eq!(lesson.checks.len(), 1);
    assert_eq!(lesson.checks[0].expect, "inverted_tets == 1");
    assert!(!lesson.checks[0].holds);
    app.do_step();
    let report = app.report();
    assert_eq!(report.inverted_tets, 1);
    assert!(report.lesson.unwrap().checks[0].holds);
    assert_eq!(report.frame, app.bench.simulation.frame());
}

/// A fragment that cannot be read leaves the defaults and says which key was wrong.
#[test]
fn a_malformed_link_falls_back_to_the_defaults_with_a_message() {
    let mut app = TetlabApp::with_preferences(Preferences::default());
    let before = *app.bench.simulation.settings();
    app.open_fragment("#scene=cube&substeps=lots");
    let error = app.error.as_deref().unwrap();
    assert!(error.contains("'substeps'"), "{error}");
    assert!(error.contains("defaults"), "{error}");
    assert_eq!(*app.bench.simulation.settings(), before);

    let mut app = TetlabApp::with_preferences(Preferences::default());
    app.open_fragment("#scene=tet&edits=tet:9:0");
    let error = app.error.as_deref().unwrap();
    assert!(
        error.contains("tet 9 is not in a body of 1 tets"),
        "{error}"
    );
}

#[test]
fn remembered_settings_out_of_range_are_refused_with_a_message() {
    let mut preferences = Preferences::default();
    preferences.settings.dt = 0.0;
    preferences.settings.compliance[Family::VOLUME] = f64::INFINITY;
    let app = TetlabApp::with_preferences(preferences);
    assert_eq!(
        *app.bench.simulation.settings(),
        Preferences::default().settings
    );
    let error = app.error.expect("the refusal is shown");
    assert!(error.contains("dt 0 is out of range"), "{error}");
}
