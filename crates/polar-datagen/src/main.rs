//! `polar-datagen`: command-line front end (see `--help`).

fn main() {}
