//! The keyboard shortcuts: one declaration per shortcut ([`SHORTCUTS`]),
//! read both by the handler ([`pressed`]) and by the help overlay
//! ([`Shortcut::keys_text`]), so that what the help lists is what the keys do.
//!
//! No shortcut fires while a widget has the keyboard (a text field being
//! typed into, a focused value): digits typed into a parameter field are the
//! field's, not "maximise view 3".

use eframe::egui::{self, Key, KeyboardShortcut, Modifiers};

/// What a shortcut does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Action {
    /// Show or hide the help overlay.
    ToggleHelp,
    /// Reset the lobe camera.
    ResetCamera,
    /// Toggle the logarithmic scale.
    ToggleLog,
    /// Toggle the × cos θo factor.
    ToggleCosine,
    /// Toggle the lobe wireframe.
    ToggleWireframe,
    /// Next model for the selected BRDF.
    NextModel,
    /// Previous model for the selected BRDF.
    PreviousModel,
    /// Select the next BRDF.
    NextBrdf,
    /// Select the previous BRDF.
    PreviousBrdf,
    /// Maximise the view under the pointer (or restore).
    MaximiseHovered,
    /// Maximise view number `k` (0-based, registry order) or restore.
    MaximiseView(usize),
    /// Close the help, or restore the layout.
    Escape,
    /// Switch between the dark and light themes.
    ToggleTheme,
    /// Open a scene file.
    OpenScene,
    /// Save the scene to the file it came from.
    SaveScene,
    /// Open the figure export dialog.
    ExportFigure,
    /// Open or close the *Fit…* panel.
    ToggleFit,
    /// Quit.
    Quit,
    /// Enter or leave presentation mode.
    TogglePresentation,
    /// Presenting: the next scene of the deck (or the next view).
    NextSlide,
    /// Presenting: the previous scene of the deck (or the previous view).
    PreviousSlide,
    /// Presenting: the first scene of the deck (or the first view).
    FirstSlide,
    /// Presenting: the last scene of the deck (or the last view).
    LastSlide,
    /// Zoom the whole window in, out or back to 1:1: egui itself handles
    /// these keys before the viewer sees them; they are declared here so
    /// that the help lists them.
    Zoom,
}

/// One shortcut: its keys (any of them), what it does, and its help text.
#[derive(Debug, Clone, Copy)]
pub struct Shortcut {
    /// The key combinations; for [`Action::MaximiseView`] the `k`-th one
    /// maximises view `k`.
    pub keys: &'static [KeyboardShortcut],
    /// What it does.
    pub action: Action,
    /// The help overlay's description.
    pub help: &'static str,
}

const fn plain(key: Key) -> KeyboardShortcut {
    KeyboardShortcut::new(Modifiers::NONE, key)
}

/// The keys 1 … 9: view `k` of the layout (registry order) for key `k + 1`.
pub const VIEW_KEYS: [KeyboardShortcut; 9] = [
    plain(Key::Num1),
    plain(Key::Num2),
    plain(Key::Num3),
    plain(Key::Num4),
    plain(Key::Num5),
    plain(Key::Num6),
    plain(Key::Num7),
    plain(Key::Num8),
    plain(Key::Num9),
];

const COMMAND_SHIFT: Modifiers = Modifiers {
    shift: true,
    ..Modifiers::COMMAND
};

