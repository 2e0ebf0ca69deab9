//! Wall time of a command's stages, for `--timings`: where the time a user waits goes.

use std::fmt;
use std::time::{Duration, Instant};

/// The named stages of one command with their wall times, in the order they ran.
#[derive(Clone, Debug, Default)]
pub struct Timings(Vec<(String, Duration)>);

impl Timings {
    /// Runs `stage`, recording its wall time under `name`.
    pub fn time<T>(&mut self, name: &str, stage: impl FnOnce() -> T) -> T {
        let start = Instant::now();
        let out = stage();
        self.push(name, start.elapsed());
        out
    }

    /// Records a stage timed elsewhere (e.g. on another thread).
    pub fn push(&mut self, name: &str, took: Duration) {
        self.0.push((name.to_owned(), took));
    }

    /// Appends `other`'s stages after this one's.
    pub fn extend(&mut self, other: Timings) {
        self.0.extend(other.0);
    }
}

/// `name 12.3 ms, name 4.5 ms, ...`
impl fmt::Display for Timings {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (k, (name, took)) in self.0.iter().enumerate() {
            let sep = if k == 0 { "" } else { ", " };
            write!(f, "{sep}{name} {:.1} ms", took.as_secs_f64() * 1e3)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stages_print_in_order_with_their_times() {
        let mut t = Timings::default();
        let v = t.time("read", || 7);
        t.push("write", Duration::from_micros(2500));
        assert_eq!(v, 7);
        let line = t.to_string();
        assert!(line.starts_with("read "), "{line}");
        assert!(line.ends_with(", write 2.5 ms"), "{line}");
    }
}
