//! Formatting shared by the Markdown sections.

use crate::runner::solver::Compare;
use crate::stats::Stat;

/// `median [min, max]` with `digits` decimals.
pub fn fmt_stat(s: &Stat, digits: usize) -> String {
    format!(
        "{:.d$} [{:.d$}, {:.d$}]",
        s.median,
        s.min,
        s.max,
        d = digits
    )
}

/// Rates in millions with three significant-ish digits.
pub fn fmt_rate(s: &Stat) -> String {
    format!(
        "{:.3}e6 [{:.3}e6, {:.3}e6]",
        s.median / 1e6,
        s.min / 1e6,
        s.max / 1e6
    )
}

/// "yes", or why not, of a 1-against-2-rank comparison.
pub fn identity_text(compare: &Option<Result<Compare, String>>) -> String {
    match compare {
        Some(Ok(c)) if c.identical() => "yes".to_string(),
        Some(Ok(c)) => format!(
            "**no** (exit {}: {})",
            c.code.map_or("none".into(), |x| x.to_string()),
            c.summary
        ),
        Some(Err(e)) => format!("not compared: {e}"),
        None => "not compared (a run failed)".to_string(),
    }
}

/// A message as a table cell: `|` would end the cell.
pub fn cell(text: &str) -> String {
    text.replace('|', "/")
}

/// `x` with `digits` decimals, or "-".
pub fn fmt_opt(x: Option<f64>, digits: usize) -> String {
    x.map_or("-".into(), |x| format!("{x:.digits$}"))
}

/// " (with uncommitted changes)" when the tree was dirty.
pub fn dirty(git_dirty: Option<bool>) -> &'static str {
    if git_dirty == Some(true) {
        " (with uncommitted changes)"
    } else {
        ""
    }
}

/// The hypervisor's steal as a percentage, or "unknown".
pub fn fmt_steal(steal: Option<f64>) -> String {
    steal.map_or("unknown".to_string(), |x| format!("{:.1} %", 100.0 * x))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats() {
        let s = Stat::of(&[1.0, 2.0, 4.0]);
        assert_eq!(fmt_stat(&s, 2), "2.00 [1.00, 4.00]");
        assert_eq!(fmt_rate(&s.rate(1e7)), "5.000e6 [2.500e6, 10.000e6]");
        assert_eq!(fmt_opt(Some(1.25), 1), "1.2");
        assert_eq!(fmt_opt(None, 1), "-");
        assert_eq!(cell("a | b"), "a / b");
        assert_eq!(fmt_steal(Some(0.0123)), "1.2 %");
    }

    #[test]
    fn identity() {
        let same = Compare {
            code: Some(0),
            summary: "result: identical".into(),
        };
        let differ = Compare {
            code: Some(1),
            summary: "result: 3 datasets differ".into(),
        };
        assert_eq!(identity_text(&Some(Ok(same))), "yes");
        assert_eq!(
            identity_text(&Some(Ok(differ))),
            "**no** (exit 1: result: 3 datasets differ)"
        );
        assert_eq!(identity_text(&None), "not compared (a run failed)");
        assert_eq!(identity_text(&Some(Err("x".into()))), "not compared: x");
    }
}
