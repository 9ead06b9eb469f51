//! oceanbench: the uniprocessor vs dual-processor deep-ocean study of Reagin and Lake, as a
//! headless benchmark harness.

pub mod affinity;
pub mod balance;
pub mod bench_run;
pub mod calibrate;
pub mod camera;
pub mod cell;
pub mod cli;
pub mod commands;
pub mod config;
pub mod crosscore;
pub mod doctor;
pub mod findings;
pub mod frame_loop;
pub mod input;
pub mod latency;
pub mod lock;
pub mod machine;
pub mod measure;
pub mod named;
pub mod ocean;
pub mod placement;
pub mod projected;
pub mod publish;
pub mod registry;
pub mod report;
pub mod results;
pub mod sched;
pub mod slow_trials;
pub mod stats;
pub mod suggest;
pub mod sweep;
pub mod sync;
pub mod workload;
