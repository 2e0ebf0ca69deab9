//! Helpers shared by the integration tests (and, by path, the `demosaic_error` example).

pub mod demosaic_eval;
