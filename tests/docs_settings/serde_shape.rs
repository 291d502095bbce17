//! A settings type's fields, which of them are required and the RON text of each default,
//! read from serde itself (so `#[serde(default)]`, `default = "..."`, `rename`, `skip` and
//! `skip_serializing_if` count as the code has them), never from the Rust source.
//!
//! - Field names: a probing deserializer that records the `fields` serde's derive passes to
//!   `deserialize_struct` (or to `struct_variant` for an enum's struct variant).
//! - Defaults: the type deserialized from a minimal text that gives only its required fields
//!   (what a scenario gets when it leaves a field out), serialized with `ron::to_string`, and
//!   split into its fields' texts. A field the serializer leaves out (`skip_serializing_if`
//!   at its default) is checked by a round trip instead: the minimal text with the documented
//!   value added must serialize exactly as the default does.
//! - Required: exactly the fields of the minimal text; each one is checked to be required
//!   (the text without it does not parse).

use std::collections::{BTreeMap, BTreeSet};
use std::fmt;

use serde::de::{self, DeserializeOwned, DeserializeSeed, EnumAccess, VariantAccess, Visitor};
use serde::{Deserializer, Serialize};

/// What a type's table must say: its fields, the required ones and the defaults.
pub struct Shape {
    /// The type's field names as a scenario writes them, in declaration order.
    pub fields: Vec<String>,
    pub required: BTreeSet<String>,
    /// RON text of each field's default, where the serializer writes the field.
    pub defaults: BTreeMap<String, String>,
    /// RON text of the whole default value (the minimal text parsed and serialized).
    pub whole: String,
    /// The fields whose default is a struct, with that struct's type name (the last segment of
    /// its path): what the registry must list too.
    pub nested: Vec<(String, String)>,
    /// Parses the minimal text with `field: value` added and serializes it.
    pub with_field: Box<dyn Fn(&str, &str) -> Result<String, String>>,
}

/// The options scenarios are read with (methods add newtype-variant unwrapping).
pub fn options() -> ron::Options {
    ron::Options::default()
        .with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME)
        .with_default_extension(ron::extensions::Extensions::UNWRAP_VARIANT_NEWTYPES)
}

/// The shape of struct `T`; `minimal` is a RON text of `T` giving just its required fields.
pub fn struct_shape<T: Serialize + DeserializeOwned + 'static>(
    minimal: &str,
) -> Result<Shape, String> {
    let fields = match T::deserialize(Probe(None)) {
        Err(Found::Fields(f)) => f,
        Err(other) => return Err(format!("not a struct: {other}")),
        Ok(_) => return Err("the probe gave a value".into()),
    };
    shape::<T>(fields, minimal)
}

/// The shape of struct variant `variant` of enum `T`; `minimal` is `Variant(required...)`.
pub fn variant_shape<T: Serialize + DeserializeOwned + 'static>(
    variant: &'static str,
    minimal: &str,
) -> Result<Shape, String> {
    let fields = match T::deserialize(Probe(Some(variant))) {
        Err(Found::Fields(f)) => f,
        other => {
            return Err(format!("variant {variant} is not a struct variant: {:?}", other.err()));
        }
    };
    shape::<T>(fields, minimal)
}

fn shape<T: Serialize + DeserializeOwned + 'static>(
    fields: Vec<&'static str>,
    minimal: &str,
) -> Result<Shape, String> {
    let reserialize = |text: &str| -> Result<String, String> {
        let value: T = options().from_str(text).map_err(|e| format!("`{text}`: {e}"))?;
        ron::to_string(&value).map_err(|e| e.to_string())
    };
    let whole =
        reserialize(minimal).map_err(|e| format!("the minimal text does not parse: {e}"))?;
    let (prefix, given) = split_fields(minimal)?;
    for (name, _) in &given {
        let without: Vec<_> = given.iter().filter(|(n, _)| n != name).cloned().collect();
        if reserialize(&join_fields(&prefix, &without)).is_ok() {
            return Err(format!(
                "`{name}` of the minimal text is not required (the type parses without it)"
            ));
        }
    }
    let (_, serialized) = split_fields(&whole)?;
    // serde lists a field's aliases (`#[serde(alias = "w")]`) among its fields; an alias of a
    // required field is found by giving both: serde refuses the primary name as a duplicate.
    let is_alias = |name: &str| {
        !serialized.iter().any(|(n, _)| n == name)
            && given.iter().any(|(primary, value)| {
                let mut both = given.clone();
                both.push((name.to_string(), value.clone()));
                reserialize(&join_fields(&prefix, &both))
                    .is_err_and(|e| e.contains(&format!("duplicate field named `{primary}`")))
            })
    };
    let fields: Vec<String> =
        fields.iter().filter(|f| !is_alias(f)).map(|f| f.to_string()).collect();
    let nested = nested_structs(&minimal_value::<T>(minimal)?, &serialized)?;
    let prefix_owned = prefix.clone();
    Ok(Shape {
        nested,
        fields,
        required: given.iter().map(|(n, _)| n.clone()).collect(),
        defaults: serialized.into_iter().collect(),
        whole,
        with_field: Box::new(move |field: &str, value: &str| {
            let mut all = given.clone();
            all.push((field.to_string(), value.to_string()));
            reserialize(&join_fields(&prefix_owned, &all))
        }),
    })
}

