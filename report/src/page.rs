//! What every HTML page of the report shares: the document around a body, and JSON placed
//! inside a <script> element. The markup is written with maud, which escapes every value it
//! splices into text and attributes; only constant CSS and JavaScript and [`script_json`]'s
//! output go in unescaped.

use maud::{DOCTYPE, Markup, PreEscaped, html};

/// The page: `title`, the stylesheet `style` (constant CSS) and `body`.
pub fn document(title: &str, style: &str, body: Markup) -> String {
    html! {
        (DOCTYPE) "\n"
        html lang="en" {
            head { meta charset="utf-8"; title { (title) } style { (PreEscaped(style)) } }
            body { "\n" (body) }
        }
        "\n"
    }
    .into_string()
}

/// `value` as JSON that can stand inside a <script> element: serde_json writes it, and every
/// `<` (only ever inside a string there) becomes `\u003c`, so a name holding `</script>` or
/// `<!--` cannot end or change the script element. The text is the same JSON value.
pub fn script_json(value: &serde_json::Value) -> PreEscaped<String> {
    PreEscaped(value.to_string().replace('<', "\\u003c"))
}
