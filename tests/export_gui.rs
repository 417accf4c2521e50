//! The viewer's side of figures and scenes with egui_kittest: the export dialog
//! (Ctrl+Shift+S), figures at 1×/2×/4×, transparent backgrounds, scene
//! shortcuts, toasts, and the albedo and Fresnel views.

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv::app::Viewer;
use bv::app::screenshot::{FigureLayout, FigureSettings, Format, ScreenGeometry, Target};
use bv::session::Command;
use bv::session::state::AppState;
use bv::views::albedo::AlbedoView;
use bv::views::fresnel::FresnelView;
use eframe::egui;
use egui_kittest::Harness;
use egui_kittest::kittest::{Queryable, by};

const SIZE: [f32; 2] = [1280.0, 800.0];

fn viewer(state: AppState) -> Harness<'static, Viewer> {
    let mut h = Harness::builder()
        .with_size(SIZE)
        .with_max_steps(12)
        .build_ui_state(|ui, v: &mut Viewer| v.ui(ui), Viewer::new(state));
    h.run();
    h
}

fn tmp(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("bv-export-gui-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn two_brdfs() -> AppState {
    let mut s = AppState::default();
    s.add(bv_core::ModelSpec::new("cook-torrance").unwrap());
    s.add(bv_core::ModelSpec::new("lambert").unwrap());
    s.selected = Some(s.brdfs[0].id);
    s
}

#[test]
fn ctrl_shift_s_opens_the_export_dialog() {
    let mut h = viewer(two_brdfs());
    assert!(h.query_by_label("Export figure").is_none());
    h.key_press_modifiers(
        egui::Modifiers::COMMAND | egui::Modifiers::SHIFT,
        egui::Key::S,
    );
    h.run();
    assert!(h.state().export.dialog_open);
    assert!(h.get_all_by_label("Export figure").count() >= 1);
    // Choosing "4×" in the dialog changes the settings.
    h.get_by_label("4×").click();
    h.run();
    assert_eq!(h.state().export.settings.scale, 4);
    // Ctrl+S without a scene file asks where to save (a file dialog opens);
    // with one it saves there at once and says so.
    let path = tmp("ctrl-s.toml");
    h.state_mut().export.scene_path = Some(path.clone());
    h.state_mut().export.dialog_open = false;
    h.run();
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::S);
    h.run();
    let loaded = bv::session::scene_file::load(&path).unwrap();
    assert_eq!(&loaded.state, h.state().state());
    let toast = h.state().export.toast.clone().unwrap();
    assert!(
        toast.text.contains("ctrl-s.toml") && !toast.error,
        "{}",
        toast.text
    );
}

fn geometry(ppp: f32) -> ScreenGeometry {
    ScreenGeometry {
        window: egui::vec2(SIZE[0], SIZE[1]),
        pixels_per_point: ppp,
    }
}

#[test]
fn figures_at_1x_2x_4x_are_drawn_at_that_resolution() {
    let mut v = Viewer::new(two_brdfs());
    let state = v.state().clone();
    let mut sizes = Vec::new();
    for scale in [1, 2, 4] {
        let path = tmp(&format!("polar-{scale}x.png"));
        let s = FigureSettings {
            target: Target::View("polar".into()),
            format: Format::Png,
            scale,
            transparent: false,
            layout: FigureLayout::Screen,
            caption: false,
        };
        let msg = v
            .export
            .export_figure(
                &state,
                &s,
                &path,
                geometry(1.0),
                Some(egui::vec2(300.0, 200.0)),
                bv::app::viewer::figure_window,
            )
            .unwrap();
        assert!(msg.contains(&path.display().to_string()), "{msg}");
        let img = image::open(&path).unwrap().to_rgba8();
        sizes.push(img.dimensions());
    }
    assert_eq!(sizes, vec![(300, 200), (600, 400), (1200, 800)]);

    // Laid out as a figure, whatever the view's size on screen: at 2× on a
    // 1× screen, 1600 × 1200 pixels, with the x axis's numbers.
    let path = tmp("polar-figure.png");
    let s = FigureSettings {
        target: Target::View("cartesian".into()),
        format: Format::Png,
        scale: 2,
        transparent: false,
        layout: FigureLayout::Figure,
        caption: false,
    };
    v.export
        .export_figure(
            &state,
            &s,
            &path,
            geometry(1.0),
            Some(egui::vec2(300.0, 200.0)),
            bv::app::viewer::figure_window,
        )
        .unwrap();
    let img = image::open(&path).unwrap().to_rgba8();
    assert_eq!(img.dimensions(), (1600, 1200));

    // The whole window, transparent: panels are unfilled.
    let path = tmp("window.png");
    let s = FigureSettings {
        target: Target::Window,
        format: Format::Png,
        scale: 1,
        transparent: true,
        layout: FigureLayout::Figure,
        caption: false,
    };
    v.export
        .export_figure(
            &state,
            &s,
            &path,
            geometry(1.0),
            None,
            bv::app::viewer::figure_window,
        )
        .unwrap();
    let img = image::open(&path).unwrap().to_rgba8();
    assert_eq!(img.dimensions(), (1280, 800));
    let clear = img.pixels().filter(|p| p.0[3] == 0).count();
    assert!(clear > 1280 * 800 / 10, "only {clear} transparent pixels");

    // SVG of a plot and the lobe's mesh.
    for (target, format, name) in [
        ("cartesian", Format::Svg, "cartesian.svg"),
        ("lobe", Format::Mesh, "lobe.obj"),
    ] {
        let path = tmp(name);
        let s = FigureSettings {
            target: Target::View(target.into()),
            format,
            scale: 1,
            transparent: false,
            layout: FigureLayout::Screen,
            caption: false,
        };
        v.export
            .export_figure(
                &state,
                &s,
                &path,
                geometry(1.0),
                Some(egui::vec2(400.0, 300.0)),
                bv::app::viewer::figure_window,
            )
            .unwrap();
        assert!(std::fs::metadata(&path).unwrap().len() > 1000, "{name}");
    }
}

