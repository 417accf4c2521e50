//! File dialogs for the viewer: open and save dialogs (the `egui_file` crate,
//! drawn inside the window, so they work the same on every platform and under
//! Xvfb) with extension filters, one dialog at a time, remembering the last
//! folder.
//!
//! Usage: keep a [`Files<T>`] in the UI state, call [`Files::open`] or
//! [`Files::save`] with a tag saying what the file is for, and call
//! [`Files::show`] every frame; it returns `(tag, path)` once the user has
//! chosen. A saved file gets the filter's first extension when the name typed
//! has none of them, and saving over an existing file asks first ("X exists.
//! Replace?"); answering no goes back to the dialog with the name kept.

use eframe::egui;
use egui_file::FileDialog;
use std::ffi::OsStr;
use std::path::{Path, PathBuf};

/// One kind of file a dialog offers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Filter {
    /// What the files are ("bv scene", "PNG image").
    pub name: &'static str,
    /// Accepted extensions without the dot, lowercase; the first is added to
    /// saved names that lack one.
    pub extensions: &'static [&'static str],
}

/// Scene files.
pub const SCENE: Filter = Filter {
    name: "bv scene (.toml)",
    extensions: &["toml"],
};
/// PNG images.
pub const PNG: Filter = Filter {
    name: "PNG image (.png)",
    extensions: &["png"],
};
/// SVG drawings.
pub const SVG: Filter = Filter {
    name: "SVG drawing (.svg)",
    extensions: &["svg"],
};
/// Meshes.
pub const MESH: Filter = Filter {
    name: "mesh (.obj, .ply)",
    extensions: &["obj", "ply"],
};

impl Filter {
    /// Whether `path` has one of the extensions (case-insensitive).
    pub fn accepts(&self, path: &Path) -> bool {
        path.extension()
            .and_then(OsStr::to_str)
            .is_some_and(|e| self.extensions.iter().any(|x| x.eq_ignore_ascii_case(e)))
    }

    /// `path` with the first extension added when it has none of them.
    pub fn with_extension(&self, path: &Path) -> PathBuf {
        if self.accepts(path) || self.extensions.is_empty() {
            return path.to_path_buf();
        }
        let mut s = path.as_os_str().to_owned();
        s.push(".");
        s.push(self.extensions[0]);
        PathBuf::from(s)
    }
}

/// A dialog in progress.
struct Pending<T> {
    tag: T,
    filter: Filter,
    dialog: FileDialog,
    /// A save over this existing file waits for the user's yes.
    confirm: Option<PathBuf>,
    /// Frames the question has been drawn (a new window is laid out
    /// unseen in its first frame, so a few frames are asked for).
    confirm_frames: u32,
}

/// The answer to "X exists. Replace?".
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Answer {
    Replace,
    Back,
}

/// The title of the confirmation window (for tests and screen readers).
pub const REPLACE_TITLE: &str = "Replace the file?";

/// The question asked before saving over `path`.
pub fn replace_question(path: &Path) -> String {
    let name = path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    format!("{name} exists. Replace?")
}

/// Asks whether to replace `path`; `None` while unanswered. Escape means no.
fn confirm_window(ctx: &egui::Context, path: &Path) -> Option<Answer> {
    let mut answer = None;
    egui::Window::new(REPLACE_TITLE)
        .collapsible(false)
        .resizable(false)
        .anchor(egui::Align2::CENTER_CENTER, egui::Vec2::ZERO)
        .order(egui::Order::Foreground)
        .show(ctx, |ui| {
            ui.label(egui::RichText::new(replace_question(path)).strong());
            if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
                ui.weak(format!("in {}", dir.display()));
            }
            ui.add_space(6.0);
            ui.horizontal(|ui| {
                if ui.button("Replace").clicked() {
                    answer = Some(Answer::Replace);
                }
                if ui.button("Cancel").clicked() {
                    answer = Some(Answer::Back);
                }
            });
        });
    if ctx.input(|i| i.key_pressed(egui::Key::Escape)) {
        answer = Some(Answer::Back);
    }
    answer
}

/// At most one open or save dialog at a time.
pub struct Files<T> {
    pending: Option<Pending<T>>,
    last_dir: Option<PathBuf>,
    /// A browser page's save, chosen at once (see [`Files::save`]).
    ready: Option<(T, PathBuf)>,
}

impl<T> Default for Files<T> {
    fn default() -> Self {
        Self {
            pending: None,
            last_dir: None,
            ready: None,
        }
    }
}

fn filter_box(filter: Filter) -> egui_file::Filter<PathBuf> {
    Box::new(move |p: &Path| filter.accepts(p))
}

impl<T> Files<T> {
    /// Whether a dialog is showing.
    pub fn is_open(&self) -> bool {
        self.pending.is_some()
    }

