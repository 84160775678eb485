//! Other codes run on our problems beside us, each in its own module: the deck or input
//! it needs written from our scene, its runner and the parser of its output. A new peer
//! is a module here plus its line in the suite (`suite.rs`) and its report section
//! (`report/mod.rs`).

pub mod calculix;