#[test]
fn the_albedo_view_computes_in_the_background_and_finishes() {
    let mut h = viewer(two_brdfs());
    let ids: Vec<u64> = h.state().state().brdfs.iter().map(|b| b.id).collect();
    // Change a parameter so that the curve is not cached from another test.
    h.state_mut().push(Command::SetParam {
        brdf: ids[1],
        param: "albedo".into(),
        value: bv_core::ParamValue::Color([0.37, 0.37, 0.37]),
    });
    let start = std::time::Instant::now();
    loop {
        h.run();
        let v = h.state().view::<AlbedoView>().unwrap();
        if v.progress.is_none() {
            break;
        }
        assert!(
            start.elapsed().as_secs() < 120,
            "albedo still computing: {:?}",
            v.progress
        );
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    // ρhh of the Lambert BRDF is in the legend: its albedo, 0.37.
    assert!(
        h.query_all(by().label_contains("ρhh = 0.37").include_labels())
            .next()
            .is_some(),
        "no ρhh in the legend"
    );
}

#[test]
fn the_fresnel_view_follows_the_selected_brdf() {
    let mut h = viewer(two_brdfs());
    let c = h
        .state()
        .view::<FresnelView>()
        .unwrap()
        .last
        .clone()
        .unwrap();
    // Cook-Torrance's default is a dielectric of η = 1.5: Rp, Rs, F, F inside
    // and Schlick's of the same F0 = 0.04 (dashed); Brewster's angle
    // atan 1.5 = 56.31°, the critical angle asin(1/1.5) = 41.81°.
    assert_eq!(
        c.series.len(),
        5,
        "{:?}",
        c.series.iter().map(|s| &s.label).collect::<Vec<_>>()
    );
    let at = |prefix: &str| {
        c.vlines
            .iter()
            .find(|m| m.label.starts_with(prefix))
            .unwrap()
            .at
    };
    assert!((at("θB") - 1.5f64.atan().to_degrees()).abs() < 1e-9);
    assert!((at("θc") - (1.0f64 / 1.5).asin().to_degrees()).abs() < 1e-9);
    // Brewster: Rp is 0 there.
    let rp = &c.series[0];
    let near = rp
        .points
        .iter()
        .min_by(|a, b| (a[0] - at("θB")).abs().total_cmp(&(b[0] - at("θB")).abs()))
        .unwrap();
    assert!(near[1] < 1e-4, "{near:?}");

    let lambert = h.state().state().brdfs[1].id;
    h.state_mut().push(Command::Select(lambert));
    h.run();
    let c = h
        .state()
        .view::<FresnelView>()
        .unwrap()
        .last
        .clone()
        .unwrap();
    // Lambert selected: it is listed as having no term, and Cook-Torrance,
    // still drawn, keeps its F alone.
    assert_eq!(
        c.series.len(),
        1,
        "{:?}",
        c.series.iter().map(|s| &s.label).collect::<Vec<_>>()
    );
    assert!(c.series[0].label.starts_with("F (dielectric)"));
    assert!(
        c.note.lines().next().unwrap().contains("no Fresnel term"),
        "{}",
        c.note
    );
}
