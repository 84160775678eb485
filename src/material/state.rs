//! The history one integration point keeps, and its size in a restart file.

/// The history of one integration point; all zero in a virgin point.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PlasticState {
    /// Plastic strain (small kinematics) or C_p^-1 - I (large kinematics), in the order
    /// xx yy zz xy yz zx (tensor components, not engineering shears).
    pub strain: [f64; 6],
    /// Back stress, same order.
    pub back: [f64; 6],
    /// Equivalent plastic strain, the integral of sqrt(2/3) |eps_p'|.
    pub eqps: f64,
}

/// Number of f64 one `PlasticState` is stored as (restart files).
pub const STATE_LEN: usize = 13;

impl PlasticState {
    pub fn to_array(&self) -> [f64; STATE_LEN] {
        let mut a = [0.0; STATE_LEN];
        a[..6].copy_from_slice(&self.strain);
        a[6..12].copy_from_slice(&self.back);
        a[12] = self.eqps;
        a
    }

    pub fn from_slice(a: &[f64]) -> Self {
        PlasticState {
            strain: std::array::from_fn(|i| a[i]),
            back: std::array::from_fn(|i| a[6 + i]),
            eqps: a[12],
        }
    }
}
