//! The study's series: which paper scene, how each series' error is read from
//! `solver post verify --json`, the refinements, tolerances and rank counts.

/// How a series' error is read from the verify report.
#[derive(Clone, Copy)]
pub enum Pick {
    /// The value of the check or reported quantity with exactly this name.
    Named(&'static str),
    /// The largest value among checks whose name contains this text.
    MaxContaining(&'static str),
}

pub struct Case {
    pub scene: &'static str,
    /// (series label, error norm as stated in the report, how to read it)
    pub series: &'static [(&'static str, &'static str, Pick)],
    pub factors: &'static [u32],
}

pub const CASES: &[Case] = &[
    Case {
        scene: "bc_interaction",
        series: &[(
            "bc_interaction (stick)",
            "max over nodes and steps of |u - exact| / d (d: the prescribed displacement)",
            Pick::Named("max |u - exact| / d"),
        )],
        factors: &[1, 2, 3, 4],
    },
    Case {
        scene: "capture_release",
        series: &[(
            "capture_release",
            "max over the contact-force and stress checks at t = 1, 2, 4, 5 of |error| / (E a / 2)",
            Pick::MaxContaining("/ (E a/2)"),
        )],
        factors: &[1, 2, 3, 4],
    },
    Case {
        scene: "stick_slip",
        series: &[
            (
                "stick_slip (loading)",
                "max over x and loading steps of |cross-section average u_x - 1-D formula| / u_max",
                Pick::Named("loading: max over x, t of |avg u_x - 1-D formula| / u_max"),
            ),
            (
                "stick_slip (unloading)",
                "max over x and unloading steps of |average u_x - superposition| / u_max",
                Pick::Named("unloading: max |avg u_x - superposition| / u_max"),
            ),
        ],
        factors: &[1, 2, 3, 4],
    },
    Case {
        scene: "multi_constraint",
        series: &[(
            "multi_constraint",
            "max over nodes of |u - exact| / max |u|",
            Pick::Named("max |u - exact| / max |u|"),
        )],
        factors: &[1, 2, 3, 4],
    },
    Case {
        scene: "multi_constraint_nonmatching",
        series: &[(
            "multi_constraint_nonmatching",
            "max over nodes of |u - exact| / max |u|",
            Pick::Named("max |u - exact| / max |u|"),
        )],
        factors: &[1, 2, 3, 4],
    },
];

pub const TOLERANCES: &[f64] = &[1e-5, 1e-7, 1e-9];
pub const RANKS: &[usize] = &[1, 2];

/// A check's or reported quantity's value by name.
pub fn value(report: &serde_json::Value, name: &str) -> Option<f64> {
    let checks = report["checks"].as_array()?;
    if let Some(c) = checks.iter().find(|c| c["name"] == name) {
        return c["value"].as_f64();
    }
    report["reported"]
        .as_array()?
        .iter()
        .find(|r| r[0] == name)
        .and_then(|r| r[1].as_f64())
}

pub fn pick_error(report: &serde_json::Value, pick: Pick) -> Option<f64> {
    match pick {
        Pick::Named(name) => value(report, name),
        Pick::MaxContaining(text) => report["checks"]
            .as_array()?
            .iter()
            .filter(|c| c["name"].as_str().is_some_and(|n| n.contains(text)))
            .filter_map(|c| c["value"].as_f64())
            .fold(None, |m: Option<f64>, v| Some(m.map_or(v, |m| m.max(v)))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const REPORT: &str = r#"{"checks": [
        {"name": "|contact force - E a/2| / (E a/2) at t = 1", "value": 1e-13, "limit": 1e-10, "pass": true},
        {"name": "max |sigma_yy + E a/2| / (E a/2) at t = 1", "value": 4e-13, "limit": 1e-10, "pass": true},
        {"name": "max |u(t=5) - u(t=1)| / max |u(t=1)|", "value": 9e-13, "limit": 1e-10, "pass": true}],
        "reported": [["CG iterations (total)", 13.0], ["wall time [s]", 0.05]]}"#;

    /// A named value comes from the checks first, then the reported quantities; the
    /// largest of the checks containing a text is taken, and only among the checks.
    #[test]
    fn errors_are_read_from_the_verify_report() {
        let r: serde_json::Value = serde_json::from_str(REPORT).unwrap();
        assert_eq!(value(&r, "CG iterations (total)"), Some(13.0));
        assert_eq!(
            value(&r, "max |u(t=5) - u(t=1)| / max |u(t=1)|"),
            Some(9e-13)
        );
        assert_eq!(value(&r, "missing"), None);
        assert_eq!(
            pick_error(&r, Pick::MaxContaining("/ (E a/2)")),
            Some(4e-13)
        );
        assert_eq!(pick_error(&r, Pick::MaxContaining("no such check")), None);
        assert_eq!(pick_error(&r, Pick::Named("wall time [s]")), Some(0.05));
    }

    /// Every series' error names one of its scene's verify quantities (checked by the
    /// scene kinds `solver post verify` knows).
    #[test]
    fn every_case_is_a_paper_scene() {
        for c in CASES {
            assert!(
                solver::post::verify::kind_of(c.scene).is_some(),
                "{}",
                c.scene
            );
            assert!(!c.series.is_empty() && c.factors.windows(2).all(|w| w[0] < w[1]));
        }
    }
}
