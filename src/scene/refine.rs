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
    // Node and element ids name different things on a refined mesh, and a Gmsh mesh is
    // not refined: refuse rather than silently select the wrong nodes or keep the mesh.
    for kind in ["node_set", "side_set"] {
        if let Some(toml::Value::Array(sets)) = doc.get(kind) {
            for set in sets {
                if set.get("ids").is_some() || set.get("faces").is_some() {
                    let name = set.get("name").and_then(|v| v.as_str()).unwrap_or("?");
                    return Err(format!(
                        "{kind} '{name}' selects by id; ids change with refinement (select by position to refine this scene)"
                    ));
                }
            }
        }
    }
    if let Some(toml::Value::Array(bodies)) = doc.get("body") {
        for body in bodies {
            if body.get("divisions").is_none() {
                let name = body.get("name").and_then(|v| v.as_str()).unwrap_or("?");
                return Err(format!(
                    "body '{name}' is not a generated block (no divisions); only generated blocks can be refined"
                ));
            }
        }
    }
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

    #[test]
    fn refuses_what_refinement_would_silently_break() {
        let ids = "[[body]]\nname = \"b\"\ndivisions = [1, 1, 1]\n[[node_set]]\nname = \"top\"\nids = [5, 6]\n";
        let e = refine_scene_text(ids, 2, "x").unwrap_err();
        assert!(e.contains("node_set 'top' selects by id"), "{e}");
        let faces = "[[side_set]]\nname = \"s\"\nfaces = [[1, 2]]\n";
        assert!(refine_scene_text(faces, 2, "x")
            .unwrap_err()
            .contains("side_set 's'"));
        let gmsh = "[[body]]\nname = \"c\"\ngmsh_volume = \"cyl\"\n";
        assert!(refine_scene_text(gmsh, 2, "x")
            .unwrap_err()
            .contains("body 'c' is not a generated block"));
        // Factor 1 is never asked of refine (load_scene_refined parses the text as is).
    }
}
