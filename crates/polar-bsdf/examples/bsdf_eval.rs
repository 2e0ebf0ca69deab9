//! Evaluates BSDFs for an external cross-check (`tools/bsdf_crosscheck.py`).
//!
//! Reads a JSON array from stdin; each item is
//! `{"material": "<TOML table>", "wo": [x, y, z], "wi": [x, y, z]}` for `eval`, or
//! `{"material": ..., "wo": [...], "u": [u0, u1, u2]}` for `sample`. Writes a JSON
//! array of `{"m": [16 numbers, row-major], "wi": [...]}`: the `eval` matrix, or
//! the sampled `wi` with `weight × pdf` (a delta lobe's matrix). No sample gives
//! a zero matrix.

use nalgebra::Vector3;
use polar_bsdf::Material;
use serde_json::{Value, json};
use std::io::Read;

fn vector(v: &Value) -> Option<Vector3<f64>> {
    let a: Vec<f64> = serde_json::from_value(v.clone()).ok()?;
    (a.len() == 3).then(|| Vector3::new(a[0], a[1], a[2]))
}

fn run(case: &Value) -> Result<Value, String> {
    let text = case["material"].as_str().ok_or("missing `material`")?;
    let material: Material = toml::from_str(text).map_err(|e| e.to_string())?;
    material.validate().map_err(|e| e.to_string())?;
    let bsdf = material.bsdf([0.5, 0.5]);
    let wo = vector(&case["wo"]).ok_or("bad `wo`")?;
    let (m, wi) = if let Some(wi) = vector(&case["wi"]) {
        (bsdf.eval(&wo, &wi), wi)
    } else {
        let u: [f64; 3] = serde_json::from_value(case["u"].clone()).map_err(|e| e.to_string())?;
        match bsdf.sample(&wo, u) {
            Some(s) => (s.weight * s.pdf, s.wi),
            None => (polar_optics::Mueller::zeros(), Vector3::zeros()),
        }
    };
    let rows: Vec<f64> = m.transpose().iter().copied().collect();
    Ok(json!({ "m": rows, "wi": [wi.x, wi.y, wi.z] }))
}

fn main() -> Result<(), String> {
    let mut input = String::new();
    std::io::stdin()
        .read_to_string(&mut input)
        .map_err(|e| e.to_string())?;
    let cases: Vec<Value> = serde_json::from_str(&input).map_err(|e| e.to_string())?;
    let out = cases.iter().map(run).collect::<Result<Vec<_>, _>>()?;
    println!("{}", Value::Array(out));
    Ok(())
}
