//! The noise settings a user writes for a sensor (a scene file's `[sensor]` table, a
//! suite's `[[noise]]` levels), with the bounds every writer of them is checked against.

use serde::Deserialize;

/// Sensor noise settings as a scene file's `[sensor]` table gives them; an absent key
/// takes the value of the reader's default sensor (the IMX250MZR preset in
/// `polar-datagen`). Parsing refuses unknown keys; [`Self::check`] checks the bounds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorSettings {
    /// Full-well capacity in electrons, at least 1.
    pub full_well_e: Option<f64>,
    /// Gaussian read noise in electrons RMS, at least 0.
    pub read_noise_e: Option<f64>,
    /// ADC bit depth of the raw mosaic, 8 to 16.
    pub bits: Option<u8>,
    /// Poisson photon shot noise on or off.
    pub shot_noise: Option<bool>,
    /// Micro-polarizer extinction ratio `T_max / T_min`, at least 1.
    pub extinction_ratio: Option<f64>,
}

impl SensorSettings {
    /// Checks the values given against their bounds; the message names the key as the
    /// user wrote it (e.g. `bits = 0 must be in 8..=16`).
    pub fn check(&self) -> Result<(), String> {
        if let Some(fw) = self.full_well_e.filter(|v| !(v.is_finite() && *v >= 1.0)) {
            return Err(format!("full_well_e = {fw} must be >= 1 electron"));
        }
        if let Some(er) = self.extinction_ratio.filter(|er| er.is_nan() || *er < 1.0) {
            return Err(format!("extinction_ratio = {er} must be >= 1"));
        }
        if let Some(rn) = self.read_noise_e.filter(|v| !(v.is_finite() && *v >= 0.0)) {
            return Err(format!("read_noise_e = {rn} must be >= 0"));
        }
        if let Some(bits) = self.bits.filter(|b| !(8..=16).contains(b)) {
            return Err(format!("bits = {bits} must be in 8..=16"));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each bound refuses the first value past it and accepts the bound itself, and the
    /// message names the user's key; an empty table (every key absent) is valid.
    #[test]
    fn check_holds_each_bound_and_names_the_key() {
        let ok = SensorSettings {
            full_well_e: Some(1.0),
            read_noise_e: Some(0.0),
            bits: Some(8),
            shot_noise: Some(true),
            extinction_ratio: Some(1.0),
        };
        assert_eq!(ok.check(), Ok(()));
        assert_eq!(SensorSettings::default().check(), Ok(()));
        let cases = [
            (
                SensorSettings {
                    full_well_e: Some(0.5),
                    ..ok
                },
                "full_well_e = 0.5",
            ),
            (
                SensorSettings {
                    full_well_e: Some(f64::INFINITY),
                    ..ok
                },
                "full_well_e = inf",
            ),
            (
                SensorSettings {
                    read_noise_e: Some(-0.1),
                    ..ok
                },
                "read_noise_e = -0.1",
            ),
            (
                SensorSettings {
                    bits: Some(17),
                    ..ok
                },
                "bits = 17",
            ),
            (
                SensorSettings {
                    bits: Some(7),
                    ..ok
                },
                "bits = 7",
            ),
            (
                SensorSettings {
                    extinction_ratio: Some(0.9),
                    ..ok
                },
                "extinction_ratio = 0.9",
            ),
            (
                SensorSettings {
                    extinction_ratio: Some(f64::NAN),
                    ..ok
                },
                "extinction_ratio = NaN",
            ),
        ];
        for (settings, key) in cases {
            let err = settings.check().unwrap_err();
            assert!(err.starts_with(key), "{err}");
        }
    }

    /// Unknown keys are refused by name.
    #[test]
    fn unknown_keys_are_refused() {
        let err = serde_json::from_str::<SensorSettings>(r#"{"bitz": 12}"#).unwrap_err();
        assert!(err.to_string().contains("bitz"), "{err}");
    }
}
