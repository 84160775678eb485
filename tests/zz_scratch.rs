mod common;
use common::*;

#[test]
fn scratch() {
    let path = std::env::var("SCENE").unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let p = problem(&text);
    let (_, st) = solve(&p);
    let pz: f64 = std::env::var("P")
        .map(|v| v.parse().unwrap())
        .unwrap_or(1e3);
    let (e, nu) = (1e6, 0.3);
    let mut worst_s: f64 = 0.0;
    for s in &st.stress {
        // [xx,yy,zz,xy,yz,zx]
        let ex = [0.0, 0.0, -pz, 0.0, 0.0, 0.0];
        for i in 0..6 {
            worst_s = worst_s.max((s[i] - ex[i]).abs() / pz);
        }
    }
    let mut worst_u: f64 = 0.0;
    let mut umax: f64 = 0.0;
    for (n, x) in p.mesh.coords.iter().enumerate() {
        let ex = [nu * pz * x[0] / e, nu * pz * x[1] / e, -pz * x[2] / e];
        for i in 0..3 {
            worst_u = worst_u.max((st.displacement[n][i] - ex[i]).abs());
            umax = umax.max(ex[i].abs());
        }
    }
    println!("stress err {worst_s:.3e}  disp err {:.3e}", worst_u / umax);
}