/// The minimal text parsed, serialized with struct names (`NircCacheSettings(encoding: ...)`).
fn minimal_value<T: Serialize + DeserializeOwned>(minimal: &str) -> Result<String, String> {
    let value: T = options().from_str(minimal).map_err(|e| e.to_string())?;
    ron::ser::to_string_pretty(&value, ron::ser::PrettyConfig::new().struct_names(true))
        .map_err(|e| e.to_string())
}

/// The fields whose default is a struct with named fields: a name that the serialization with
/// struct names has and the one without lacks is a struct's (an enum variant's name is in
/// both), `(a: ...)` with named fields rather than a tuple such as a vector.
fn nested_structs(
    named: &str,
    plain: &[(String, String)],
) -> Result<Vec<(String, String)>, String> {
    let mut out = Vec::new();
    for (field, text) in split_fields(named)?.1 {
        let Some((_, plain_text)) = plain.iter().find(|(f, _)| *f == field) else { continue };
        let strip = |t: &str| {
            t.trim().strip_prefix("Some(").map_or(t.trim().to_string(), |r| r.to_string())
        };
        let (named_text, plain_text) = (strip(&text), strip(plain_text));
        let name_len = named_text.find(|c: char| !(c.is_alphanumeric() || c == '_')).unwrap_or(0);
        let opens_fields = plain_text.starts_with('(')
            && split_fields(&plain_text).is_ok_and(|(_, f)| !f.is_empty());
        if name_len > 0 && named_text[name_len..].starts_with('(') && opens_fields {
            out.push((field, named_text[..name_len].to_string()));
        }
    }
    Ok(out)
}

/// `Name(a: 1, b: (2, 3))` or `(a: 1)` into its name (maybe empty) and its fields' texts.
pub fn split_fields(text: &str) -> Result<(String, Vec<(String, String)>), String> {
    let text = text.trim();
    let name_len = text.find(|c: char| !(c.is_alphanumeric() || c == '_')).unwrap_or(text.len());
    let (name, rest) = text.split_at(name_len);
    let inner = rest
        .trim()
        .strip_prefix('(')
        .and_then(|r| r.strip_suffix(')'))
        .ok_or_else(|| format!("`{text}`: expected `(field: value, ...)`"))?;
    let mut out = Vec::new();
    for piece in split_top(inner, ',') {
        if piece.trim().is_empty() {
            continue;
        }
        let parts = split_top(&piece, ':');
        if parts.len() < 2 {
            return Err(format!("`{piece}` in `{text}`: expected `field: value`"));
        }
        let value = piece[parts[0].len() + 1..].trim().to_string();
        out.push((parts[0].trim().to_string(), value));
    }
    Ok((name.to_string(), out))
}

fn join_fields(name: &str, fields: &[(String, String)]) -> String {
    let body: Vec<String> = fields.iter().map(|(n, v)| format!("{n}: {v}")).collect();
    format!("{name}({})", body.join(", "))
}