/// Every shortcut, in the order the help lists them. Matching is egui's
/// (extra Shift or Alt is ignored), so Ctrl+Shift+S comes before Ctrl+S, and
/// a key with modifiers before the same key without.
pub const SHORTCUTS: &[Shortcut] = &[
    Shortcut {
        keys: &[plain(Key::F1), plain(Key::Questionmark)],
        action: Action::ToggleHelp,
        help: "show or hide this help",
    },
    Shortcut {
        keys: &[KeyboardShortcut::new(Modifiers::COMMAND, Key::O)],
        action: Action::OpenScene,
        help: "open a scene file",
    },
    Shortcut {
        keys: &[KeyboardShortcut::new(COMMAND_SHIFT, Key::S)],
        action: Action::ExportFigure,
        help: "export a figure: a view or the window as PNG / SVG / OBJ",
    },
    Shortcut {
        keys: &[KeyboardShortcut::new(Modifiers::COMMAND, Key::S)],
        action: Action::SaveScene,
        help: "save the scene (to the file it came from)",
    },
    Shortcut {
        keys: &[KeyboardShortcut::new(Modifiers::COMMAND, Key::Q)],
        action: Action::Quit,
        help: "quit (the session is saved)",
    },
    Shortcut {
        keys: &[plain(Key::R)],
        action: Action::ResetCamera,
        help: "reset the camera",
    },
    Shortcut {
        keys: &[plain(Key::L)],
        action: Action::ToggleLog,
        help: "logarithmic scale",
    },
    Shortcut {
        keys: &[plain(Key::C)],
        action: Action::ToggleCosine,
        help: "multiply by cos θo",
    },
    Shortcut {
        keys: &[plain(Key::W)],
        action: Action::ToggleWireframe,
        help: "wireframe lobe",
    },
    Shortcut {
        keys: &[plain(Key::N)],
        action: Action::NextModel,
        help: "next model for the selected BRDF",
    },
    Shortcut {
        keys: &[plain(Key::P)],
        action: Action::PreviousModel,
        help: "previous model for the selected BRDF",
    },
    Shortcut {
        keys: &[plain(Key::PageDown)],
        action: Action::NextBrdf,
        help: "select the next BRDF (presenting: the next scene or view)",
    },
    Shortcut {
        keys: &[plain(Key::PageUp)],
        action: Action::PreviousBrdf,
        help: "select the previous BRDF (presenting: the previous scene or view)",
    },
    Shortcut {
        keys: &[plain(Key::M)],
        action: Action::MaximiseHovered,
        help: "maximise the view under the pointer (again to restore)",
    },
    Shortcut {
        keys: &VIEW_KEYS,
        action: Action::MaximiseView(0),
        help: "maximise view 1 … 9 (again to restore)",
    },
    Shortcut {
        keys: &[plain(Key::Escape)],
        action: Action::Escape,
        help: "close this help, or restore the layout",
    },
    Shortcut {
        keys: &[plain(Key::F)],
        action: Action::ToggleFit,
        help: "open or close the Fit… panel (fit a model to a BRDF)",
    },
    Shortcut {
        keys: &[plain(Key::T)],
        action: Action::ToggleTheme,
        help: "switch between dark and light themes",
    },
    Shortcut {
        keys: &[plain(Key::F5)],
        action: Action::TogglePresentation,
        help: "presentation mode: one view, large text, the deck's titles",
    },
    Shortcut {
        keys: &[plain(Key::ArrowRight)],
        action: Action::NextSlide,
        help: "presenting: the next scene of the deck (or the next view)",
    },
    Shortcut {
        keys: &[plain(Key::ArrowLeft)],
        action: Action::PreviousSlide,
        help: "presenting: the previous scene of the deck (or view)",
    },
    Shortcut {
        keys: &[plain(Key::Home)],
        action: Action::FirstSlide,
        help: "presenting: the first scene of the deck",
    },
    Shortcut {
        keys: &[plain(Key::End)],
        action: Action::LastSlide,
        help: "presenting: the last scene of the deck",
    },
    Shortcut {
        keys: &[
            egui::gui_zoom::kb_shortcuts::ZOOM_IN,
            egui::gui_zoom::kb_shortcuts::ZOOM_OUT,
            egui::gui_zoom::kb_shortcuts::ZOOM_RESET,
        ],
        action: Action::Zoom,
        help: "zoom the whole window in / out / back to 1:1",
    },
];

