//! Prints Mie efficiencies and normalised plane elements (series and table) as one JSON
//! object per sphere, for `tools/mie_check.py` to compare with miepython.
//!
//! Usage: `cargo run --release -p polar-optics --example mie_values -- x,n,k [x,n,k ...]`
//! (relative index `n + ik`). Tables are built for `x ≤ 1000` only (larger ones take
//! seconds); `cos θ` runs over 0°, 0.1°, 0.5°, 1°, 2°, …, 180°.

use num_complex::Complex64;
use polar_optics::scatter::{MieCoefficients, MieTable, PlaneElements};
use std::process::ExitCode;

fn main() -> ExitCode {
    let mut angles = vec![0.0, 0.1, 0.5];
    angles.extend((1..=180).map(f64::from));
    for arg in std::env::args().skip(1) {
        let parts: Vec<f64> = arg.split(',').filter_map(|p| p.parse().ok()).collect();
        let &[x, n, k] = parts.as_slice() else {
            eprintln!("expected x,n,k, got {arg:?}");
            return ExitCode::FAILURE;
        };
        let m = Complex64::new(n, k);
        let series = match MieCoefficients::new(x, m) {
            Ok(s) => s,
            Err(e) => {
                eprintln!("{arg}: {e}");
                return ExitCode::FAILURE;
            }
        };
        let table = (x <= 1000.0).then(|| MieTable::new(x, m).ok()).flatten();
        let mu: Vec<f64> = angles.iter().map(|a: &f64| a.to_radians().cos()).collect();
        let elements = |f: &dyn Fn(f64) -> PlaneElements| {
            let rows: Vec<String> = mu
                .iter()
                .map(|&c| {
                    let e = f(c);
                    format!("[{:e},{:e},{:e},{:e}]", e.s11, e.s12, e.s33, e.s34)
                })
                .collect();
            format!("[{}]", rows.join(","))
        };
        let table_json = match &table {
            Some(t) => elements(&|c| t.plane_elements(c)),
            None => "null".to_string(),
        };
        let list = |v: &[f64]| {
            let items: Vec<String> = v.iter().map(|a| format!("{a:e}")).collect();
            format!("[{}]", items.join(","))
        };
        println!(
            "{{\"x\":{x:e},\"n\":{n:e},\"k\":{k:e},\"q_ext\":{:e},\"q_sca\":{:e},\"q_back\":{:e},\"g\":{:e},\"angles\":{},\"series\":{},\"table\":{}}}",
            series.q_ext(),
            series.q_sca(),
            series.q_back(),
            series.asymmetry(),
            list(&angles),
            elements(&|c| series.plane_elements(c)),
            table_json
        );
    }
    ExitCode::SUCCESS
}
