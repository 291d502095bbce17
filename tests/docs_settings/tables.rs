//! The settings tables of a document: `<!-- settings: crate::path::Type -->` followed by a table
//! `| field | default | meaning |`, one row per field, and their check against the type's
//! [`Shape`].

use pulldown_cmark::{Event, Tag, TagEnd};

use super::docs_common::Doc;
use super::serde_shape::{Shape, normalized};

/// One table: the type its marker names and its rows.
pub struct Table {
    /// `file:line` of the marker.
    pub place: String,
    pub type_name: String,
    pub rows: Vec<Row>,
}

pub struct Row {
    pub place: String,
    /// The field cell: one code span, `name`.
    pub field: Option<String>,
    pub field_text: String,
    pub default: Cell,
}

/// The default column.
#[derive(Debug, PartialEq)]
pub enum Cell {
    /// One code span: the RON text of the default.
    Ron(String),
    /// The word `required` (plain or in backticks: no RON value is called that).
    Required,
    /// A link to another settings type's table; its text names the type.
    Link { text: String },
    /// Anything else.
    Other(String),
}

const MARKER: &str = "<!-- settings:";

/// Every settings table of `doc`; a marker not followed by a table, or a table whose header is
/// not `field | default | meaning`, is an error naming its line.
pub fn tables(doc: &Doc) -> Result<Vec<Table>, Vec<String>> {
    let (mut out, mut errors) = (Vec::new(), Vec::new());
    let mut pending: Option<(String, String)> = None;
    let mut table: Option<Table> = None;
    let mut in_head = false;
    // The current row's cells: for each, its code spans, its plain text and its link texts.
    let mut cells: Vec<(Vec<String>, String, Vec<String>)> = Vec::new();
    let mut link: Option<String> = None;
    let mut row_at = 0;
    for (event, range) in doc.events() {
        match &event {
            Event::Html(h) | Event::InlineHtml(h) if h.contains(MARKER) => {
                for piece in h.split(MARKER).skip(1) {
                    let name = piece.split("-->").next().unwrap_or("").trim().to_string();
                    if let Some((p, n)) = pending.take() {
                        errors.push(format!("{p}: marker of {n} is not followed by its table"));
                    }
                    pending = Some((doc.place(range.start), name));
                }
                continue;
            }
            _ => {}
        }
        match event {
            Event::Start(Tag::Table(_)) => {
                if let Some((place, type_name)) = pending.take() {
                    table = Some(Table { place, type_name, rows: Vec::new() });
                }
            }
            Event::Start(Tag::TableHead) => {
                in_head = true;
                cells.clear();
            }
            Event::End(TagEnd::TableHead) => {
                in_head = false;
                let texts: Vec<String> =
                    cells.drain(..).map(|c| c.1.trim().to_lowercase()).collect();
                if let Some(t) = &table
                    && texts != ["field", "default", "meaning"]
                {
                    errors.push(format!(
                        "{}: the table of {} has the header {texts:?}; expected | field | default | meaning |",
                        t.place, t.type_name
                    ));
                }
            }
            Event::Start(Tag::TableRow) => {
                cells.clear();
                row_at = range.start;
            }
            Event::Start(Tag::TableCell) => cells.push((Vec::new(), String::new(), Vec::new())),
            Event::Code(c) => {
                if let Some(cell) = cells.last_mut() {
                    cell.0.push(c.to_string());
                    cell.1.push_str(&format!("`{c}`"));
                }
                if let Some(l) = link.as_mut() {
                    l.push_str(&c);
                }
            }
            Event::Text(t) => {
                if let Some(cell) = cells.last_mut() {
                    cell.1.push_str(&t);
                }
                if let Some(l) = link.as_mut() {
                    l.push_str(&t);
                }
            }
            Event::Start(Tag::Link { .. }) => link = Some(String::new()),
            Event::End(TagEnd::Link) => {
                if let (Some(l), Some(cell)) = (link.take(), cells.last_mut()) {
                    cell.2.push(l);
                }
            }
            Event::End(TagEnd::TableRow) if !in_head => {
                if let Some(t) = table.as_mut() {
                    t.rows.push(row(doc.place(row_at), &cells));
                }
            }
            Event::End(TagEnd::Table) => {
                if let Some(t) = table.take() {
                    out.push(t);
                }
            }
            Event::Start(
                Tag::Paragraph | Tag::Heading { .. } | Tag::CodeBlock(_) | Tag::List(_),
            ) => {
                if let Some((p, n)) = pending.take() {
                    errors.push(format!("{p}: marker of {n} is not followed by its table"));
                }
            }
            _ => {}
        }
    }
    if let Some((p, n)) = pending {
        errors.push(format!("{p}: marker of {n} is not followed by its table"));
    }
    if errors.is_empty() { Ok(out) } else { Err(errors) }
}

