//! Lu–Chipman polar decomposition `M = M_Δ · M_R · M_D` (S.-Y. Lu and
//! R. A. Chipman, "Interpretation of Mueller matrices based on polar
//! decomposition", JOSA A 13(5), 1106–1113, 1996).

use crate::error::OpticsError;
use crate::mueller::Mueller;
use nalgebra::{Matrix3, Vector3};

/// The three factors of a Lu–Chipman decomposition.
#[derive(Clone, Debug, PartialEq)]
pub struct LuChipman {
    /// `M_Δ = [[1, 0ᵀ], [P_Δ, m_Δ]]`, `m_Δ` symmetric: depolarizer (with polarizance `P_Δ`).
    pub depolarizer: Mueller,
    /// `M_R = [[1, 0ᵀ], [0, m_R]]`, `m_R ∈ SO(3)`: pure retarder.
    pub retarder: Mueller,
    /// `M_D = T_u [[1, Dᵀ], [D, m_D]]`: diattenuator carrying the unpolarized transmittance `T_u = m00`.
    pub diattenuator: Mueller,
}

impl LuChipman {
    /// `M_Δ · M_R · M_D`, which reproduces the decomposed matrix.
    pub fn product(&self) -> Mueller {
        self.depolarizer * self.retarder * self.diattenuator
    }

    /// Diattenuation `|D| = sqrt(m01² + m02² + m03²) / m00` in `[0, 1)`.
    pub fn diattenuation(&self) -> f64 {
        let m = &self.diattenuator;
        m[(0, 1)].hypot(m[(0, 2)]).hypot(m[(0, 3)]) / m[(0, 0)]
    }

    /// Total retardance `R = acos(tr(M_R)/2 − 1)` in `[0, π]`.
    pub fn retardance(&self) -> f64 {
        (0.5 * self.retarder.trace() - 1.0).clamp(-1.0, 1.0).acos()
    }

    /// Depolarization power `Δ = 1 − |tr(m_Δ)| / 3` (0: none, 1: total).
    pub fn depolarization_power(&self) -> f64 {
        1.0 - self.depolarizer.fixed_view::<3, 3>(1, 1).trace().abs() / 3.0
    }
}

/// Diattenuations closer to 1 than this make `M_D` numerically singular.
const MAX_DIATTENUATION: f64 = 1.0 - 1e-9;
/// `|det m_Δ|` below this leaves the retarder undetermined.
const MIN_DET: f64 = 1e-12;

/// Decomposes `m` as `M_Δ · M_R · M_D` following Lu & Chipman (1996):
/// 1. `D = (m01, m02, m03)/m00`, `m_D = sqrt(1−D²) I + (1 − sqrt(1−D²)) D̂D̂ᵀ`;
/// 2. `M' = M M_D⁻¹ = M_Δ M_R`, `m'` its lower 3×3, `P_Δ` its first column below m00;
/// 3. with `λᵢ` the eigenvalues of `m' m'ᵀ`,
///    `m_Δ = ±[m'm'ᵀ + (√λ1λ2 + √λ2λ3 + √λ3λ1) I]⁻¹ [(√λ1 + √λ2 + √λ3) m'm'ᵀ + √λ1λ2λ3 I]`,
///    sign of `det m'`;
/// 4. `m_R = m_Δ⁻¹ m'`.
///
/// Errors: non-finite entries, `m00 ≤ 0`, diattenuation `≥ 1 − 1e-9` (an ideal
/// polarizer's `M_D` has no inverse), or a singular `m_Δ` (e.g. a total
/// depolarizer, whose retarder is undetermined).
pub fn lu_chipman(m: &Mueller) -> Result<LuChipman, OpticsError> {
    if let Some((index, &value)) = m.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(OpticsError::NonFinite {
            what: "mueller (column-major)",
            index,
            value,
        });
    }
    let tu = m[(0, 0)];
    if tu.is_nan() || tu <= 0.0 {
        return Err(OpticsError::OutOfRange {
            name: "m00",
            value: tu,
            expected: "(0, inf)",
        });
    }
    let diattenuator = diattenuator(tu, &(m.fixed_view::<1, 3>(0, 1).transpose() / tu))?;
    let inv = diattenuator.try_inverse().ok_or(OpticsError::Singular {
        reason: "diattenuator not invertible",
        value: tu,
    })?;
    let mp = m * inv;
    let m_prime: Matrix3<f64> = mp.fixed_view::<3, 3>(1, 1).into_owned();
    let m_delta = depolarizer_block(&m_prime)?;
    let det = m_delta.determinant();
    let m_delta_inv = m_delta
        .try_inverse()
        .filter(|_| det.abs() >= MIN_DET)
        .ok_or(OpticsError::Singular {
            reason: "depolarizer block singular, retarder undetermined",
            value: det,
        })?;
    let mut depolarizer = Mueller::identity();
    depolarizer
        .fixed_view_mut::<3, 1>(1, 0)
        .copy_from(&mp.fixed_view::<3, 1>(1, 0));
    depolarizer.fixed_view_mut::<3, 3>(1, 1).copy_from(&m_delta);
    let mut retarder = Mueller::identity();
    retarder
        .fixed_view_mut::<3, 3>(1, 1)
        .copy_from(&(m_delta_inv * m_prime));
    Ok(LuChipman {
        depolarizer,
        retarder,
        diattenuator,
    })
}

/// `M_D = T_u [[1, Dᵀ], [D, m_D]]` for diattenuation vector `d` (|d| < 1).
fn diattenuator(tu: f64, d: &Vector3<f64>) -> Result<Mueller, OpticsError> {
    let dn = d.norm();
    if dn >= MAX_DIATTENUATION {
        return Err(OpticsError::Singular {
            reason: "diattenuation reaches 1",
            value: dn,
        });
    }
    let s = (1.0 - dn * dn).sqrt();
    let m_d = if dn > 0.0 {
        let u = d / dn;
        Matrix3::identity() * s + u * u.transpose() * (1.0 - s)
    } else {
        Matrix3::identity()
    };
    let mut out = Mueller::identity();
    out.fixed_view_mut::<1, 3>(0, 1).copy_from(&d.transpose());
    out.fixed_view_mut::<3, 1>(1, 0).copy_from(d);
    out.fixed_view_mut::<3, 3>(1, 1).copy_from(&m_d);
    Ok(out * tu)
}

/// The symmetric depolarizer block `m_Δ` of `m' = m_Δ m_R` (step 3 above).
fn depolarizer_block(m_prime: &Matrix3<f64>) -> Result<Matrix3<f64>, OpticsError> {
    let mmt = m_prime * m_prime.transpose();
    let l = mmt.symmetric_eigenvalues().map(|v| v.max(0.0).sqrt());
    let k1 = l.sum();
    let k2 = l[0] * l[1] + l[1] * l[2] + l[2] * l[0];
    let k3 = l[0] * l[1] * l[2];
    let lhs = (mmt + Matrix3::identity() * k2)
        .try_inverse()
        .ok_or(OpticsError::Singular {
            reason: "m' m'^T + k2 I not invertible",
            value: k2,
        })?;
    let sign = if m_prime.determinant() < 0.0 {
        -1.0
    } else {
        1.0
    };
    Ok(lhs * (mmt * k1 + Matrix3::identity() * k3) * sign)
}
