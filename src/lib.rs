//! oceanbench: the uniprocessor vs dual-processor deep-ocean study of Reagin and Lake, as a
//! headless benchmark harness.

pub mod affinity;
pub mod config;
pub mod crosscore;
pub mod frame_loop;
pub mod machine;
pub mod measure;
pub mod ocean;
pub mod results;
pub mod sync;
pub mod workload;
