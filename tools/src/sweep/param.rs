//! Setting one method parameter by path (`taa.alpha`, `nirc_blend_1spp.cache.reliability.kappa`):
//! the method's settings go through their serde form (JSON), the field is replaced and the
//! settings are parsed back by the method's own struct, so every check a scenario gets (types,
//! unknown fields, enums) applies to a sweep's values too.

use serde_json::Value;

use playback::methods::Method;

/// Sets `path` (after the method label) of `method` to `value`.
pub fn set(method: &mut Method, path: &[&str], value: &Value) -> Result<(), String> {
    let mut tree = method.spec.settings_json().map_err(|e| e.to_string())?;
    // The settings must survive the round trip unchanged, or a sweep would change more than it says.
    let back = method
        .spec
        .with_settings_json(tree.clone())
        .map_err(|e| format!("settings of '{}' do not round-trip: {e}", method.label()))?;
    if back != method.spec {
        return Err(format!(
            "settings of '{}' do not round-trip through their serde form",
            method.label()
        ));
    }
    let mut at = &mut tree;
    let mut walked = method.spec.name().to_string();
    for (i, field) in path.iter().enumerate() {
        let Value::Object(map) = at else {
            return Err(format!("{walked} is not a struct of fields, so it has no '{field}'"));
        };
        let known: Vec<String> = map.keys().cloned().collect();
        let missing =
            format!("{walked} has no field '{field}'; its fields are: {}", known.join(", "));
        // A field left out of the serde form at its default (`skip_serializing_if`, such as
        // NIRC's `sparse_grid`) is still a field: the settings struct decides.
        if !map.contains_key(*field) && i + 1 == path.len() {
            map.insert(field.to_string(), value.clone());
            return match method.spec.with_settings_json(tree) {
                Ok(spec) => {
                    method.spec = spec;
                    Ok(())
                }
                Err(e) if e.to_string().contains("unknown field") => Err(missing),
                Err(e) => Err(format!("{walked}.{field} = {value}: {e}")),
            };
        }
        at = map.get_mut(*field).ok_or(missing)?;
        walked = format!("{walked}.{field}");
    }
    *at = value.clone();
    method.spec =
        method.spec.with_settings_json(tree).map_err(|e| format!("{walked} = {value}: {e}"))?;
    Ok(())
}

/// Applies `param = value` to the method of `methods` whose label is the parameter's first part.
pub fn apply(methods: &mut [Method], param: &str, value: &Value) -> Result<(), String> {
    let mut parts = param.split('.');
    let label = parts.next().unwrap_or_default();
    let path: Vec<&str> = parts.collect();
    let labels: Vec<String> = methods.iter().map(Method::label).collect();
    let method = methods.iter_mut().find(|m| m.label() == label).ok_or_else(|| {
        format!(
            "parameter '{param}': no method labelled '{label}' in the case; its methods are: {}",
            labels.join(", ")
        )
    })?;
    set(method, &path, value).map_err(|e| format!("parameter '{param}': {e}"))
}

/// Sets each (label, field path, value) on the method of that label.
pub fn set_each(
    methods: &mut [Method],
    params: &[(String, Vec<String>, serde_json::Value)],
) -> Result<(), String> {
    for (label, path, value) in params {
        let m = methods
            .iter_mut()
            .find(|m| m.label() == *label)
            .ok_or_else(|| format!("no method labelled '{label}'"))?;
        let path: Vec<&str> = path.iter().map(String::as_str).collect();
        set(m, &path, value).map_err(|e| format!("parameter '{label}.{}': {e}", path.join(".")))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn sets_nested_fields_and_refuses_unknown_ones() {
        let mut m = Method::parse("Nirc(spp: 1, predictor: Blend)").unwrap();
        set(&mut m, &["cache", "reliability", "kappa"], &json!(2.0)).unwrap();
        set(&mut m, &["cache", "ema", "alpha"], &json!(0.9)).unwrap();
        // Read through the settings' serde form: tools knows no method's settings type.
        let s = m.spec.settings_json().unwrap();
        let (kappa, alpha) = (&s["cache"]["reliability"]["kappa"], &s["cache"]["ema"]["alpha"]);
        // Both are f32 settings.
        let f32_of = |v: &serde_json::Value| v.as_f64().map(|v| v as f32);
        assert_eq!((f32_of(kappa), f32_of(alpha)), (Some(2.0), Some(0.9)));
        // Everything else as parsed.
        let expected = Method::parse("Nirc(spp: 1, predictor: Blend)").unwrap();
        let mut e = expected.spec.settings_json().unwrap();
        e["cache"]["reliability"]["kappa"] = json!(2.0);
        e["cache"]["ema"]["alpha"] = json!(0.9);
        assert_eq!(m.spec, expected.spec.with_settings_json(e).unwrap());

        let e = set(&mut m, &["cache", "kapa"], &json!(1.0)).unwrap_err();
        assert!(e.contains("Nirc.cache has no field 'kapa'") && e.contains("reliability"), "{e}");
        // A field the serde form leaves out at its default is set all the same.
        set(&mut m, &["cache", "optimizer", "sparse_grid"], &json!(true)).unwrap();
        let s = m.spec.settings_json().unwrap();
        assert_eq!(s["cache"]["optimizer"]["sparse_grid"], json!(true));
        let e = set(&mut m, &["cache", "optimizer", "sparse"], &json!(true)).unwrap_err();
        assert!(e.contains("Nirc.cache.optimizer has no field 'sparse'"), "{e}");
        let e = set(&mut m, &["spp"], &json!(1.5)).unwrap_err();
        assert!(e.contains("Nirc.spp = 1.5"), "{e}");
        let mut taa = vec![Method::parse("Taa()").unwrap()];
        apply(&mut taa, "taa.alpha", &json!(0.25)).unwrap();
        let t = taa[0].spec.get::<taa::TaaSettings>().expect("Taa settings");
        assert_eq!(t.alpha, 0.25);
        let e = apply(&mut taa, "pt_1spp.spp", &json!(2)).unwrap_err();
        assert!(e.contains("no method labelled 'pt_1spp'") && e.contains("taa"), "{e}");
    }
}