/// Splits at `sep` outside brackets and string literals.
fn split_top(text: &str, sep: char) -> Vec<String> {
    let (mut out, mut cur, mut depth, mut in_str, mut escaped) =
        (Vec::new(), String::new(), 0i32, false, false);
    for c in text.chars() {
        if in_str {
            in_str = escaped || c != '"';
            escaped = !escaped && c == '\\';
        } else {
            match c {
                '"' => in_str = true,
                '(' | '[' | '{' => depth += 1,
                ')' | ']' | '}' => depth -= 1,
                c if c == sep && depth == 0 => {
                    out.push(std::mem::take(&mut cur));
                    continue;
                }
                _ => {}
            }
        }
        cur.push(c);
    }
    out.push(cur);
    out
}

/// RON text without the whitespace outside string literals, so `(0.0, 1.0)` equals `(0.0,1.0)`,
/// and without the raw-identifier prefix ron writes for a variant named like a RON keyword
/// (`r#None` for `ReferenceFrames::None`, which a scenario writes and reads as `None`).
pub fn normalized(text: &str) -> String {
    let (mut out, mut in_str, mut escaped) = (String::new(), false, false);
    for c in text.trim().chars() {
        if in_str {
            in_str = escaped || c != '"';
            escaped = !escaped && c == '\\';
        } else if c == '"' {
            in_str = true;
        } else if c.is_whitespace() {
            continue;
        } else if c == '#'
            && out.ends_with('r')
            && !out[..out.len() - 1].ends_with(|p: char| p.is_alphanumeric() || p == '_')
        {
            out.pop();
            continue;
        }
        out.push(c);
    }
    out
}

/// What the probe found (carried out as the deserializer's error).
#[derive(Debug)]
enum Found {
    Fields(Vec<&'static str>),
    Other(String),
}

impl fmt::Display for Found {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Found::Fields(fields) => write!(f, "fields {fields:?}"),
            Found::Other(what) => f.write_str(what),
        }
    }
}

impl std::error::Error for Found {}

impl de::Error for Found {
    fn custom<T: fmt::Display>(msg: T) -> Self {
        Found::Other(msg.to_string())
    }
}

/// A deserializer that answers a struct with its field names (or, given a variant name, an
/// enum with that variant's field names) and anything else with an error.
struct Probe(Option<&'static str>);

impl<'de> Deserializer<'de> for Probe {
    type Error = Found;

    fn deserialize_any<V: Visitor<'de>>(self, _: V) -> Result<V::Value, Found> {
        Err(Found::Other("not a struct or enum".into()))
    }

    fn deserialize_struct<V: Visitor<'de>>(
        self,
        _: &'static str,
        fields: &'static [&'static str],
        _: V,
    ) -> Result<V::Value, Found> {
        Err(Found::Fields(fields.to_vec()))
    }

    fn deserialize_enum<V: Visitor<'de>>(
        self,
        _: &'static str,
        variants: &'static [&'static str],
        visitor: V,
    ) -> Result<V::Value, Found> {
        match self.0 {
            Some(v) if variants.contains(&v) => visitor.visit_enum(VariantProbe(v)),
            _ => Err(Found::Other(format!("an enum of variants {variants:?}"))),
        }
    }

    serde::forward_to_deserialize_any! {
        bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string bytes byte_buf
        option unit unit_struct newtype_struct seq tuple tuple_struct map identifier ignored_any
    }
}

struct VariantProbe(&'static str);

impl<'de> EnumAccess<'de> for VariantProbe {
    type Error = Found;
    type Variant = Self;

    fn variant_seed<S: DeserializeSeed<'de>>(self, seed: S) -> Result<(S::Value, Self), Found> {
        let name = seed.deserialize(de::value::StrDeserializer::<Found>::new(self.0))?;
        Ok((name, self))
    }
}

impl<'de> VariantAccess<'de> for VariantProbe {
    type Error = Found;

    fn unit_variant(self) -> Result<(), Found> {
        Err(Found::Other("a unit variant".into()))
    }

    fn newtype_variant_seed<S: DeserializeSeed<'de>>(self, _: S) -> Result<S::Value, Found> {
        Err(Found::Other("a newtype variant".into()))
    }

    fn tuple_variant<V: Visitor<'de>>(self, _: usize, _: V) -> Result<V::Value, Found> {
        Err(Found::Other("a tuple variant".into()))
    }

    fn struct_variant<V: Visitor<'de>>(
        self,
        fields: &'static [&'static str],
        _: V,
    ) -> Result<V::Value, Found> {
        Err(Found::Fields(fields.to_vec()))
    }
}
