//! `polar-vision`: command-line front end of the polarization vision pipeline.

fn main() {}
