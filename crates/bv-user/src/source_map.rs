//! The generated source a compiler sees is the user's section wrapped in a
//! prelude (parameter declarations, a version line) and a postlude. A
//! [`SourceMap`] turns a compiler's byte offset in that text back into the
//! user's file line and column.

use crate::error::Place;

/// How generated text maps onto the user's file.
#[derive(Debug, Clone)]
pub struct SourceMap {
    /// The file name errors carry.
    pub file: String,
    /// Lines of generated text before the user's first section line.
    pub prelude_lines: usize,
    /// Lines of the user's section.
    pub user_lines: usize,
    /// 1-based file line of the section's first text line.
    pub first_line: usize,
}

impl SourceMap {
    /// The user's place of 1-based generated `line` and `column`. A place in
    /// the generated prelude or postlude is reported at the section's first
    /// line (what the user wrote made the generated code fail).
    pub fn place(&self, line: usize, column: usize) -> Place {
        let user = line.checked_sub(self.prelude_lines + 1);
        match user {
            Some(k) if k < self.user_lines => Place {
                file: self.file.clone(),
                line: self.first_line + k,
                column: column.max(1),
            },
            _ => Place {
                file: self.file.clone(),
                line: self.first_line.saturating_sub(1).max(1),
                column: 1,
            },
        }
    }

    /// The user's place of a byte span's start in `generated`.
    pub fn place_of_span(&self, span: naga::Span, generated: &str) -> Option<Place> {
        if !span.is_defined() {
            return None;
        }
        let loc = span.location(generated);
        Some(self.place(loc.line_number as usize, loc.line_position as usize))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn generated_lines_map_to_the_users_lines() {
        let m = SourceMap {
            file: "f.brdf".into(),
            prelude_lines: 3,
            user_lines: 10,
            first_line: 20,
        };
        // Generated line 4 is the section's first line (file line 20).
        assert_eq!(m.place(4, 7).line, 20);
        assert_eq!(m.place(4, 7).column, 7);
        assert_eq!(m.place(13, 1).line, 29);
        // Prelude and postlude fall on the `::begin` line.
        assert_eq!(m.place(2, 5).line, 19);
        assert_eq!(m.place(14, 5).line, 19);
        assert_eq!(m.place(14, 5).to_string(), "f.brdf:19:1");
    }
}
