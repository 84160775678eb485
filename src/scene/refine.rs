//! Mesh refinement of a scene by an integer factor: every body's divisions are multiplied
//! and the scene is renamed `<name>_r<factor>`. Used by the refinement studies, so refined
//! scenes are generated from the paper scenes rather than copied by hand.

/// The refined scene's text. `default_name` is used when the scene has no `name` key.
pub fn refine_scene_text(text: &str, factor: u32, default_name: &str) -> Result<String, String> {
    if factor == 0 {
        return Err("the refinement factor must be at least 1".into());
    }
    let mut doc: toml::Table = text.parse().map_err(|e: toml::de::Error| e.to_string())?;
    let name = doc
        .get("name")
        .and_then(|v| v.as_str())
        .unwrap_or(default_name)
        .to_string();
    doc.insert(
        "name".into(),
        toml::Value::String(format!("{name}_r{factor}")),
    );
    if let Some(toml::Value::Array(bodies)) = doc.get_mut("body") {
        for body in bodies.iter_mut() {
            if let Some(toml::Value::Array(div)) = body.get_mut("divisions") {
                for d in div.iter_mut() {
                    if let toml::Value::Integer(n) = d {
                        *n *= factor as i64;
                    }
                }
            }
        }
    }
    toml::to_string(&doc).map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn multiplies_divisions_and_renames() {
        let text =
            "name = \"a\"\n[[body]]\nname = \"b\"\ndivisions = [2, 3, 1]\n[time]\nsegments = []\n";
        let out = refine_scene_text(text, 4, "x").unwrap();
        let doc: toml::Table = out.parse().unwrap();
        assert_eq!(doc["name"].as_str(), Some("a_r4"));
        let div: Vec<i64> = doc["body"][0]["divisions"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_integer().unwrap())
            .collect();
        assert_eq!(div, vec![8, 12, 4]);
    }
}
