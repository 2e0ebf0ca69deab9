//! The polarization vision pipeline as a library: reading an observation ([`input`]), the
//! Stokes front end ([`stokes`]), the analysis tasks ([`tasks`]) run on one sample
//! ([`run`]) or a whole dataset ([`eval`]), and training learned models ([`train`]). The `polar-vision` binary is a thin shell over
//! these modules, one per subcommand.

pub mod cli;
pub mod error;
pub mod eval;
pub mod input;
pub mod out_dir;
pub mod pictures;
pub mod run;
pub mod stokes;
pub mod task_options;
pub mod tasks;
pub mod timings;
pub mod train;
pub mod writes;