impl Shortcut {
    /// The keys as the help shows them ("F1 or ?", "1 … 9", "Ctrl+S"),
    /// in the platform's notation.
    pub fn keys_text(&self, ctx: &egui::Context) -> String {
        let names: Vec<String> = self.keys.iter().map(|k| key_text(ctx, k)).collect();
        match self.action {
            Action::MaximiseView(_) if names.len() > 2 => {
                format!("{} … {}", names[0], names[names.len() - 1])
            }
            Action::Zoom => names.join(" / "),
            _ => names.join(" or "),
        }
    }
}

/// One key combination as the help shows it: egui's modifier names
/// ("Ctrl+", "Cmd+") and the key's symbol ("?", "1") where it has one
/// that the default fonts can draw.
fn key_text(ctx: &egui::Context, k: &KeyboardShortcut) -> String {
    let names = egui::ModifierNames::NAMES;
    let mut s = names.format(&k.modifiers, ctx.os().is_mac());
    if !s.is_empty() {
        s += names.concat;
    }
    // egui's arrow symbols (⏴ ⏵) are in none of its default fonts: the
    // arrows go by name.
    let key = k.logical_key;
    let text = match key {
        Key::ArrowLeft | Key::ArrowRight | Key::ArrowUp | Key::ArrowDown => key.name(),
        _ => key.symbol_or_name(),
    };
    s + text
}

/// Whether no widget has the keyboard: shortcuts are for the window only
/// then. A focused text field or value owns every key, including Escape
/// (which reverts it) and Ctrl+S.
pub fn keyboard_free(ctx: &egui::Context) -> bool {
    !ctx.memory(|m| m.focused().is_some())
}

/// The actions whose keys were pressed this frame, consumed from the input,
/// in the order of [`SHORTCUTS`]; nothing when `free` is false (a widget had
/// the keyboard at some point of the frame).
pub fn pressed(ctx: &egui::Context, free: bool) -> Vec<Action> {
    if !free || !keyboard_free(ctx) {
        return Vec::new();
    }
    ctx.input_mut(|i| {
        let mut out = Vec::new();
        for s in SHORTCUTS {
            for (k, key) in s.keys.iter().enumerate() {
                if i.consume_shortcut(key) {
                    out.push(match s.action {
                        Action::MaximiseView(_) => Action::MaximiseView(k),
                        a => a,
                    });
                }
            }
        }
        // "?" comes as text on layouts where it is no key of its own.
        if !out.contains(&Action::ToggleHelp)
            && i.events
                .iter()
                .any(|e| matches!(e, egui::Event::Text(t) if t == "?"))
        {
            out.push(Action::ToggleHelp);
        }
        out
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_key_belongs_to_one_shortcut() {
        let mut seen = Vec::new();
        for s in SHORTCUTS {
            for k in s.keys {
                assert!(!seen.contains(k), "{k:?} declared twice");
                seen.push(*k);
            }
        }
        assert_eq!(
            SHORTCUTS
                .iter()
                .filter(|s| matches!(s.action, Action::MaximiseView(_)))
                .count(),
            1
        );
    }

    #[test]
    fn more_specific_keys_come_first() {
        // egui ignores extra Shift when matching: Ctrl+Shift+S must be tried
        // before Ctrl+S, or it would save instead of exporting.
        let pos = |a: Action| SHORTCUTS.iter().position(|s| s.action == a).unwrap();
        assert!(pos(Action::ExportFigure) < pos(Action::SaveScene));
    }

    #[test]
    fn help_texts_name_the_keys() {
        let ctx = egui::Context::default();
        let text = |a: Action| {
            SHORTCUTS
                .iter()
                .find(|s| s.action == a)
                .unwrap()
                .keys_text(&ctx)
        };
        assert_eq!(text(Action::MaximiseView(0)), "1 … 9");
        assert_eq!(text(Action::ToggleHelp), "F1 or ?");
        assert_eq!(text(Action::ResetCamera), "R");
        assert_eq!(text(Action::TogglePresentation), "F5");
        assert_eq!(text(Action::NextSlide), "Right");
        if !ctx.os().is_mac() {
            assert_eq!(text(Action::ExportFigure), "Ctrl+Shift+S");
            assert_eq!(text(Action::SaveScene), "Ctrl+S");
        }
    }
}
