//! From bytes to a [`Case`], reporting every shape error at once.
//!
//! 1. The file size is checked before reading, and the bytes must be UTF-8 (an invalid byte is
//!    reported with its position).
//! 2. The text is parsed to a `serde_json::Value`: a syntax error stops here (nothing after it
//!    can be trusted), reported with its line, column and the member being read — so a truncated
//!    file says which member it ends in.
//! 3. Keys repeated within one object are found on the text (the `Value` keeps only the last).
//! 4. Each top-level field, and each element of the top-level lists, is deserialized on its
//!    own, with unknown fields collected rather than fatal: one bad body does not hide the next.

use serde::de::DeserializeOwned;
use serde_json::Value;

use crate::case::{Case, NamedMap};
use crate::error::ModelError;
use crate::limits::{Limit, Limits, format_count};
use crate::locate;

/// Most characters of a user-supplied text quoted in a message.
const MAX_QUOTED: usize = 120;

/// `text`, cut to [`MAX_QUOTED`] characters with the number of characters left out.
pub(crate) fn clip(text: &str) -> String {
    match text.char_indices().nth(MAX_QUOTED) {
        None => text.to_string(),
        Some((cut, _)) => format!(
            "{}… ({} more characters)",
            &text[..cut],
            text[cut..].chars().count()
        ),
    }
}

pub(crate) fn too_large(
    path: &str,
    what: &str,
    found: f64,
    limit: Limit,
    value: u64,
) -> ModelError {
    ModelError::invalid(
        path,
        format!(
            "{} {what}; the limit is {} ({})",
            format_count(found),
            format_count(value as f64),
            limit.hint()
        ),
    )
}

/// Reads a case file's text, refusing a file over the size limit before reading it and naming
/// the position of the first byte that is not UTF-8.
pub(crate) fn read_text(path: &std::path::Path, limits: &Limits) -> Result<String, ModelError> {
    use std::io::Read;
    let io = |e: std::io::Error| ModelError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    };
    let file = std::fs::File::open(path).map_err(io)?;
    let size = file.metadata().map_err(io)?.len();
    let oversize = |n: u64| {
        too_large(
            ".",
            "bytes in the file",
            n as f64,
            Limit::FileBytes,
            limits.file_bytes,
        )
    };
    if size > limits.file_bytes {
        return Err(oversize(size));
    }
    // A file that grows while read (or a device) is cut one byte past the limit.
    let mut bytes = Vec::new();
    file.take(limits.file_bytes.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > limits.file_bytes {
        return Err(oversize(bytes.len() as u64));
    }
    String::from_utf8(bytes).map_err(|e| {
        let valid = e.utf8_error().valid_up_to();
        let prefix = std::str::from_utf8(&e.as_bytes()[..valid]).unwrap_or("");
        let at = locate::position(prefix, valid);
        ModelError::Syntax {
            path: locate::path_at(prefix, valid),
            line: at.line,
            column: at.column,
            message: format!(
                "byte {valid} (0x{:02x}) is not valid UTF-8; a case file is UTF-8 text",
                e.as_bytes()[valid]
            ),
        }
    })
}

/// Parses the text of a case file into a [`Case`], collecting every shape error.
///
/// Unknown fields and repeated keys do not stop the parse: the case is still returned (without
/// them) so that validation can report its own errors in the same pass. Any other error leaves
/// no case.
pub(crate) fn parse(text: &str, limits: &Limits) -> (Option<Case>, Vec<ModelError>) {
    match parse_value(text, limits) {
        Ok(result) => result,
        Err(error) => (None, vec![error]),
    }
}

fn parse_value(text: &str, limits: &Limits) -> Result<(Option<Case>, Vec<ModelError>), ModelError> {
    if text.len() as u64 > limits.file_bytes {
        return Err(too_large(
            ".",
            "bytes in the file",
            text.len() as f64,
            Limit::FileBytes,
            limits.file_bytes,
        ));
    }
    let value: Value = serde_json::from_str(text).map_err(|e| syntax_error(text, &e))?;
    let Value::Object(members) = value else {
        return Err(ModelError::Syntax {
            path: ".".into(),
            line: 1,
            column: 1,
            message: format!(
                "a case file is one JSON object `{{ \"name\": …, \"bodies\": … }}`, found {}",
                kind(&value)
            ),
        });
    };
    let mut reader = Reader {
        errors: Vec::new(),
        fatal: false,
        limits,
    };
    for (path, at) in locate::duplicate_keys(text) {
        let key = path.rsplit('.').next().unwrap_or(&path).to_string();
        reader.errors.push(ModelError::Syntax {
            path,
            line: at.line,
            column: at.column,
            message: format!("duplicate key `{}`", clip(&key)),
        });
    }
    let case = reader.case(&members);
    let mut errors = reader.errors;
    locate_syntax(text, &mut errors);
    Ok((case.filter(|_| !reader.fatal), errors))
}

