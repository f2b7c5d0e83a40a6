//! Where a JSON path is in the text: line and column for error messages, duplicate keys.
//!
//! The case is deserialized from a `serde_json::Value`, which keeps no positions, so that
//! every section can be checked on its own and every error collected. This module recovers the
//! positions with one pass over the text. It is iterative (an explicit stack), so nesting
//! cannot exhaust the call stack, and it tolerates malformed JSON, so that it can also say in
//! which member a syntax error (a truncated file) occurred.

use std::collections::{HashMap, HashSet};

/// A line and a column, both counted from 1 (the column in characters).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct Position {
    pub line: usize,
    pub column: usize,
}

/// The position of byte `offset` (clamped to the text).
pub fn position(text: &str, offset: usize) -> Position {
    let mut offset = offset.min(text.len());
    while !text.is_char_boundary(offset) {
        offset -= 1;
    }
    let before = &text[..offset];
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    Position {
        line: before.matches('\n').count() + 1,
        column: before[line_start..].chars().count() + 1,
    }
}

/// The byte offset of a serde_json `(line, column)` (both from 1; the column counts bytes).
pub fn offset(text: &str, line: usize, column: usize) -> usize {
    let mut start = 0;
    for _ in 1..line {
        match text[start..].find('\n') {
            Some(i) => start += i + 1,
            None => return text.len(),
        }
    }
    (start + column.saturating_sub(1)).min(text.len())
}

enum Frame {
    /// An object, with the path length before its members and the keys seen so far.
    Object { base: usize, keys: HashSet<String> },
    /// An array, with the path length before its elements and the current index.
    Array { base: usize, index: usize },
}

/// One member or element found by [`scan`].
struct Visit<'p> {
    path: &'p str,
    offset: usize,
    /// The key was already used in the same object.
    duplicate: bool,
}

/// Walks the text up to `stop`, calling `visit` for every object member (at its key) and
/// every array element and the root (at its value); `visit` returns `false` to stop early.
/// Returns the path being read where it stopped.
fn scan(text: &str, stop: usize, mut visit: impl FnMut(Visit) -> bool) -> String {
    let b = text.as_bytes();
    let stop = stop.min(b.len());
    let mut path = String::new();
    let mut stack: Vec<Frame> = Vec::new();
    let mut expect_key = false;
    let mut i = 0;
    // An array element or the root starts at its value; an object member at its key.
    let value_start =
        |stack: &Vec<Frame>, path: &str, at: usize, visit: &mut dyn FnMut(Visit) -> bool| {
            !matches!(stack.last(), None | Some(Frame::Array { .. }))
                || visit(Visit {
                    path: if path.is_empty() { "." } else { path },
                    offset: at,
                    duplicate: false,
                })
        };
    while i < stop {
        match b[i] {
            b' ' | b'\t' | b'\n' | b'\r' | b':' => i += 1,
            b'{' => {
                if !value_start(&stack, &path, i, &mut visit) {
                    break;
                }
                stack.push(Frame::Object {
                    base: path.len(),
                    keys: HashSet::new(),
                });
                expect_key = true;
                i += 1;
            }
            b'[' => {
                if !value_start(&stack, &path, i, &mut visit) {
                    break;
                }
                stack.push(Frame::Array {
                    base: path.len(),
                    index: 0,
                });
                path.push_str("[0]");
                expect_key = false;
                i += 1;
            }
            b'"' => {
                let end = string_end(b, i);
                if let (true, Some(Frame::Object { base, keys })) = (expect_key, stack.last_mut()) {
                    let key = decode_key(&text[i..end]);
                    path.truncate(*base);
                    if *base > 0 {
                        path.push('.');
                    }
                    path.push_str(&key);
                    let duplicate = !keys.insert(key);
                    let go_on = visit(Visit {
                        path: &path,
                        offset: i,
                        duplicate,
                    });
                    if !go_on {
                        break;
                    }
                    expect_key = false;
                } else if !value_start(&stack, &path, i, &mut visit) {
                    break;
                }
                i = end;
            }
            b',' => {
                match stack.last_mut() {
                    Some(Frame::Object { .. }) => expect_key = true,
                    Some(Frame::Array { base, index }) => {
                        *index += 1;
                        path.truncate(*base);
                        path.push_str(&format!("[{index}]"));
                    }
                    None => {}
                }
                i += 1;
            }
            b'}' | b']' => {
                if let Some(Frame::Object { base, .. } | Frame::Array { base, .. }) = stack.pop() {
                    path.truncate(base);
                }
                expect_key = false;
                i += 1;
            }
            _ => {
                if !value_start(&stack, &path, i, &mut visit) {
                    break;
                }
                while i < b.len()
                    && !matches!(b[i], b',' | b']' | b'}' | b' ' | b'\t' | b'\n' | b'\r')
                {
                    i += 1;
                }
            }
        }
    }
    if path.is_empty() {
        ".".to_string()
    } else {
        path
    }
}

