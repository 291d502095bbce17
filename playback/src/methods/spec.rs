//! Parsing the scenario's `methods: [...]` into [`MethodSpec`]s. Any entry may carry
//! `name: "..."`: the method's label in the run folder, frames.csv and the report. Two methods
//! with one label are refused, naming both entries by file, line and column.

use sim::{MethodEntry, Scenario, ScenarioError};

use super::{Method, MethodSpec, registry};

/// Parses every method of the scenario; errors name the file, line and column.
pub fn parse_methods(scenario: &Scenario) -> Result<Vec<Method>, ScenarioError> {
    let methods = scenario
        .methods
        .iter()
        .map(|entry| {
            parse_entry(entry).map_err(|(pos, message)| ScenarioError {
                file: scenario.origin.clone(),
                position: Some(pos),
                message,
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    check_labels(scenario, &methods)?;
    Ok(methods)
}

/// Refuses two methods with one label (their frames, rows and summaries would merge), naming both
/// entries by file, line and column.
pub fn check_labels(scenario: &Scenario, methods: &[Method]) -> Result<(), ScenarioError> {
    for (i, m) in methods.iter().enumerate() {
        let label = m.label();
        if let Some(first) = methods[..i].iter().find(|f| f.label() == label) {
            return Err(ScenarioError {
                file: scenario.origin.clone(),
                position: Some((m.entry.line, m.entry.column)),
                message: format!(
                    "two methods are labelled '{label}': `{}` at {}:{}:{} and `{}` here; expected distinct labels (give one of them `name: \"...\"`)",
                    first.entry.text,
                    scenario.origin.display(),
                    first.entry.line,
                    first.entry.column,
                    m.entry.text
                ),
            });
        }
    }
    Ok(())
}

/// A method from RON text alone.
pub(super) fn parse_one(text: &str) -> Result<Method, String> {
    parse_entry(&MethodEntry::new(text)).map_err(|(_, message)| message)
}

/// One entry: its `name` taken out (its text blanked, so positions stay), the rest parsed as a
/// [`MethodSpec`].
fn parse_entry(entry: &MethodEntry) -> Result<Method, ((usize, usize), String)> {
    let at = |line: usize, col: usize| entry.position_in_file(line, col);
    let (text, name) = take_name(&entry.text).map_err(|m| (at(1, 1), m))?;
    let options = ron::Options::default()
        .with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME)
        .with_default_extension(ron::extensions::Extensions::UNWRAP_VARIANT_NEWTYPES);
    // `Name(fields)`: the registry's plugin called Name parses `(fields)`, the name blanked so
    // that positions stay the entry's.
    let start = skip_blank(&text);
    let name_len = text[start..]
        .find(|c: char| !is_ident(c as u8) || !c.is_ascii())
        .unwrap_or(text.len() - start);
    let method_name = &text[start..start + name_len];
    let (line, col) = line_col(&text, start);
    let plugin = registry::find(method_name).ok_or_else(|| {
        (
            at(line, col),
            format!(
                "method `{}`: unknown method `{method_name}`; expected one of: {}",
                entry.text,
                registry::names().join(", ")
            ),
        )
    })?;
    let body = format!("{}{}{}", &text[..start], " ".repeat(name_len), &text[start + name_len..]);
    let spec: MethodSpec = plugin.parse(&body, &options).map_err(|e| {
        (at(e.span.start.line, e.span.start.col), format!("method `{}`: {}", entry.text, e.code))
    })?;
    if let Some(n) = &name {
        let ok = !n.is_empty()
            && n.chars().all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.'))
            && !n.starts_with('.');
        if !ok {
            return Err((
                at(1, 1),
                format!(
                    "method name '{n}'; expected letters, digits, '_', '-' or '.' (it names a folder)"
                ),
            ));
        }
    }
    Ok(Method { spec, name, entry: entry.clone() })
}

/// Finds `name: "..."` among the top-level fields of `Variant(...)`, returns the text with that
/// field (and its comma) replaced by spaces, and the name.
fn take_name(text: &str) -> Result<(String, Option<String>), String> {
    let bytes = text.as_bytes();
    let mut depth = 0;
    let mut i = 0;
    let mut found: Option<(usize, usize, String)> = None;
    while i < bytes.len() {
        match bytes[i] {
            b'"' => {
                i = skip_string(bytes, i);
                continue;
            }
            b'(' | b'[' | b'{' => depth += 1,
            b')' | b']' | b'}' => depth -= 1,
            b'n' if depth == 1
                && text[i..].starts_with("name")
                && (i == 0 || !is_ident(bytes[i - 1])) =>
            {
                let mut j = i + 4;
                while j < bytes.len() && bytes[j].is_ascii_whitespace() {
                    j += 1;
                }
                if j < bytes.len() && bytes[j] == b':' {
                    j += 1;
                    while j < bytes.len() && bytes[j].is_ascii_whitespace() {
                        j += 1;
                    }
                    if j >= bytes.len() || bytes[j] != b'"' {
                        return Err(
                            "`name:` must be followed by a string, e.g. name: \"blend_fixed\""
                                .into(),
                        );
                    }
                    let end = skip_string(bytes, j);
                    let name: String =
                        ron::from_str(&text[j..end]).map_err(|e| format!("method name: {e}"))?;
                    let mut k = end;
                    while k < bytes.len() && bytes[k].is_ascii_whitespace() {
                        k += 1;
                    }
                    if k < bytes.len() && bytes[k] == b',' {
                        k += 1;
                    }
                    if found.is_some() {
                        return Err("`name` given twice".into());
                    }
                    found = Some((i, k, name));
                    i = k;
                    continue;
                }
            }
            _ => {}
        }
        i += 1;
    }
    match found {
        None => Ok((text.to_string(), None)),
        Some((start, end, name)) => {
            // Newlines kept, everything else blanked: line and column of what follows stay.
            let blank: String =
                text[start..end].chars().map(|c| if c == '\n' { '\n' } else { ' ' }).collect();
            Ok((format!("{}{}{}", &text[..start], blank, &text[end..]), Some(name)))
        }
    }
}

/// Byte offset of the first character of `text` that is not white space or a comment.
fn skip_blank(text: &str) -> usize {
    let mut i = 0;
    loop {
        let rest = &text[i..];
        let trimmed = rest.trim_start();
        i += rest.len() - trimmed.len();
        if trimmed.starts_with("//") {
            i += trimmed.find('\n').unwrap_or(trimmed.len());
        } else if let Some(block) = trimmed.strip_prefix("/*") {
            i += 2 + block.find("*/").map_or(block.len(), |e| e + 2);
        } else {
            return i;
        }
    }
}

/// 1-based line and column of byte `offset` of `text`.
fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, col)
}

fn is_ident(b: u8) -> bool {
    b.is_ascii_alphanumeric() || b == b'_'
}

/// Index just past the string literal starting at `start` (a `"`).
fn skip_string(bytes: &[u8], start: usize) -> usize {
    let mut i = start + 1;
    while i < bytes.len() {
        match bytes[i] {
            b'\\' => i += 2,
            b'"' => return i + 1,
            _ => i += 1,
        }
    }
    bytes.len()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn name_is_taken_out_and_positions_stay() {
        let (text, name) =
            take_name("Nirc(name: \"blend_fixed\", spp: 1, cache: (name: 3))").unwrap();
        assert_eq!(name.as_deref(), Some("blend_fixed"));
        assert_eq!(text.len(), "Nirc(name: \"blend_fixed\", spp: 1, cache: (name: 3))".len());
        assert!(text.starts_with("Nirc(") && text.contains("spp: 1, cache: (name: 3))"));
        assert_eq!(take_name("Taa(alpha: 0.2)").unwrap(), ("Taa(alpha: 0.2)".to_string(), None));
        assert!(take_name("Taa(name: 3)").is_err());
    }

    #[test]
    fn the_method_name_follows_comments_and_unknown_names_list_the_registry() {
        assert_eq!(skip_blank("  // a control\n  /* x */ Taa()"), 25);
        let m = parse_one("// the baseline\n  PathTracing(spp: 2)").unwrap();
        assert_eq!(m.label(), "pt_2spp");
        let e = parse_one("Tea(alpha: 0.2)").unwrap_err();
        assert!(e.contains("unknown method `Tea`") && e.contains("Taa, HashCache"), "{e}");
    }
}