/// Fills in the line and column of shape errors found on the `Value`.
fn locate_syntax(text: &str, errors: &mut [ModelError]) {
    let paths: Vec<String> = errors
        .iter()
        .filter(|e| matches!(e, ModelError::Syntax { line: 0, .. }))
        .map(|e| e.path().to_string())
        .collect();
    let refs: Vec<&str> = paths.iter().map(String::as_str).collect();
    let found = locate::positions(text, &refs);
    for e in errors {
        if let ModelError::Syntax {
            path, line, column, ..
        } = e
            && *line == 0
            && let Some(p) = found.get(path.as_str())
        {
            *line = p.line;
            *column = p.column;
        }
    }
}

fn kind(value: &Value) -> &'static str {
    match value {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "an array",
        Value::Object(_) => "an object",
    }
}

/// A JSON syntax error, with the member it occurred in.
fn syntax_error(text: &str, error: &serde_json::Error) -> ModelError {
    let message = error.to_string();
    let message = match message.rfind(" at line ") {
        Some(i) => message[..i].to_string(),
        None => message,
    };
    let at = locate::offset(text, error.line(), error.column());
    let message = if error.is_eof() {
        format!("the file ends inside this value ({message}): is it truncated?")
    } else {
        clip(&message)
    };
    ModelError::Syntax {
        path: locate::path_at(text, at),
        line: error.line(),
        column: error.column(),
        message,
    }
}

/// `prefix` followed by a path relative to it.
fn join(prefix: &str, relative: &str) -> String {
    match (prefix, relative) {
        (".", r) => r.to_string(),
        (p, ".") => p.to_string(),
        (p, r) if r.starts_with('[') => format!("{p}{r}"),
        (p, r) => format!("{p}.{r}"),
    }
}

/// The path of a field serde_ignored skipped, in this crate's notation.
fn ignored_path(path: &serde_ignored::Path) -> String {
    use serde_ignored::Path;
    match path {
        Path::Root => ".".to_string(),
        Path::Seq { parent, index } => join(&ignored_path(parent), &format!("[{index}]")),
        Path::Map { parent, key } => join(&ignored_path(parent), key),
        Path::Some { parent }
        | Path::NewtypeStruct { parent }
        | Path::NewtypeVariant { parent } => ignored_path(parent),
    }
}

struct Reader<'a> {
    errors: Vec<ModelError>,
    /// An error other than an unknown field: the case cannot be built.
    fatal: bool,
    limits: &'a Limits,
}

