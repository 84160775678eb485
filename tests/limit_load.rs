//! Beyond a limit load the run stops and says so: a flat punch pressed by a traction that
//! rises to twice Prandtl's limit pressure (2 + pi) sigma_y / sqrt(3) into an
//! elastic-perfectly plastic block in plane strain (half model, symmetry at x = 0, one
//! element through the thickness with u_z = 0). No equilibrium exists past the block's limit
//! load: the run must end with a diagnosed stop that names the plastic body, the last
//! converged time and the region that flows, under the punch; never an endless solve.

use crate::common;
use common::punch::{self, A, L};

const SY: f64 = 100.0;
const N: usize = 10;
const P_MAX: f64 = 2.0 * 296.85;

fn scene() -> String {
    format!(
        "{}[[traction]]\nside_set = \"punch_face\"\nvector = [0.0, -1.0, 0.0]\nfunction = [[0.0, 0.0], [1.0, {P_MAX}]]\n\
         [time]\nsegments = [{{ end = 1.0, steps = 8 }}]\n[solver]\nmax_iterations = 2000\nmax_cutbacks = 4\n",
        punch::block(N, 200e3, 0.3, SY, "volumetric = \"mean_dilatation\"")
    )
}

#[test]
fn a_load_beyond_the_limit_stops_naming_the_flowing_region() {
    let p = common::problem(&scene());
    let (summary, _) = common::run_serial(&p, None);
    let failure = summary
        .failure
        .expect("a load of twice the limit load cannot be carried");
    println!("{failure}");
    assert!(
        failure.contains("a limit load of the plastic body 'block'"),
        "{failure}"
    );
    let after = |key: &str| -> f64 {
        let rest = &failure[failure
            .find(key)
            .unwrap_or_else(|| panic!("{key}: {failure}"))
            + key.len()..];
        rest.split([',', ' '])
            .next()
            .and_then(|v| v.parse().ok())
            .unwrap_or_else(|| panic!("{key}: {failure}"))
    };
    let prandtl = (2.0 + std::f64::consts::PI) * SY / 3f64.sqrt();
    let carried = after("the last converged state is t = ") * P_MAX;
    println!(
        "carried {carried:.2} = {:.3} of Prandtl's {prandtl:.2}",
        carried / prandtl
    );
    // A displacement-based mesh over-estimates the limit load (the kinematic theorem; the
    // prescribed punch at n = 40 levels off 7.7% above Prandtl's value, coarser meshes
    // higher), and the stop comes only once the attempts fail at the limit: so the pressure
    // carried is at least most of Prandtl's (0.9: the last cut-backs may stop short of the
    // discrete limit by a halving of the step) and below the 10 x 10 mesh's own over-estimate
    // (at most 1.4 times: n = 20 carried 1.03 of it with the same load path).
    assert!(
        (0.9 * prandtl..1.4 * prandtl).contains(&carried),
        "{carried} against Prandtl's {prandtl}"
    );
    // The flowing region is Prandtl's mechanism under the punch: it reaches the punch's
    // edge (x = a) at the top surface and stays within the block's upper part.
    let (x_hi, y_lo) = (after(" .. "), after(", y "));
    assert!((A..L).contains(&x_hi), "{failure}");
    assert!(y_lo > 0.5 * L, "{failure}");
}
