//! Piecewise-linear functions of time.

/// A piecewise-linear function through points (t_i, v_i), t strictly increasing, held
/// constant before the first and after the last point.
#[derive(serde::Serialize, serde::Deserialize, Clone, Debug, PartialEq)]
pub struct PiecewiseLinear {
    points: Vec<(f64, f64)>,
}

impl PiecewiseLinear {
    pub fn constant(v: f64) -> Self {
        PiecewiseLinear {
            points: vec![(0.0, v)],
        }
    }

    /// Points must be non-empty with strictly increasing times (checked by the scene layer).
    pub fn new(points: Vec<(f64, f64)>) -> Self {
        debug_assert!(!points.is_empty());
        PiecewiseLinear { points }
    }

    pub fn eval(&self, t: f64) -> f64 {
        let p = &self.points;
        if t <= p[0].0 {
            return p[0].1;
        }
        for w in p.windows(2) {
            let (t0, v0) = w[0];
            let (t1, v1) = w[1];
            if t <= t1 {
                if t == t1 {
                    return v1;
                }
                let s = (t - t0) / (t1 - t0);
                return v0 + s * (v1 - v0);
            }
        }
        p[p.len() - 1].1
    }

    /// The times of the points (where the function may change slope).
    pub fn times(&self) -> impl Iterator<Item = f64> + '_ {
        self.points.iter().map(|p| p.0)
    }

    pub fn max_abs(&self) -> f64 {
        self.points.iter().fold(0.0, |m, &(_, v)| m.max(v.abs()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolates_and_holds() {
        let f = PiecewiseLinear::new(vec![(0.0, 0.0), (1.0, -1.0), (2.0, 0.0)]);
        assert_eq!(f.eval(-1.0), 0.0);
        assert_eq!(f.eval(0.5), -0.5);
        assert_eq!(f.eval(1.0), -1.0);
        assert_eq!(f.eval(1.5), -0.5);
        assert_eq!(f.eval(3.0), 0.0);
        assert_eq!(f.max_abs(), 1.0);
    }
}