/// The index just past the string starting with the quote at `start` (or the end).
fn string_end(b: &[u8], start: usize) -> usize {
    let mut j = start + 1;
    while j < b.len() {
        match b[j] {
            b'\\' => j += 2,
            b'"' => return j + 1,
            _ => j += 1,
        }
    }
    b.len()
}

fn decode_key(quoted: &str) -> String {
    if quoted.contains('\\')
        && let Ok(key) = serde_json::from_str::<String>(quoted)
    {
        return key;
    }
    quoted
        .trim_start_matches('"')
        .trim_end_matches('"')
        .to_string()
}

/// The path of the member or element being read at byte `offset` (`.` at the top level).
pub fn path_at(text: &str, offset: usize) -> String {
    scan(text, offset, |_| true)
}

/// Paths of keys that repeat a key of the same object, with their positions.
pub fn duplicate_keys(text: &str) -> Vec<(String, Position)> {
    let mut found = Vec::new();
    scan(text, text.len(), |v| {
        if v.duplicate {
            found.push((v.path.to_string(), v.offset));
        }
        true
    });
    found
        .into_iter()
        .map(|(path, at)| (path, position(text, at)))
        .collect()
}

/// Positions of the given paths (the first occurrence of each); a path not in the text is
/// located at its nearest ancestor that is (`bodies[0].com` of a body without `com`: the body).
pub fn positions(text: &str, paths: &[&str]) -> HashMap<String, Position> {
    let mut wanted: HashSet<String> = HashSet::from([".".to_string()]);
    for p in paths {
        for a in ancestors(p) {
            wanted.insert(a.to_string());
        }
    }
    let mut offsets: HashMap<String, usize> = HashMap::new();
    let total = wanted.len();
    scan(text, text.len(), |v| {
        if wanted.contains(v.path) && !offsets.contains_key(v.path) {
            offsets.insert(v.path.to_string(), v.offset);
        }
        offsets.len() < total
    });
    let mut out = HashMap::new();
    for p in paths {
        if let Some(at) = ancestors(p).chain(["."]).find_map(|a| offsets.get(a)) {
            out.insert(p.to_string(), position(text, *at));
        }
    }
    out
}

/// `a.b[2].c`, `a.b[2]`, `a.b`, `a`.
fn ancestors(path: &str) -> impl Iterator<Item = &str> {
    let mut next = Some(path);
    std::iter::from_fn(move || {
        let current = next?;
        next = current
            .rfind(['.', '['])
            .filter(|&i| i > 0)
            .map(|i| &current[..i]);
        Some(current)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = "{\n  \"a\": 1,\n  \"b\": [ {\"c\": true}, {\"c\": [1, 2]} ],\n  \"d\": {\"e\\\"\": \"x,]}\"}\n}";

    #[test]
    fn members_and_elements_are_located() {
        let found = positions(TEXT, &["a", "b[1].c[1]", "d.e\"", "b[0].zz", "."]);
        assert_eq!(found["a"], Position { line: 2, column: 3 });
        // `[1, 2]` of the second element: the element `2` is at column 33 of line 3.
        assert_eq!(
            found["b[1].c[1]"],
            Position {
                line: 3,
                column: 33
            }
        );
        assert_eq!(found["d.e\""], Position { line: 4, column: 9 });
        // a missing member is located at its parent
        assert_eq!(
            found["b[0].zz"],
            Position {
                line: 3,
                column: 10
            }
        );
        assert_eq!(found["."], Position { line: 1, column: 1 });
    }

    #[test]
    fn duplicates_and_truncation() {
        let dup = "{\"p\": {\"x\": 1, \"y\": 2, \"x\": 3}, \"q\": [{\"x\": 1, \"x\": 2}]}";
        let found: Vec<String> = duplicate_keys(dup).into_iter().map(|d| d.0).collect();
        assert_eq!(found, vec!["p.x", "q[0].x"]);
        let truncated = "{\"bodies\": [{\"name\": \"a\"}, {\"name\": \"b\", \"mass\": 1";
        assert_eq!(path_at(truncated, truncated.len()), "bodies[1].mass");
        assert_eq!(path_at("[1, 2", 5), "[1]");
    }

    #[test]
    fn deep_nesting_does_not_recurse() {
        let deep = "[".repeat(1_000_000);
        assert!(path_at(&deep, deep.len()).ends_with("[0]"));
    }
}