fn row(place: String, cells: &[(Vec<String>, String, Vec<String>)]) -> Row {
    let empty = (Vec::new(), String::new(), Vec::new());
    let (field_codes, field_text, _) = cells.first().unwrap_or(&empty);
    let (codes, text, links) = cells.get(1).unwrap_or(&empty);
    let field = match field_codes.as_slice() {
        [one] if field_text.trim() == format!("`{one}`") => Some(one.clone()),
        _ => None,
    };
    let default = if let [l] = links.as_slice() {
        Cell::Link { text: l.trim_matches('`').to_string() }
    } else if text.trim() == "required" || text.trim() == "`required`" {
        Cell::Required
    } else if let [one] = codes.as_slice()
        && text.trim() == format!("`{one}`")
    {
        Cell::Ron(one.clone())
    } else {
        Cell::Other(text.trim().to_string())
    };
    Row { place, field, field_text: field_text.trim().to_string(), default }
}

/// What is wrong with `table` as the table of a type of shape `shape`. `linked` answers a
/// link's type name (the last segment of a registered type's path) with that type's shape.
pub fn check(table: &Table, shape: &Shape, linked: &dyn Fn(&str) -> Option<Shape>) -> Vec<String> {
    let mut errors = Vec::new();
    let ty = &table.type_name;
    let mut seen: Vec<&str> = Vec::new();
    for row in &table.rows {
        let p = &row.place;
        let Some(field) = row.field.as_deref() else {
            errors.push(format!(
                "{p}: the field cell `{}` of {ty}'s table; expected one code span, `name`",
                row.field_text
            ));
            continue;
        };
        if !shape.fields.iter().any(|f| f == field) {
            errors.push(format!(
                "{p}: `{field}` is not a field of {ty}; its fields: {}",
                shape.fields.join(", ")
            ));
            continue;
        }
        if seen.contains(&field) {
            errors.push(format!("{p}: `{field}` of {ty} has two rows"));
            continue;
        }
        seen.push(field);
        let required = shape.required.contains(field);
        let expected = || match shape.defaults.get(field) {
            Some(d) => format!("`{d}`"),
            None => "its default".into(),
        };
        match &row.default {
            Cell::Required if required => {}
            Cell::Required => errors.push(format!(
                "{p}: {ty}.{field} is documented `required` but has a default, {}",
                expected()
            )),
            _ if required => errors.push(format!("{p}: {ty}.{field} has no default; expected `required`")),
            Cell::Ron(doc) => match shape.defaults.get(field) {
                Some(d) if normalized(d) == normalized(doc) => {}
                Some(d) => errors.push(format!("{p}: {ty}.{field} defaults to `{d}`, not `{doc}`")),
                // Not serialized at its default: the documented value must serialize as the
                // default does.
                None => match (shape.with_field)(field, doc) {
                    Ok(s) if s == shape.whole => {}
                    Ok(s) => errors.push(format!(
                        "{p}: {ty}.{field} is not `{doc}` by default (with it the value reads `{s}`, by default `{}`)",
                        shape.whole
                    )),
                    Err(e) => errors.push(format!("{p}: {ty}.{field}: `{doc}` does not parse: {e}")),
                },
            },
            Cell::Link { text } => match linked(text) {
                None => errors.push(format!(
                    "{p}: {ty}.{field} links to `{text}`, which is no registered settings type"
                )),
                Some(other) if other.required.is_empty() => {
                    let same = match shape.defaults.get(field) {
                        Some(d) => normalized(d) == normalized(&other.whole),
                        None => (shape.with_field)(field, &other.whole).is_ok_and(|s| s == shape.whole),
                    };
                    if !same {
                        errors.push(format!(
                            "{p}: {ty}.{field} defaults to {}, not to {text}'s defaults `{}`",
                            shape.defaults.get(field).map_or("a value the serializer leaves out".into(), |d| format!("`{d}`")),
                            other.whole
                        ));
                    }
                }
                Some(_) => {}
            },
            Cell::Other(text) => errors.push(format!(
                "{p}: {ty}.{field}'s default `{text}`; expected the RON text in backticks, `required`, or a link to its type's table"
            )),
        }
    }
    for f in &shape.fields {
        if !seen.contains(&f.as_str()) {
            errors.push(format!("{}: {ty}'s field `{f}` has no row", table.place));
        }
    }
    errors
}
