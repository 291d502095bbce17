//! Every number written in a scenario file is finite. RON reads `NaN`, `inf` and literals
//! past f32's range (`1e39`) into float fields without complaint, and a camera, light or
//! animation parameter that is not finite poisons every frame; this finds the first such
//! literal, outside strings and comments, with the key it belongs to.

/// The first non-finite number in `text`: its byte offset, the key before it and the literal.
pub fn first_non_finite(text: &str) -> Option<(usize, String, String)> {
    let bytes = text.as_bytes();
    let mut key = String::new();
    let mut i = 0;
    while i < bytes.len() {
        let c = bytes[i];
        let rest = &text[i..];
        if rest.starts_with("//") {
            i += rest.find('\n').unwrap_or(rest.len());
        } else if rest.starts_with("/*") {
            i += block_comment_len(rest);
        } else if c == b'"' {
            i += string_len(rest);
        } else if c == b'r' && raw_string_hashes(rest).is_some() {
            let hashes = raw_string_hashes(rest).unwrap_or(0);
            let close = format!("\"{}", "#".repeat(hashes));
            let body = 2 + hashes;
            i += rest[body..].find(&close).map_or(rest.len(), |e| body + e + close.len());
        } else if c.is_ascii_alphabetic() || c == b'_' {
            let len = rest
                .find(|ch: char| !(ch.is_ascii_alphanumeric() || ch == '_'))
                .unwrap_or(rest.len());
            let word = &rest[..len];
            if word == "NaN" || word == "inf" {
                let signed = i > 0 && matches!(bytes[i - 1], b'-' | b'+');
                let start = if signed { i - 1 } else { i };
                return Some((start, key, text[start..i + len].to_string()));
            }
            if rest[len..].trim_start().starts_with(':') {
                key = word.to_string();
            }
            i += len;
        } else if c.is_ascii_digit()
            || (c == b'.' && rest[1..].starts_with(|ch: char| ch.is_ascii_digit()))
        {
            let len = number_len(rest);
            let literal = &rest[..len];
            let value = literal.replace('_', "").parse::<f32>();
            if value.is_ok_and(|v| !v.is_finite()) {
                let signed = i > 0 && matches!(bytes[i - 1], b'-' | b'+');
                let start = if signed { i - 1 } else { i };
                return Some((start, key, text[start..i + len].to_string()));
            }
            i += len.max(1);
        } else {
            i += text[i..].chars().next().map_or(1, char::len_utf8);
        }
    }
    None
}

/// A number: digits, `_`, one `.`, an exponent with its sign; a hex or suffixed integer stops
/// where it stops parsing as a float, which is never non-finite.
fn number_len(s: &str) -> usize {
    let b = s.as_bytes();
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        let exponent_sign = (c == b'-' || c == b'+') && i > 0 && matches!(b[i - 1], b'e' | b'E');
        if c.is_ascii_alphanumeric() || c == b'_' || c == b'.' || exponent_sign {
            i += 1;
        } else {
            break;
        }
    }
    i
}

fn string_len(s: &str) -> usize {
    let mut escaped = false;
    for (i, c) in s.char_indices().skip(1) {
        match c {
            '\\' if !escaped => escaped = true,
            '"' if !escaped => return i + 1,
            _ => escaped = false,
        }
    }
    s.len()
}

/// `r"…"` or `r#"…"#`: the number of `#`.
fn raw_string_hashes(s: &str) -> Option<usize> {
    let after = s.strip_prefix('r')?;
    let hashes = after.len() - after.trim_start_matches('#').len();
    after[hashes..].starts_with('"').then_some(hashes)
}

/// RON's block comments nest.
fn block_comment_len(s: &str) -> usize {
    let mut depth = 0;
    let mut i = 0;
    while i < s.len() {
        if s[i..].starts_with("/*") {
            depth += 1;
            i += 2;
        } else if s[i..].starts_with("*/") {
            depth -= 1;
            i += 2;
            if depth == 0 {
                return i;
            }
        } else {
            i += s[i..].chars().next().map_or(1, char::len_utf8);
        }
    }
    s.len()
}

#[cfg(test)]
mod tests {
    use super::first_non_finite;

    #[test]
    fn finds_non_finite_literals_outside_strings_and_comments() {
        let found = first_non_finite;
        assert_eq!(found("(a: 1.0, b: (0, -1e3, 2.5e-3), c: 0x1F, d: 7u8)"), None);
        assert_eq!(found("(name: \"NaN inf\", // inf\n /* NaN /* inf */ */ x: 1)"), None);
        assert_eq!(found("(s: r#\"a \" NaN\"#, x: 1)"), None);
        assert_eq!(
            found("(camera: (position: (0, NaN, 1)))"),
            Some((24, "position".into(), "NaN".into()))
        );
        assert_eq!(found("(degrees: -inf)"), Some((10, "degrees".into(), "-inf".into())));
        assert_eq!(found("(intensity: 1e39)"), Some((12, "intensity".into(), "1e39".into())));
        assert_eq!(found("(v: 3.4e38, w: 1e-50)"), None);
        assert_eq!(found("(infinity_light: 2, f: inf)"), Some((23, "f".into(), "inf".into())));
    }
}
