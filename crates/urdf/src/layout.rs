//! Readable layout of the case JSON: a list or object that fits on one line is written on one
//! line (`"com": [0.4, 0, 0]`, `{ "rot_z": "q1" }`), larger ones one member per line, keeping the
//! member order of the document (a `serde_json::Value` would sort the keys).

/// A parsed JSON value, members in text order.
enum Node {
    Scalar(String),
    Array(Vec<Node>),
    Object(Vec<(String, Node)>),
}

/// Longest line written on one line, indentation included.
const WIDTH: usize = 100;

/// Lays out valid compact JSON text (as written by `serde_json::to_string`).
pub fn layout(compact: &str) -> String {
    let mut chars = compact.char_indices().peekable();
    let node = parse(compact, &mut chars);
    let mut out = String::new();
    write(&node, 0, 0, &mut out);
    out.push('\n');
    out
}

type Chars<'a> = std::iter::Peekable<std::str::CharIndices<'a>>;

fn string(text: &str, chars: &mut Chars) -> String {
    let (start, _) = chars.next().expect("opening quote");
    let mut escaped = false;
    for (i, c) in chars.by_ref() {
        match (escaped, c) {
            (true, _) => escaped = false,
            (false, '\\') => escaped = true,
            (false, '"') => return text[start..=i].to_string(),
            _ => {}
        }
    }
    unreachable!("valid JSON closes its strings")
}

fn parse(text: &str, chars: &mut Chars) -> Node {
    match chars.peek().map(|&(_, c)| c) {
        Some('[') => {
            chars.next();
            let mut items = Vec::new();
            while chars.peek().map(|&(_, c)| c) != Some(']') {
                items.push(parse(text, chars));
                if chars.peek().map(|&(_, c)| c) == Some(',') {
                    chars.next();
                }
            }
            chars.next();
            Node::Array(items)
        }
        Some('{') => {
            chars.next();
            let mut members = Vec::new();
            while chars.peek().map(|&(_, c)| c) != Some('}') {
                let key = string(text, chars);
                chars.next(); // ':'
                members.push((key, parse(text, chars)));
                if chars.peek().map(|&(_, c)| c) == Some(',') {
                    chars.next();
                }
            }
            chars.next();
            Node::Object(members)
        }
        Some('"') => Node::Scalar(string(text, chars)),
        _ => {
            let mut s = String::new();
            while let Some(&(_, c)) = chars.peek() {
                if matches!(c, ',' | ']' | '}') {
                    break;
                }
                s.push(c);
                chars.next();
            }
            Node::Scalar(s)
        }
    }
}

fn one_line(node: &Node) -> String {
    match node {
        Node::Scalar(s) => s.clone(),
        Node::Array(items) => {
            let inner: Vec<String> = items.iter().map(one_line).collect();
            format!("[{}]", inner.join(", "))
        }
        Node::Object(members) if members.is_empty() => "{}".into(),
        Node::Object(members) => {
            let inner: Vec<String> = members
                .iter()
                .map(|(k, v)| format!("{k}: {}", one_line(v)))
                .collect();
            format!("{{ {} }}", inner.join(", "))
        }
    }
}

/// Writes `node` starting at `column` of a line indented by `indent`.
fn write(node: &Node, indent: usize, column: usize, out: &mut String) {
    let flat = one_line(node);
    if column + flat.len() <= WIDTH {
        out.push_str(&flat);
        return;
    }
    let pad = " ".repeat(indent + 2);
    match node {
        Node::Scalar(s) => out.push_str(s),
        Node::Array(items) => {
            out.push('[');
            for (i, item) in items.iter().enumerate() {
                out.push('\n');
                out.push_str(&pad);
                write(item, indent + 2, indent + 2, out);
                if i + 1 < items.len() {
                    out.push(',');
                }
            }
            out.push('\n');
            out.push_str(&" ".repeat(indent));
            out.push(']');
        }
        Node::Object(members) => {
            out.push('{');
            for (i, (key, value)) in members.iter().enumerate() {
                out.push('\n');
                out.push_str(&pad);
                out.push_str(key);
                out.push_str(": ");
                write(value, indent + 2, indent + 4 + key.len(), out);
                if i + 1 < members.len() {
                    out.push(',');
                }
            }
            out.push('\n');
            out.push_str(&" ".repeat(indent));
            out.push('}');
        }
    }
}