    /// Makes the next dialog start in `dir` (as if the last file had been
    /// chosen there).
    pub fn set_start_dir(&mut self, dir: impl Into<PathBuf>) {
        self.last_dir = Some(dir.into());
    }

    /// The folder dialogs start in.
    pub fn start_dir(&self) -> PathBuf {
        self.last_dir
            .clone()
            .or_else(|| std::env::current_dir().ok())
            .unwrap_or_else(|| PathBuf::from("."))
    }

    /// Shows an open dialog for `filter`'s files. In a browser page, opens
    /// the browser's file chooser instead: the page has no folders to show,
    /// and the files chosen arrive as bytes
    /// ([`crate::session::platform::take_picked`]), like dropped ones.
    pub fn open(&mut self, tag: T, title: &str, filter: Filter) {
        if crate::session::platform::WEB {
            let _ = (tag, title);
            crate::session::platform::pick_files(filter.extensions);
            return;
        }
        let mut d = FileDialog::open_file()
            .title(title)
            .initial_path(self.start_dir())
            .show_files_filter(filter_box(filter))
            .show_rename(false)
            .show_new_folder(false);
        d.open();
        self.pending = Some(Pending {
            tag,
            filter,
            dialog: d,
            confirm: None,
            confirm_frames: 0,
        });
    }

    /// Shows a save dialog proposing `default_name`. In a browser page the
    /// name is taken at once (the file becomes a download, which the browser
    /// names or asks about itself).
    pub fn save(&mut self, tag: T, title: &str, filter: Filter, default_name: &str) {
        if crate::session::platform::WEB {
            let _ = title;
            self.ready = Some((tag, filter.with_extension(Path::new(default_name))));
            return;
        }
        let mut d = FileDialog::save_file()
            .title(title)
            .initial_path(self.start_dir())
            .default_filename(default_name)
            .show_files_filter(filter_box(filter));
        d.open();
        self.pending = Some(Pending {
            tag,
            filter,
            dialog: d,
            confirm: None,
            confirm_frames: 0,
        });
    }

    /// The existing file a save waits to replace, while the question shows.
    pub fn confirming(&self) -> Option<&Path> {
        self.pending.as_ref()?.confirm.as_deref()
    }

    /// Draws the dialog; returns the tag and the chosen path once chosen
    /// (saved names get the filter's extension; an existing file only once
    /// the user said to replace it). Cancelling drops the dialog.
    pub fn show(&mut self, ctx: &egui::Context) -> Option<(T, PathBuf)> {
        if let Some(r) = self.ready.take() {
            return Some(r);
        }
        let p = self.pending.as_mut()?;
        if let Some(path) = p.confirm.clone() {
            if p.confirm_frames < 3 {
                p.confirm_frames += 1;
                ctx.request_repaint();
            }
            return match confirm_window(ctx, &path)? {
                Answer::Replace => self.finish(path),
                Answer::Back => {
                    // Back to the dialog, the typed name kept.
                    p.confirm = None;
                    p.dialog.open();
                    None
                }
            };
        }
        p.dialog.show(ctx);
        match p.dialog.state() {
            egui_file::State::Open => None,
            egui_file::State::Selected => {
                let path = p.dialog.path()?.to_path_buf();
                if p.dialog.dialog_type() == egui_file::DialogType::SaveFile {
                    let path = p.filter.with_extension(&path);
                    if path.exists() {
                        p.confirm = Some(path);
                        p.confirm_frames = 0;
                        ctx.request_repaint();
                        return None;
                    }
                    return self.finish(path);
                }
                self.finish(path)
            }
            _ => {
                self.pending = None;
                None
            }
        }
    }
}

impl<T> Files<T> {
    /// Ends the dialog with `path` chosen.
    fn finish(&mut self, path: PathBuf) -> Option<(T, PathBuf)> {
        let p = self.pending.take()?;
        self.last_dir = path.parent().map(Path::to_path_buf);
        Some((p.tag, path))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extensions_are_added_once() {
        assert_eq!(
            SCENE.with_extension(Path::new("a/b")),
            Path::new("a/b.toml")
        );
        assert_eq!(
            SCENE.with_extension(Path::new("b.TOML")),
            Path::new("b.TOML")
        );
        assert_eq!(MESH.with_extension(Path::new("m.ply")), Path::new("m.ply"));
        assert_eq!(MESH.with_extension(Path::new("m")), Path::new("m.obj"));
        assert!(!PNG.accepts(Path::new("x.svg")));
    }

    #[test]
    fn the_question_names_the_file() {
        assert_eq!(
            replace_question(Path::new("/tmp/talk/scene.toml")),
            "scene.toml exists. Replace?"
        );
    }
}