impl Reader<'_> {
    /// Records an error that leaves no case to validate.
    fn fatal(&mut self, error: ModelError) {
        self.fatal = true;
        self.errors.push(error);
    }

    fn syntax(&mut self, path: String, message: String) {
        self.fatal = true;
        self.push_syntax(path, message);
    }

    fn push_syntax(&mut self, path: String, message: String) {
        self.errors.push(ModelError::Syntax {
            path,
            line: 0,
            column: 0,
            message,
        });
    }

    /// Deserializes one part, reporting its unknown fields and its first shape error.
    fn part<T: DeserializeOwned>(&mut self, value: &Value, path: &str) -> Option<T> {
        let mut unknown = Vec::new();
        let mut record = |p: serde_ignored::Path| unknown.push(ignored_path(&p));
        let result: Result<T, _> =
            serde_path_to_error::deserialize(serde_ignored::Deserializer::new(value, &mut record));
        for u in unknown {
            let field = u.rsplit(['.', '[']).next().unwrap_or(&u).to_string();
            self.push_syntax(join(path, &u), format!("unknown field `{}`", clip(&field)));
        }
        match result {
            Ok(v) => Some(v),
            Err(e) => {
                let at = join(path, &e.path().to_string());
                let message = e.into_inner().to_string();
                let message = match message.rfind(" at line ") {
                    Some(i) => message[..i].to_string(),
                    None => message,
                };
                self.syntax(at, clip(&message));
                None
            }
        }
    }

    /// A list whose elements are deserialized one by one.
    fn list<T: DeserializeOwned>(&mut self, value: &Value, path: &str) -> Option<Vec<T>> {
        let Value::Array(items) = value else {
            self.syntax(
                path.to_string(),
                format!("invalid type: {}, expected an array", kind(value)),
            );
            return None;
        };
        if items.len() as u64 > self.limits.list_items {
            self.fatal(too_large(
                path,
                "entries",
                items.len() as f64,
                Limit::ListItems,
                self.limits.list_items,
            ));
            return None;
        }
        let mut out = Vec::with_capacity(items.len());
        let mut ok = true;
        for (i, item) in items.iter().enumerate() {
            match self.part(item, &format!("{path}[{i}]")) {
                Some(v) => out.push(v),
                None => ok = false,
            }
        }
        ok.then_some(out)
    }

    fn case(&mut self, members: &serde_json::Map<String, Value>) -> Option<Case> {
        const FIELDS: [&str; 12] = [
            "name",
            "description",
            "gravity",
            "parameters",
            "coordinates",
            "bodies",
            "payloads",
            "joints",
            "actuators",
            "balancing",
            "tasks",
            "paths",
        ];
        for key in members.keys() {
            if !FIELDS.contains(&key.as_str()) {
                self.push_syntax(
                    key.clone(),
                    format!(
                        "unknown field `{}`, expected one of {}",
                        clip(key),
                        FIELDS.map(|f| format!("`{f}`")).join(", ")
                    ),
                );
            }
        }
        let required = |reader: &mut Self, name: &str| -> Option<&Value> {
            let value = members.get(name);
            if value.is_none() {
                reader.syntax(name.to_string(), format!("missing field `{name}`"));
            }
            value
        };
        let name = required(self, "name").and_then(|v| self.part::<String>(v, "name"));
        let gravity = required(self, "gravity").and_then(|v| self.part(v, "gravity"));
        let coordinates = required(self, "coordinates").and_then(|v| self.list(v, "coordinates"));
        let bodies = required(self, "bodies").and_then(|v| self.list(v, "bodies"));
        let actuators = required(self, "actuators").and_then(|v| self.list(v, "actuators"));
        let description = self.optional(members, "description");
        let parameters = match members.get("parameters") {
            None => Some(NamedMap::default()),
            Some(v) => self.parameters(v),
        };
        let payloads = self.optional_list(members, "payloads");
        let joints = self.optional_list(members, "joints");
        let paths = self.optional_list(members, "paths");
        let balancing = self.optional(members, "balancing");
        let tasks = self.optional(members, "tasks");
        Some(Case {
            name: name?,
            description: description?,
            gravity: gravity?,
            parameters: parameters?,
            coordinates: coordinates?,
            bodies: bodies?,
            payloads: payloads?,
            joints: joints?,
            actuators: actuators?,
            balancing: balancing?,
            tasks: tasks?,
            paths: paths?,
        })
    }

    /// An optional section (`null` or absent is `None`).
    fn optional<T: DeserializeOwned>(
        &mut self,
        members: &serde_json::Map<String, Value>,
        name: &str,
    ) -> Option<Option<T>> {
        match members.get(name) {
            None | Some(Value::Null) => Some(None),
            Some(v) => self.part(v, name).map(Some),
        }
    }

    /// An optional list (absent is empty).
    fn optional_list<T: DeserializeOwned>(
        &mut self,
        members: &serde_json::Map<String, Value>,
        name: &str,
    ) -> Option<Vec<T>> {
        match members.get(name) {
            None => Some(Vec::new()),
            Some(v) => self.list(v, name),
        }
    }

    fn parameters(&mut self, value: &Value) -> Option<NamedMap<f64>> {
        if let Value::Object(map) = value
            && map.len() as u64 > self.limits.parameters
        {
            self.fatal(too_large(
                "parameters",
                "parameters",
                map.len() as f64,
                Limit::Parameters,
                self.limits.parameters,
            ));
            return None;
        }
        self.part(value, "parameters")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_join_like_serde_path_to_error() {
        assert_eq!(join(".", "a"), "a");
        assert_eq!(join("bodies[2]", "."), "bodies[2]");
        assert_eq!(
            join("bodies[2]", "pose[0].rot_z"),
            "bodies[2].pose[0].rot_z"
        );
        assert_eq!(join("bodies", "[3]"), "bodies[3]");
    }

    #[test]
    fn clipping_keeps_short_text_and_counts_the_rest() {
        assert_eq!(clip("short"), "short");
        let long = "é".repeat(1000);
        let clipped = clip(&long);
        assert!(clipped.ends_with("… (880 more characters)"), "{clipped}");
    }
}
