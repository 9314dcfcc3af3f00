//! Error positions: a file's text, its spans and the messages that point
//! into it (file, line, column, field path and the offending line).

use std::fmt::Write as _;
use std::ops::Range;
use std::path::Path;

use super::*;

pub(super) struct Source<'a> {
    pub(super) text: &'a str,
    pub(super) file: &'a str,
    /// The folder relative texture paths start from.
    pub(super) dir: &'a Path,
}

impl Source<'_> {
    /// An error at `span` (byte range into the text; start of file if none).
    pub(super) fn error(
        &self,
        span: Option<Range<usize>>,
        field: impl Into<String>,
        message: impl Into<String>,
    ) -> SceneError {
        let text = self.text;
        let span = span.unwrap_or(0..0);
        let mut start = span.start.min(text.len());
        while !text.is_char_boundary(start) {
            start -= 1;
        }
        let line_start = text[..start].rfind('\n').map_or(0, |i| i + 1);
        let line_end = text[start..].find('\n').map_or(text.len(), |i| start + i);
        let line = text[..start].matches('\n').count() + 1;
        let column = text[line_start..start].chars().count() + 1;
        let mut end = span.end.clamp(start, line_end);
        while !text.is_char_boundary(end) {
            end -= 1;
        }
        let source_line = text[line_start..line_end].trim_end_matches('\r');
        let snippet = if source_line.trim().is_empty() {
            String::new()
        } else {
            // Keep tabs in the padding so that the caret lines up.
            let pad: String = text[line_start..start].chars().map(|c| if c == '\t' { '\t' } else { ' ' }).collect();
            let width = text[start..end].trim_end_matches('\r').chars().count().max(1);
            let gutter = line.to_string().len();
            format!("\n{line:>gutter$} | {source_line}\n{:>gutter$} | {pad}{}", "", "^".repeat(width))
        };
        SceneError::Invalid {
            file: self.file.to_owned(),
            line,
            column,
            field: field.into(),
            message: message.into(),
            snippet,
        }
    }

    /// The line (from 1) of byte offset `pos`.
    pub(super) fn line_of(&self, pos: usize) -> usize {
        let mut pos = pos.min(self.text.len());
        while !self.text.is_char_boundary(pos) {
            pos -= 1;
        }
        self.text[..pos].matches('\n').count() + 1
    }

    pub(super) fn toml_error(&self, e: serde_path_to_error::Error<toml::de::Error>) -> SceneError {
        let mut field = String::new();
        for segment in e.path() {
            match segment {
                serde_path_to_error::Segment::Seq { index } => {
                    let _ = write!(field, "[{index}]");
                }
                serde_path_to_error::Segment::Map { key } | serde_path_to_error::Segment::Enum { variant: key } => {
                    // Skip the private keys of `toml::Spanned`.
                    if !key.starts_with("$__") {
                        if !field.is_empty() {
                            field.push('.');
                        }
                        field.push_str(key);
                    }
                }
                serde_path_to_error::Segment::Unknown => {}
            }
        }
        let inner = e.inner();
        let mut message = inner.message().trim().lines().map(str::trim).collect::<Vec<_>>().join(": ");
        if let Some(missing) = message.strip_prefix("missing field `").and_then(|m| m.strip_suffix('`')) {
            if !field.is_empty() {
                field.push('.');
            }
            field.push_str(missing);
            message = format!("the required key `{missing}` is missing");
        } else if field.is_empty() {
            message = format!("invalid TOML: {message}");
        } else if message == "invalid type: map, expected a sequence" {
            // The table header of the array: the path without its indices.
            let header: String = field.split('[').map(|p| p.split_once(']').map_or(p, |(_, rest)| rest)).collect();
            message.push_str(&format!(" (write [[{header}]] with double brackets for each entry)"));
        } else if let Some(better) = self.unknown_typed_key(&field, &message) {
            message = better;
        } else if message.starts_with("unknown field `background`") && field.contains('.') {
            message.push_str(
                " (top-level keys such as `background` must come before the first [table] header, \
                 or TOML puts them in that table)",
            );
        }
        self.error(inner.span(), field, message)
    }

    /// For an unknown key of a material or a light (`materials[2].roughnes`),
    /// the keys of that table's own type instead of every type's, and the
    /// nearest one ("did you mean `roughness`?").
    fn unknown_typed_key(&self, field: &str, message: &str) -> Option<String> {
        let key = message.strip_prefix("unknown field `")?.split('`').next()?;
        let (array, rest) = field.split_once('[')?;
        let (index, key_path) = rest.split_once(']')?;
        // Only a key of the material or light itself, not of a table in it.
        if key_path != format!(".{key}") {
            return None;
        }
        let index: usize = index.parse().ok()?;
        let (types, noun, default): (&[(&str, &[&str])], _, _) = match array {
            "materials" => (&super::schema::MATERIAL_KEYS, "material", "diffuse"),
            "lights" => (&super::schema::LIGHT_KEYS, "light", ""),
            _ => return None,
        };
        let doc: toml::Value = toml::from_str(self.text).ok()?;
        let table = doc.get(array)?.get(index)?;
        let kind = table.get("type").and_then(|t| t.as_str()).unwrap_or(default);
        let (_, accepted) = types.iter().find(|(t, _)| *t == kind)?;
        let nearest = accepted.iter().min_by_key(|k| edit_distance(k, key)).filter(|k| edit_distance(k, key) <= 2);
        let hint = nearest.map_or(String::new(), |k| format!("did you mean `{k}`? "));
        Some(format!("unknown key `{key}`; {hint}a {kind} {noun} accepts {}", accepted.join(", ")))
    }
}

// ---------------------------------------------------------------------------
// Self-checking leaf types
// ---------------------------------------------------------------------------

/// A number type that checks its value while being deserialized, so that a
/// bad value is reported at its own token.
pub(super) trait Number: Copy {
    /// Accepts `v` (already known to be finite) or says why not.
    fn check(v: f64) -> Result<(), String>;
    fn new(v: f64) -> Self;
    fn get(self) -> f64;

    fn parse(v: f64) -> Result<Self, String> {
        if !v.is_finite() {
            return Err(format!("must be a finite number (got {v})"));
        }
        Self::check(v).map(|()| Self::new(v))
    }
}

/// Levenshtein distance between two short words.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let cur = row[j + 1];
            row[j + 1] = (prev + usize::from(ca != *cb)).min(row[j] + 1).min(cur + 1);
            prev = cur;
        }
    }
    row[b.len()]
}
