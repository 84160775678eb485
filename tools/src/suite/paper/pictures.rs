//! The captions of run/render's ParaView pictures of a result's last step (from its
//! `<scene>.render.json`), or why there are none.

use super::results::{Paper, Render};
use crate::text::Doc;
use crate::text::{general, num};
use serde_json::Value;

fn base(p: &Value) -> String {
    let s = p.as_str().unwrap_or("");
    s.rsplit('/').next().unwrap_or(s).to_string()
}

fn f(v: &Value) -> Option<f64> {
    v.as_f64()
}

fn truthy(v: &Value) -> bool {
    match v {
        Value::Bool(b) => *b,
        Value::Number(n) => n.as_f64().is_some_and(|x| x != 0.0),
        Value::Null => false,
        Value::String(s) => !s.is_empty(),
        Value::Array(a) => !a.is_empty(),
        Value::Object(o) => !o.is_empty(),
    }
}

/// The text shared by both captions: the step and the warp.
fn common(name: &str, info: &Value) -> String {
    let scale = f(&info["warp_scale"]).unwrap_or(f64::NAN);
    let umax = f(&info["max_displacement"]).unwrap_or(f64::NAN);
    let diag = f(&info["diagonal"]).unwrap_or(f64::NAN);
    let mut how = if info["warp_scale_kind"].as_str() != Some("automatic") {
        "given".to_string()
    } else {
        "automatic".to_string()
    };
    if umax > 0.0 && diag > 0.0 {
        how += &format!(
            ": the largest displacement, {}, is drawn as {}% of the mesh's bounding-box diagonal",
            num(Some(umax)),
            general(100.0 * scale * umax / diag, 2)
        );
    }
    let step = info["step"]
        .as_f64()
        .map_or("?".into(), |k| num(Some(k + 1.0)));
    let mut c = format!(
        "ParaView (`run/render`), `{name}` at its last step, t = {} (step {step} of {}): the mesh \
         warped by the displacement times {} ({how}",
        num(f(&info["time"])),
        num(f(&info["steps"])),
        num(Some(scale))
    );
    if scale > 1.0 {
        c += "; the scaling exaggerates the bodies' relative motion as well, so touching \
              surfaces may be drawn overlapping";
    }
    c + ")"
}

/// The two pictures' lines for one render.json.
pub fn captions(name: &str, info: &Value) -> Vec<String> {
    let common = common(name, info);
    let vm = &info["pictures"]["von_mises"];
    let uniform = if truthy(&vm["uniform"]) {
        " (uniform: colour scale widened to +-1%)"
    } else {
        ""
    };
    let mut out = vec![
        format!("![{name}: von Mises stress]({})\n", base(&vm["png"])),
        format!(
            "*{common}, coloured by the von Mises stress of each element, computed in ParaView \
             from the cell array `stress` (xx yy zz xy yz zx): {} to {}{uniform}.* (`{}`)\n",
            num(f(&vm["min"])),
            num(f(&vm["max"])),
            base(&vm["png"])
        ),
    ];
    let pl = &info["pictures"]["plastic_strain"];
    if !pl.is_null() {
        out.push(format!(
            "![{name}: equivalent plastic strain]({})\n",
            base(&pl["png"])
        ));
        out.push(format!(
            "*{common}, coloured by the equivalent plastic strain of each element (cell array \
             `plastic_strain`): {} to {}, {} elements yielded.* (`{}`)\n",
            num(f(&pl["min"])),
            num(f(&pl["max"])),
            pl["yielded_elements"],
            base(&pl["png"])
        ));
    }
    let c = &info["pictures"]["contact"];
    let text = if truthy(&c["nodes_in_contact"]) {
        let zoom = if truthy(&c["zoomed"]) {
            " Zoomed to the contact zone."
        } else {
            ""
        };
        let cu = if truthy(&c["uniform"]) {
            " (uniform: colour scale widened to +-1%)"
        } else {
            ""
        };
        let total: Vec<String> = c["total"]
            .as_array()
            .map(|a| a.iter().map(|v| num(v.as_f64())).collect())
            .unwrap_or_default();
        format!(
            "the {} slave nodes in contact (stick or slip) as spheres coloured by the magnitude \
             of their nodal contact force (a force per node, normal and friction parts together, \
             not a pressure): {} to {}{cu}; their sum is ({}).{zoom}",
            c["nodes_in_contact"],
            num(f(&c["min"])),
            num(f(&c["max"])),
            total.join(", ")
        )
    } else {
        "no slave node is in contact at this step.".into()
    };
    out.push(format!("![{name}: contact]({})\n", base(&c["png"])));
    out.push(format!(
        "*{common}, translucent; {text}* (`{}`)\n",
        base(&c["png"])
    ));
    out
}

impl Paper {
    pub fn pictures(&self, d: &mut Doc, name: &str, render: &Render) {
        let info = [name.to_string(), format!("{name}.failed")]
            .iter()
            .filter_map(|stem| {
                std::fs::read_to_string(self.out.join(format!("{stem}.render.json"))).ok()
            })
            .find(|t| !t.is_empty())
            .and_then(|t| serde_json::from_str::<Value>(&t).ok());
        let Some(info) = info else {
            let why = if let Some(a) = &render.absent {
                a.clone()
            } else if render.rc == "0" {
                "no result to draw".into()
            } else {
                let mine: Vec<&str> = render
                    .errors
                    .iter()
                    .filter(|l| l.contains(name))
                    .map(String::as_str)
                    .collect();
                if mine.is_empty() {
                    format!(
                        "run/render failed (exit {}), see logs/render.log",
                        render.rc
                    )
                } else {
                    mine.join("; ")
                }
            };
            d.w(format!(
                "*ParaView pictures of `{name}`: not drawn: {why}.*\n"
            ));
            return;
        };
        for line in captions(name, &info) {
            d.w(line);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn captions_tell_the_step_the_warp_and_the_ranges() {
        let info: Value = serde_json::from_str(
            r#"{"time": 5.0, "step": 49, "steps": 50, "warp_scale": 20.0, "warp_scale_kind": "automatic",
            "max_displacement": 0.01, "diagonal": 3.0,
            "pictures": {"von_mises": {"png": "out/paper/capture_release.von_mises.png", "min": 49999.5, "max": 50000.5, "uniform": true},
                         "contact": {"png": "out/paper/capture_release.contact.png", "nodes_in_contact": 4,
                                     "min": 12500.0, "max": 12500.0, "uniform": true, "zoomed": false,
                                     "total": [0.0, 50000.0, 0.0]}}}"#,
        )
        .unwrap();
        let c = captions("capture_release", &info);
        assert_eq!(
            c[0],
            "![capture_release: von Mises stress](capture_release.von_mises.png)\n"
        );
        assert!(
            c[1].starts_with(
                "*ParaView (`run/render`), `capture_release` at its last step, t = 5 (step 50 of 50): \
                 the mesh warped by the displacement times 20 (automatic: the largest displacement, \
                 0.01, is drawn as 6.7% of the mesh's bounding-box diagonal; the scaling exaggerates"
            ),
            "{}",
            c[1]
        );
        assert!(c[1].ends_with("5e+04 to 5e+04 (uniform: colour scale widened to +-1%).* (`capture_release.von_mises.png`)\n"), "{}", c[1]);
        assert!(c[3].contains("the 4 slave nodes in contact"), "{}", c[3]);
        assert!(c[3].contains("their sum is (0, 50000, 0).*"), "{}", c[3]);
    }
}
