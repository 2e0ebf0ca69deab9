//! Output files written together: one job per file on the thread pool, each job making
//! its own picture from the planes, so the files of a command or a task are encoded side
//! by side and no picture outlives its encoding.

use std::time::Instant;

use rayon::prelude::*;

use crate::timings::Timings;

/// One output file's work.
type Work<'a> = Box<dyn FnOnce() -> Result<(), polar_io::Error> + Send + 'a>;

/// The output files to write, by name.
#[derive(Default)]
pub struct Writes<'a>(Vec<(&'static str, Work<'a>)>);

impl<'a> Writes<'a> {
    /// Adds the file `name`, written by `work`.
    pub fn push(
        &mut self,
        name: &'static str,
        work: impl FnOnce() -> Result<(), polar_io::Error> + Send + 'a,
    ) {
        self.0.push((name, Box::new(work)));
    }

    /// Writes every file in parallel; each one's wall time, or the first error.
    pub fn run(self) -> Result<Timings, polar_io::Error> {
        let took = self
            .0
            .into_par_iter()
            .map(|(name, work)| {
                let start = Instant::now();
                work().map(|()| (name, start.elapsed()))
            })
            .collect::<Result<Vec<_>, _>>()?;
        let mut timings = Timings::default();
        took.into_iter().for_each(|(name, t)| timings.push(name, t));
        Ok(timings)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use polar_image::Gray;

    #[test]
    fn every_file_is_written_and_the_first_error_is_returned() {
        let dir = tempfile::tempdir().unwrap();
        let image = Gray::from_vec(2, 1, vec![3u8, 250]).unwrap();
        let (a, b) = (dir.path().join("a.png"), dir.path().join("b.png"));
        let mut files = Writes::default();
        files.push("a", || polar_io::write_gray8_png(&a, &image));
        files.push("b", || polar_io::write_gray8_png(&b, &image));
        let line = files.run().unwrap().to_string();
        assert!(line.starts_with("a ") || line.starts_with("b "), "{line}");
        for path in [&a, &b] {
            assert_eq!(polar_io::read_gray8_png(path).unwrap(), image);
        }

        let missing = dir.path().join("no such folder").join("c.png");
        let mut files = Writes::default();
        files.push("a", || polar_io::write_gray8_png(&a, &image));
        files.push("c", || polar_io::write_gray8_png(&missing, &image));
        let err = files.run().unwrap_err().to_string();
        assert!(err.contains("c.png"), "{err}");
    }
}
