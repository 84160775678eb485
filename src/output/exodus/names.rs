//! The Exodus II names this solver writes: dimensions and variables of the netCDF file as
//! the Exodus II library defines them (Sandia's "Exodus II: A Finite Element Data Model",
//! netCDF mapping), and the result variables (README "Exodus II").

/// Bytes per name (`len_name`): 32 characters and a NUL, Exodus's default.
pub const LEN_NAME: usize = 33;
/// Bytes per QA/info line (`len_line`).
pub const LEN_LINE: usize = 81;

/// Nodal variables, in file order; `contact_pressure` is left out for a result file that
/// has none.
pub const NODAL_VARIABLES: [&str; 12] = [
    "displ_x",
    "displ_y",
    "displ_z",
    "reaction_x",
    "reaction_y",
    "reaction_z",
    "contact_force_x",
    "contact_force_y",
    "contact_force_z",
    "contact_status",
    "contact_gap",
    "contact_pressure",
];

/// Element variables, in file order; `eqps` only when a body is plastic.
pub const ELEMENT_VARIABLES: [&str; 7] = [
    "stress_xx",
    "stress_yy",
    "stress_zz",
    "stress_xy",
    "stress_yz",
    "stress_zx",
    "eqps",
];

/// Global variables, one value per step (the HDF5 file's `/stats` without the wall time,
/// which differs between runs).
pub const GLOBAL_VARIABLES: [&str; 9] = [
    "cg_iterations",
    "contact_updates",
    "residual",
    "cutbacks",
    "contact_active",
    "contact_stick",
    "contact_slip",
    "contact_released",
    "max_penetration",
];

pub fn num_el_in_blk(b: usize) -> String {
    format!("num_el_in_blk{}", b + 1)
}
pub fn num_nod_per_el(b: usize) -> String {
    format!("num_nod_per_el{}", b + 1)
}
pub fn connect(b: usize) -> String {
    format!("connect{}", b + 1)
}
pub fn num_nod_ns(s: usize) -> String {
    format!("num_nod_ns{}", s + 1)
}
pub fn node_ns(s: usize) -> String {
    format!("node_ns{}", s + 1)
}
pub fn num_side_ss(s: usize) -> String {
    format!("num_side_ss{}", s + 1)
}
pub fn elem_ss(s: usize) -> String {
    format!("elem_ss{}", s + 1)
}
pub fn side_ss(s: usize) -> String {
    format!("side_ss{}", s + 1)
}
pub fn vals_nod_var(v: usize) -> String {
    format!("vals_nod_var{}", v + 1)
}
pub fn vals_elem_var(v: usize, b: usize) -> String {
    format!("vals_elem_var{}eb{}", v + 1, b + 1)
}
