//! Numbers and text for the reports: the formats the reports have always used (Python's
//! `{:.3e}`, `{:.4g}`, `{:.2g}`: a two-digit signed exponent, trailing zeros dropped), table
//! cells, and the padded Markdown table.

/// `v` in `{:.Pe}` with Python's exponent (`1.234e-05`, `1.000e+06`; `inf`, `nan`).
pub fn sci(v: f64, prec: usize) -> String {
    if !v.is_finite() {
        return nonfinite(v);
    }
    let s = format!("{v:.prec$e}");
    let (mant, exp) = s.split_once('e').expect("Rust's {:e} has an exponent");
    let e: i32 = exp.parse().expect("Rust's exponent is an integer");
    format!("{mant}e{}{:02}", if e < 0 { '-' } else { '+' }, e.abs())
}

fn nonfinite(v: f64) -> String {
    if v.is_nan() {
        "nan".into()
    } else if v > 0.0 {
        "inf".into()
    } else {
        "-inf".into()
    }
}

/// `v` in Python's general format `{:.Pg}`: `P` significant digits, exponential when the
/// rounded exponent is below -4 or at least `P`, trailing zeros removed.
pub fn general(v: f64, prec: usize) -> String {
    if !v.is_finite() {
        return nonfinite(v);
    }
    let p = prec.max(1);
    if v == 0.0 {
        return if v.is_sign_negative() { "-0" } else { "0" }.into();
    }
    let s = format!("{v:.*e}", p - 1);
    let (mant, exp) = s.split_once('e').expect("Rust's {:e} has an exponent");
    let e: i32 = exp.parse().expect("Rust's exponent is an integer");
    if e < -4 || e >= p as i32 {
        let m = strip_zeros(mant);
        format!("{m}e{}{:02}", if e < 0 { '-' } else { '+' }, e.abs())
    } else {
        let decimals = (p as i32 - 1 - e).max(0) as usize;
        strip_zeros(&format!("{v:.decimals$}")).to_string()
    }
}

fn strip_zeros(s: &str) -> &str {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        s
    }
}

/// A number for the reports: integers plainly, others in 4 significant digits (3 decimals
/// of an exponent below 1e-3 and from 1e5 on); `-` for none.
pub fn num(v: Option<f64>) -> String {
    let Some(v) = v else { return "-".into() };
    if v.is_finite() && v.fract() == 0.0 && v.abs() < 1e12 {
        return format!("{}", v as i64);
    }
    if v != 0.0 && (v.abs() < 1e-3 || v.abs() >= 1e5) {
        return sci(v, 3);
    }
    general(v, 4)
}

/// [`num`] of a value that is there.
pub fn n(v: f64) -> String {
    num(Some(v))
}

/// Text for a Markdown table cell.
pub fn cell(s: &str) -> String {
    s.replace('|', "\\|").replace('\n', " ")
}

/// Inline code.
pub fn code(s: &str) -> String {
    format!("`{}`", s.replace('`', "'"))
}

/// A Markdown table with every column padded to its widest cell (in characters).
pub fn table(header: &[&str], rows: &[Vec<String>]) -> String {
    let widths: Vec<usize> = header
        .iter()
        .enumerate()
        .map(|(i, h)| {
            rows.iter()
                .map(|r| r[i].chars().count())
                .fold(h.chars().count(), usize::max)
        })
        .collect();
    let line = |cells: Vec<&str>| {
        let padded: Vec<String> = cells
            .iter()
            .zip(&widths)
            .map(|(c, &w)| format!("{c}{}", " ".repeat(w - c.chars().count())))
            .collect();
        format!("| {} |", padded.join(" | "))
    };
    let mut out = vec![line(header.to_vec())];
    let rule: Vec<String> = widths.iter().map(|w| "-".repeat(w + 2)).collect();
    out.push(format!("|{}|", rule.join("|")));
    out.extend(
        rows.iter()
            .map(|r| line(r.iter().map(String::as_str).collect())),
    );
    out.join("\n")
}

/// The lines of a report being written (joined with newlines).
#[derive(Default)]
pub struct Doc(pub Vec<String>);

impl Doc {
    pub fn w(&mut self, s: impl Into<String>) {
        self.0.push(s.into());
    }

    pub fn text(&self) -> String {
        self.0.join("\n").trim_end().to_string() + "\n"
    }
}

/// The integer `N` of the first `<before>N<after>` in `text`.
pub fn number_between(text: &str, before: &str, after: &str) -> Option<u64> {
    let mut from = 0;
    while let Some(i) = text[from..].find(before) {
        let start = from + i + before.len();
        let digits: String = text[start..]
            .chars()
            .take_while(char::is_ascii_digit)
            .collect();
        if !digits.is_empty() && text[start + digits.len()..].starts_with(after) {
            return digits.parse().ok();
        }
        from = start;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The expected strings are Python's own output for the same values.
    #[test]
    fn numbers_read_as_python_wrote_them() {
        assert_eq!(sci(1.2345e-5, 3), "1.234e-05"); // 1.2345e-5 is below the tie in binary
        assert_eq!(sci(2.647e-13, 3), "2.647e-13");
        assert_eq!(sci(123456.0, 3), "1.235e+05");
        assert_eq!(sci(f64::INFINITY, 3), "inf");
        assert_eq!(general(0.05565, 4), "0.05565");
        assert_eq!(general(12345.6, 4), "1.235e+04");
        assert_eq!(general(9999.96, 4), "1e+04");
        assert_eq!(general(0.5, 4), "0.5");
        assert_eq!(general(4.25, 2), "4.2");
        assert_eq!(general(0.00012, 2), "0.00012");
        assert_eq!(general(0.000012, 2), "1.2e-05");
        assert_eq!(num(None), "-");
        assert_eq!(num(Some(124.0)), "124");
        assert_eq!(num(Some(-0.0)), "0");
        assert_eq!(num(Some(1.0e12)), "1.000e+12");
        assert_eq!(num(Some(0.0929812)), "0.09298");
        assert_eq!(num(Some(1.3552527156068805e-17)), "1.355e-17");
        assert_eq!(num(Some(f64::NAN)), "nan");
        assert_eq!(num(Some(f64::NEG_INFINITY)), "-inf");
        assert_eq!(num(Some(2.5)), "2.5");
    }

    #[test]
    fn table_pads_by_characters_and_escapes_cells() {
        let t = table(&["a", "bb"], &[vec!["x°".into(), cell("p|q")]]);
        assert_eq!(t, "| a  | bb   |\n|----|------|\n| x° | p\\|q |");
        assert_eq!(code("a`b"), "`a'b`");
    }
}
