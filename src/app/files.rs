//! File dialogs for the viewer: open and save dialogs (the `egui_file` crate,
//! drawn inside the window, so they work the same on every platform and under
//! Xvfb) with extension filters, one dialog at a time, remembering the last
//! folder.
//!
//! Usage: keep a [`Files<T>`] in the UI state, call [`Files::open`] or
//! [`Files::save`] with a tag saying what the file is for, and call
//! [`Files::show`] every frame; it returns `(tag, path)` once the user has
//! chosen. A saved file gets the filter's first extension when the name typed
//! has none of them.

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
}

/// At most one open or save dialog at a time.
pub struct Files<T> {
    pending: Option<Pending<T>>,
    last_dir: Option<PathBuf>,
}

impl<T> Default for Files<T> {
    fn default() -> Self {
        Self {
            pending: None,
            last_dir: None,
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

    /// The folder dialogs start in.
    pub fn start_dir(&self) -> PathBuf {
        self.last_dir
            .clone()
            .or_else(|| std::env::current_dir().ok())
            .unwrap_or_else(|| PathBuf::from("."))
    }

    /// Shows an open dialog for `filter`'s files.
    pub fn open(&mut self, tag: T, title: &str, filter: Filter) {
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
        });
    }

    /// Shows a save dialog proposing `default_name`.
    pub fn save(&mut self, tag: T, title: &str, filter: Filter, default_name: &str) {
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
        });
    }

    /// Draws the dialog; returns the tag and the chosen path once chosen
    /// (saved names get the filter's extension). Cancelling drops the dialog.
    pub fn show(&mut self, ctx: &egui::Context) -> Option<(T, PathBuf)> {
        let p = self.pending.as_mut()?;
        p.dialog.show(ctx);
        match p.dialog.state() {
            egui_file::State::Open => None,
            egui_file::State::Selected => {
                let p = self.pending.take()?;
                let path = p.dialog.path()?.to_path_buf();
                let path = if p.dialog.dialog_type() == egui_file::DialogType::SaveFile {
                    p.filter.with_extension(&path)
                } else {
                    path
                };
                self.last_dir = path.parent().map(Path::to_path_buf);
                Some((p.tag, path))
            }
            _ => {
                self.pending = None;
                None
            }
        }
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
}
