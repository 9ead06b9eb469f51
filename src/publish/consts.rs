//! Constants of the code that the docs quote, by name: a `const` block renders one, so a doc
//! that quotes a default or a threshold is checked against the code like any measured number.

use super::blocks::Block;
use crate::cell::Dim;
use crate::config::SweepConfig;
use std::path::Path;

/// Every constant a doc may quote: its name, what it is, and its value as docs write it.
pub fn all() -> Vec<(&'static str, &'static str, String)> {
    let config = SweepConfig::default();
    let fft_defaults = crate::ocean::phillips::FftParams::default();
    let balance_defaults = crate::config::BalanceSettings::default();
    let list = |dim: Dim| {
        config
            .axes
            .values(dim)
            .iter()
            .map(|v| v.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    };
    vec![
        (
            "default_sizes",
            "the default sweep's mesh sizes",
            list(Dim::Size),
        ),
        (
            "default_sync",
            "the default sweep's hand-off methods",
            list(Dim::Sync),
        ),
        (
            "default_trials",
            "trials per cell by default",
            config.trials.to_string(),
        ),
        (
            "spread_percent",
            "a cell's trial spread above which a number from it says so",
            format!("{}", crate::findings::SPREAD_PERCENT),
        ),
        (
            "flat_percent",
            "how far DP may move from its lowest level's FPS and still count as flat",
            format!("{}", crate::findings::FLAT_PERCENT),
        ),
        (
            "slow_trial_percent",
            "how far below its cell's median a trial counts as slow, by default",
            format!("{}", crate::slow_trials::DEFAULT_THRESHOLD_PERCENT),
        ),
        (
            "placement_change_ratio",
            "round trips further apart than this ratio are two placements",
            format!("{}", crate::crosscore::PLACEMENT_CHANGE_RATIO),
        ),
        (
            "compare_threshold_percent",
            "compare's default threshold",
            format!("{}", crate::report::compare::DEFAULT_THRESHOLD_PCT),
        ),
        (
            "compare_min_trials",
            "trials a side compare needs for a verdict",
            crate::report::compare::MIN_TRIALS.to_string(),
        ),
        (
            "latency_repeats",
            "the repeats `oceanbench latency` measures by default",
            crate::results::latency::DEFAULT_REPEATS.to_string(),
        ),
        (
            "max_depth",
            "the deepest run-ahead ring",
            crate::frame_loop::MAX_DEPTH.to_string(),
        ),
        (
            "max_helpers",
            "the most helper threads",
            crate::frame_loop::MAX_HELPERS.to_string(),
        ),
        (
            "trace_ticks_per_us",
            "the ticks per µs a trace's timestamps are whole numbers of",
            crate::trace::TICKS_PER_US.to_string(),
        ),
        (
            "schema_version",
            "the results.json layout this build writes",
            crate::results::SCHEMA_VERSION.to_string(),
        ),
        (
            "min_depth",
            "the shallowest run-ahead ring (the paper's loop)",
            depths(crate::frame_loop::Threading::Pool)
                .next()
                .expect("some depth runs")
                .to_string(),
        ),
        (
            "spawn_max_depth",
            "the deepest ring a helper spawned per frame can run",
            depths(crate::frame_loop::Threading::Spawn)
                .last()
                .expect("some depth runs")
                .to_string(),
        ),
        (
            "camera_max_pitch",
            "the most pitch a camera takes, in degrees (straight down)",
            format!("{}", crate::camera::MAX_PITCH),
        ),
        (
            "camera_max_fov",
            "the field of view a camera stays below, in degrees",
            format!("{}", crate::camera::MAX_FOV),
        ),
        (
            "camera_max_aspect",
            "the widest aspect ratio a camera takes",
            format!("{}", crate::camera::MAX_ASPECT),
        ),
        (
            "camera_max_distance",
            "the most camera height, far distance and path radius, in world units",
            format!("{}", crate::camera::MAX_HEIGHT),
        ),
        (
            "camera_far_patches",
            "the default far distance, in patch widths",
            format!("{}", crate::camera::FAR_PATCHES),
        ),
        (
            "camera_default_pitch",
            "the default camera's pitch, in degrees",
            format!("{}", crate::camera::Camera::default().pitch_degrees),
        ),
        (
            "camera_default_fov",
            "the default camera's field of view, in degrees",
            format!("{}", crate::camera::Camera::default().fov_degrees),
        ),
        (
            "camera_default_path_period",
            "seconds per turn of a camera path given by its radius alone (--path-radius)",
            format!("{}", default_path_period()),
        ),
        // fft (docs/fft-ocean.md, docs/balance.md):
        (
            "fft_strip_columns",
            "columns per strip of the FFT ocean's row pass",
            crate::ocean::fft::transform::STRIP.to_string(),
        ),
        (
            "fft_stream_field_mib",
            "the field size, in MiB, from which the FFT ocean's row pass writes its strips with non-temporal stores",
            (crate::ocean::fft::stream::STREAM_FIELD_BYTES >> 20).to_string(),
        ),
        (
            "fft_default_patch_metres",
            "the FFT ocean's default patch side L, in metres",
            format!("{}", fft_defaults.patch_metres),
        ),
        (
            "fft_default_wind_speed",
            "the FFT ocean's default wind speed V, in m/s",
            format!("{}", fft_defaults.wind_speed),
        ),
        (
            "fft_default_wind_direction_degrees",
            "the FFT ocean's default wind direction, in degrees from +x",
            format!("{}", fft_defaults.wind_direction_degrees),
        ),
        (
            "fft_default_amplitude",
            "the FFT ocean's default Phillips constant A",
            format!("{:e}", fft_defaults.amplitude),
        ),
        (
            "fft_default_cutoff_metres",
            "the FFT ocean's default cutoff l, in metres",
            format!("{}", fft_defaults.cutoff_metres),
        ),
        (
            "fft_default_choppiness",
            "the FFT ocean's default choppiness λ",
            format!("{}", fft_defaults.choppiness),
        ),
        (
            "fft_default_gravity",
            "the FFT ocean's default g, in m/s²",
            format!("{}", fft_defaults.gravity),
        ),
        (
            "fft_default_seed",
            "the FFT ocean's default seed",
            fft_defaults.seed.to_string(),
        ),
        (
            "fft_allowed_patch_metres",
            "the values of patch_metres a parameters file may give",
            fft_allowed("patch_metres"),
        ),
        (
            "fft_allowed_wind_speed",
            "the values of wind_speed a parameters file may give",
            fft_allowed("wind_speed"),
        ),
        (
            "fft_allowed_wind_direction_degrees",
            "the values of wind_direction_degrees a parameters file may give",
            fft_allowed("wind_direction_degrees"),
        ),
        (
            "fft_allowed_amplitude",
            "the values of amplitude a parameters file may give",
            fft_allowed("amplitude"),
        ),
        (
            "fft_allowed_cutoff_metres",
            "the values of cutoff_metres a parameters file may give",
            fft_allowed("cutoff_metres"),
        ),
        (
            "fft_allowed_choppiness",
            "the values of choppiness a parameters file may give",
            fft_allowed("choppiness"),
        ),
        (
            "fft_allowed_gravity",
            "the values of gravity a parameters file may give",
            fft_allowed("gravity"),
        ),
        (
            "fft_allowed_depth_metres",
            "the values of depth_metres a parameters file may give (besides null)",
            fft_allowed("depth_metres"),
        ),
        (
            "fft_finest_spacing_metres",
            "the default patch's vertex spacing at the FFT ocean's largest size, in metres",
            format!(
                "{:.2}",
                fft_defaults.patch_metres / crate::ocean::fft::size::MAX as f64
            ),
        ),
        (
            "balance_default_points",
            "points of a balance search's curve by default",
            balance_defaults.points.to_string(),
        ),
        (
            "balance_default_range_from",
            "where a balance search's range starts by default, as W ÷ S",
            format!("{}", balance_defaults.range[0]),
        ),
        (
            "balance_default_range_to",
            "where a balance search's range ends by default, as W ÷ S",
            format!("{}", balance_defaults.range[1]),
        ),
        (
            "balance_default_trials",
            "paired trials at every balance probe by default",
            balance_defaults.trials.to_string(),
        ),
        (
            "balance_default_tolerance_percent",
            "the bracket width, in % of the step, at which a balance search stops by default",
            format!("{}", balance_defaults.tolerance_percent),
        ),
        // reference (README, config, methodology, ci, architecture):
        (
            "rust_version",
            "the oldest Rust toolchain that builds the crate (Cargo.toml's rust-version)",
            env!("CARGO_PKG_RUST_VERSION").to_string(),
        ),
        (
            "exit_failed",
            "the exit status of a failure while running, or of a regression compare found",
            crate::exit::EXIT_FAILED.to_string(),
        ),
        (
            "exit_bad_input",
            "the exit status of bad input",
            crate::exit::EXIT_BAD_INPUT.to_string(),
        ),
        (
            "trace_default_frames",
            "measured frames a trace keeps without --trace-frames",
            crate::trace::DEFAULT_FRAMES.to_string(),
        ),
        (
            "trace_max_frames",
            "the most frames --trace-frames allows",
            crate::trace::MAX_FRAMES.to_string(),
        ),
        (
            "exit_interrupted",
            "the exit status of a command stopped by Ctrl-C or SIGTERM",
            crate::exit::EXIT_INTERRUPTED.to_string(),
        ),
        (
            "interval_percent",
            "the confidence of the bootstrap intervals of compare and findings, in percent",
            format!(
                "{:.0}",
                (crate::stats::INTERVAL_TAILS.1 - crate::stats::INTERVAL_TAILS.0) * 100.0
            ),
        ),
        (
            "level_mismatch_percent",
            "how far apart two runs' microseconds for one workload level may be and still be the same game work",
            format!("{}", crate::report::compare::LEVEL_MISMATCH * 100.0),
        ),
        (
            "mesh_min_size",
            "the smallest mesh size N",
            crate::ocean::mesh::MIN_SIZE.to_string(),
        ),
        (
            "mesh_max_size",
            "the largest mesh size N",
            crate::ocean::mesh::MAX_SIZE.to_string(),
        ),
        (
            "default_workloads",
            "the default sweep's workload levels",
            list(Dim::Workload),
        ),
        (
            "default_helpers",
            "the default sweep's helper counts",
            list(Dim::Helpers),
        ),
        (
            "default_depth",
            "the default sweep's run-ahead depths",
            list(Dim::Depth),
        ),
        (
            "lookup_max_size",
            "the largest mesh `lookup` normals take (about a second of one core a frame)",
            crate::ocean::normals::lookup_max_size().to_string(),
        ),
        (
            "fft_min_size",
            "the smallest size the FFT ocean runs at",
            crate::ocean::fft::size::MIN.to_string(),
        ),
        (
            "fft_max_size",
            "the largest size the FFT ocean runs at",
            crate::ocean::fft::size::MAX.to_string(),
        ),
        (
            "fft_primes",
            "the only prime factors of an FFT ocean size",
            and_list(crate::ocean::fft::size::PRIMES.iter().map(|p| p.to_string())),
        ),
        (
            "default_levels",
            "the default workload levels (S40: the step time of a 40×40 mesh)",
            config
                .workload_levels
                .iter()
                .map(level_text)
                .collect::<Vec<_>>()
                .join(", "),
        ),
        (
            "default_level_1",
            "default workload level 1, against the step it is placed by",
            level_against_step(&config, 1),
        ),
        (
            "default_level_2",
            "default workload level 2, against the step it is placed by",
            level_against_step(&config, 2),
        ),
        (
            "default_level_3",
            "default workload level 3, against the step it is placed by",
            level_against_step(&config, 3),
        ),
        (
            "max_particles",
            "the most particles a spray level may give",
            crate::workload::spray::MAX_PARTICLES.to_string(),
        ),
        (
            "default_particles",
            "the spray pool `run --workload-kind spray` uses without --amount",
            crate::workload::spray::DEFAULT_PARTICLES.to_string(),
        ),
        (
            "max_fog_volume",
            "the largest fog volume edge a level may give, in voxels",
            crate::workload::fog::MAX_VOLUME.to_string(),
        ),
        (
            "spray_threshold_min",
            "the lowest spray emission threshold (J)",
            format!("{}", crate::workload::spray::THRESHOLD_RANGE.0).replace('-', "−"),
        ),
        (
            "spray_threshold_max",
            "the highest spray emission threshold (J)",
            format!("{}", crate::workload::spray::THRESHOLD_RANGE.1),
        ),
        (
            "spray_max_speed",
            "the fastest spray launch speed, m/s",
            format!("{}", crate::workload::spray::MAX_SPEED),
        ),
        (
            "spray_max_lifetime",
            "the longest spray lifetime, s",
            format!("{}", crate::workload::spray::MAX_LIFETIME),
        ),
        (
            "spray_max_drag",
            "the strongest spray drag, per s",
            format!("{}", crate::workload::spray::MAX_DRAG),
        ),
        (
            "spray_max_emission",
            "the most particles one frame may emit",
            crate::workload::spray::MAX_EMISSION.to_string(),
        ),
        (
            "spray_defaults",
            "the spray's defaults: threshold, speed, lifetime, drag, emission_cap, seed",
            {
                let s = crate::workload::SprayParams::default();
                format!(
                    "{}, {}, {}, {}, {}, {}",
                    s.threshold, s.speed, s.lifetime, s.drag, s.emission_cap, s.seed
                )
            },
        ),
        (
            "fog_max_octaves",
            "the most octaves the fog's noise sums",
            crate::workload::fog::MAX_OCTAVES.to_string(),
        ),
        (
            "fog_stride_min",
            "the shortest fog stride, voxels per lattice cell",
            format!("{}", crate::workload::fog::STRIDE.0),
        ),
        (
            "fog_stride_max",
            "the longest fog stride, voxels per lattice cell",
            format!("{}", crate::workload::fog::STRIDE.1),
        ),
        (
            "fog_blur_min",
            "the narrowest fog blur, taps",
            crate::workload::fog::MIN_BLUR.to_string(),
        ),
        (
            "fog_blur_max",
            "the widest fog blur, taps",
            crate::workload::fog::blur::MAX_WIDTH.to_string(),
        ),
        (
            "fog_defaults",
            "the fog's defaults: octaves, strides, weights (before normalising), density, blur_width, seed",
            {
                let f = crate::workload::FogParams::default();
                let octaves = f.octaves();
                let join = |v: Vec<String>| v.join("/");
                format!(
                    "{}, {}, {}, {}, {}, {}",
                    f.octaves,
                    join(octaves.iter().map(|o| o.stride.to_string()).collect()),
                    join(octaves.iter().map(|o| o.weight.to_string()).collect()),
                    f.density,
                    f.blur_width,
                    f.seed
                )
            },
        ),
        (
            "camera_default_aspect",
            "the default camera's aspect ratio",
            fraction(f64::from(crate::camera::Camera::default().aspect)),
        ),
        (
            "default_budget",
            "the default trial budget: trials, warmup_frames, min_frames, min_seconds, max_seconds",
            format!(
                "{}, {}, {}, {}, {}",
                config.trials,
                config.warmup_frames,
                config.min_frames,
                config.min_seconds,
                config.max_seconds
            ),
        ),
        (
            "default_spacing",
            "the default grid spacing",
            format!("{:.1}", config.spacing),
        ),
        (
            "default_time_step",
            "simulated seconds per frame by default",
            fraction(config.time_step),
        ),
        (
            "default_timeout_seconds",
            "the default hand-off timeout, s",
            format!("{}", config.timeout_seconds),
        ),
        (
            "default_noise_threshold_percent",
            "the default share of a trial's wall time preemption or steal may take before it is noisy",
            format!("{}", config.noise_threshold_percent),
        ),
        (
            "default_retry_noisy",
            "times a noisy trial is re-run by default",
            config.retry_noisy.to_string(),
        ),
        (
            "max_retry_noisy",
            "the most times a noisy trial may be re-run",
            crate::config::MAX_RETRY_NOISY.to_string(),
        ),
        (
            "max_waves",
            "the most waves a wave set holds",
            crate::ocean::waves::MAX_WAVES.to_string(),
        ),
        (
            "min_steepness",
            "the least steepness exponent of a wave",
            format!("{}", crate::ocean::waves::MIN_STEEPNESS),
        ),
        (
            "stutter_factor",
            "a frame longer than this many average frame times is a stutter (CapFrameX's factor)",
            format!("{}", crate::summary::STUTTER_FACTOR),
        ),
        (
            "default_wavelengths",
            "the default waves' wavelengths, m",
            and_list(default_waves().iter().map(|w| w.wavelength.to_string())),
        ),
        (
            "default_wave_speeds",
            "the default waves' speeds from the deep-water dispersion relation, m/s",
            and_list(default_waves().iter().map(|w| format!("{:.1}", w.speed))),
        ),
        (
            "default_wave_spread_degrees",
            "the angle the default waves' directions spread over",
            {
                let angles: Vec<f64> = default_waves()
                    .iter()
                    .map(|w| f64::from(w.direction[1]).atan2(f64::from(w.direction[0])))
                    .collect();
                let (lo, hi) = crate::stats::min_max(&angles);
                format!("{:.0}", (hi - lo).to_degrees())
            },
        ),
        (
            "default_wave_amplitudes",
            "the default waves' amplitudes as a fraction of their wavelength",
            {
                let ratios: Vec<f64> = default_waves()
                    .iter()
                    .map(|w| f64::from(w.wavelength / w.amplitude))
                    .collect();
                let (lo, hi) = crate::stats::min_max(&ratios);
                format!("1/{hi:.0} to 1/{lo:.0}")
            },
        ),
        (
            "default_wave_steepness",
            "the default waves' steepness exponents",
            {
                let s: Vec<f64> = default_waves()
                    .iter()
                    .map(|w| f64::from(w.steepness))
                    .collect();
                let (lo, hi) = crate::stats::min_max(&s);
                format!("{lo}-{hi}")
            },
        ),
        // spray and the fast kernel (docs/spray.md, docs/performance.md):
        (
            "spray_gravity",
            "the spray's gravity, in m/s²",
            format!("{}", crate::workload::spray::GRAVITY),
        ),
        (
            "spray_bytes_per_particle",
            "bytes one particle slot of the spray's pool takes",
            crate::workload::spray::BYTES_PER_PARTICLE.to_string(),
        ),
        (
            "spray_float_arrays",
            "the `f32` arrays the spray's integration reads and writes",
            crate::workload::spray::Pool::new(0).floats().len().to_string(),
        ),
        (
            "spray_integration_bytes",
            "bytes a particle the spray's integration reads and writes once",
            (crate::workload::spray::Pool::new(0).floats().len() * std::mem::size_of::<f32>())
                .to_string(),
        ),
        (
            "spray_default_threshold",
            "the spray's default emission threshold (J)",
            format!("{}", crate::workload::SprayParams::default().threshold),
        ),
        (
            "spray_default_speed",
            "the spray's default launch speed, m/s",
            format!("{}", crate::workload::SprayParams::default().speed),
        ),
        (
            "spray_default_lifetime",
            "the spray's default lifetime, s",
            format!("{}", crate::workload::SprayParams::default().lifetime),
        ),
        (
            "spray_default_drag",
            "the spray's default drag, per s",
            format!("{}", crate::workload::SprayParams::default().drag),
        ),
        (
            "spray_default_emission_cap",
            "the spray's default cap of births a frame",
            crate::workload::SprayParams::default()
                .emission_cap
                .to_string(),
        ),
        (
            "spray_default_seed",
            "the spray's default jitter seed",
            crate::workload::SprayParams::default().seed.to_string(),
        ),
        (
            "fused_exponents",
            "the integer exponents 2k − 2 the fused wave loop is compiled for (0 to MAX_INT_EXP)",
            (crate::ocean::sines::fast::phase::MAX_INT_EXP + 1).to_string(),
        ),
        // fog and noise (docs/fog.md, docs/noise.md):
        (
            "fog_min_octaves",
            "the fewest octaves the fog's noise sums",
            fog_octaves_accepted().next().expect("some octave count").to_string(),
        ),
        (
            "fog_default_octaves",
            "the fog's octaves by default",
            crate::workload::FogParams::default().octaves.to_string(),
        ),
        (
            "fog_default_strides",
            "the default octaves' strides, voxels per lattice cell",
            fog_default_octaves(|o| o.stride.to_string()),
        ),
        (
            "fog_default_weights",
            "the default octaves' weights, before normalising",
            fog_default_octaves(|o| o.weight.to_string()),
        ),
        (
            "fog_default_density",
            "the fog's density ρ by default, per patch width",
            format!("{}", crate::workload::FogParams::default().density),
        ),
        (
            "fog_default_blur_width",
            "the fog blur's taps per axis by default",
            crate::workload::FogParams::default().blur_width.to_string(),
        ),
        (
            "fog_default_blur_taps",
            "the default blur's weights: its row of Pascal's triangle over their sum",
            fog_default_blur_taps(),
        ),
        (
            "fog_default_seed",
            "the fog's permutation seed by default",
            crate::workload::FogParams::default().seed.to_string(),
        ),
        (
            "fog_max_buffer_mib",
            "MiB of each of the two buffers of the largest fog volume",
            ((crate::workload::fog::volume_bytes(crate::workload::fog::MAX_VOLUME) / 2) >> 20)
                .to_string(),
        ),
        (
            "fog_drift",
            "voxels the fog's noise moves per frame along x, y and z",
            crate::workload::fog::Fog::frame(1)
                .offset
                .map(|d| d.to_string())
                .join(", "),
        ),
        (
            "fog_floor",
            "the floor added to the fog's height falloff",
            format!("{}", crate::workload::fog::coefficient::FLOOR),
        ),
        (
            "fog_oracle_tolerance",
            "the largest difference the tests allow between the fog's noise and the noise crate's",
            scientific(&format!("{:e}", crate::workload::fog::noise::ORACLE_TOLERANCE)),
        ),
        (
            "doctor_seconds",
            "the seconds `doctor` watches the machine by default",
            doctor_seconds(),
        ),
        (
            "doctor_placement_trips",
            "round trips `doctor` times before its window, and again after",
            crate::doctor::PLACEMENT_TRIPS.to_string(),
        ),
        (
            "row_yardstick_rounds",
            "rounds of the yardstick measured before every row, at least",
            crate::sweep::ROW_YARDSTICK_ROUNDS.to_string(),
        ),
        (
            "row_yardstick_ms",
            "milliseconds the yardstick before every row takes, at least",
            crate::sweep::ROW_YARDSTICK_MIN.as_millis().to_string(),
        ),
        (
            "calibration_drift_percent",
            "how far a row's step or workload speed may drift from the start before the sweep warns",
            format!("{}", crate::calibrate::DRIFT_WARNING * 100.0),
        ),
        (
            "canary_slower_ratio",
            "a canary at least this many times its reference says its core ran slower",
            format!("{}", 1.0 + crate::slow_trials::CANARY_SLOWER),
        ),
        (
            "trial_round_trip_batches",
            "batches of the round trip timed just before and just after every trial",
            crate::sweep::TRIAL_ROUND_TRIP_BATCHES.to_string(),
        ),
        (
            "round_trip_batch_trips",
            "round trips in one timed batch",
            crate::crosscore::BATCH.to_string(),
        ),
    ]
}

/// What a parameters file may give for the FFT ocean's number `key`, as the parameters table
/// writes it, found by asking the parameters' own check: `> 0`, `≥ 0` or `finite`.
fn fft_allowed(key: &str) -> String {
    let accepts = |v: f64| {
        crate::ocean::phillips::FftParams::from_json(&format!("{{\"{key}\": {v}}}")).is_ok()
    };
    match (accepts(-1.0), accepts(0.0), accepts(1.0)) {
        (true, true, true) => "finite".into(),
        (false, true, true) => "≥ 0".into(),
        (false, false, true) => "> 0".into(),
        other => format!("? ({key}: {other:?})"),
    }
}

/// The ring depths `check_depth` accepts under `threading`, shallowest first.
fn depths(threading: crate::frame_loop::Threading) -> impl Iterator<Item = usize> {
    (0..=crate::frame_loop::MAX_DEPTH)
        .filter(move |&d| crate::frame_loop::check_depth(d, threading).is_ok())
}

/// The period `--path-radius` alone gives a still camera's path.
fn default_path_period() -> f32 {
    let mut camera = crate::camera::Camera::default();
    crate::cli::CameraArgs {
        path_radius: Some(1.0),
        ..Default::default()
    }
    .apply(&mut camera);
    camera.path.expect("a radius gives a path").period_seconds
}

/// The constant `name` as docs write it.
pub fn value(name: &str) -> Result<String, String> {
    let all = all();
    all.iter()
        .find(|(n, _, _)| *n == name)
        .map(|(_, _, v)| v.clone())
        .ok_or_else(|| {
            format!(
                "const: unknown name `{name}` (allowed: {})",
                all.iter()
                    .map(|(n, _, _)| *n)
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        })
}

/// The value at `key` (a dotted path; list indexes as numbers) of the committed config named by
/// a `config` block's `file`, as docs write it: a list as `a, b, c`, a string without quotes.
pub fn config_value(root: &Path, block: &Block) -> Result<String, String> {
    let file = block
        .attr("file")
        .ok_or("`config` needs file=configs/NAME.json")?;
    let key = block.attr("key").ok_or("`config` needs key=PATH")?;
    let text = std::fs::read_to_string(root.join(file))
        .map_err(|e| format!("config file `{file}`: {e}"))?;
    let json: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| format!("config file `{file}`: {e}"))?;
    let mut at = &json;
    for part in key.split('.') {
        let next = match part.parse::<usize>() {
            Ok(i) => at.get(i),
            Err(_) => at.get(part),
        };
        at = next.ok_or_else(|| format!("config file `{file}` has no key `{key}`"))?;
    }
    let show = |v: &serde_json::Value| match v {
        serde_json::Value::String(s) => s.clone(),
        other => other.to_string(),
    };
    Ok(match at {
        serde_json::Value::Array(items) => items.iter().map(show).collect::<Vec<_>>().join(", "),
        other => show(other),
    })
}

/// `a, b and c`.
fn and_list(items: impl Iterator<Item = String>) -> String {
    let items: Vec<String> = items.collect();
    match items.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} and {last}", rest.join(", ")),
        _ => items.join(""),
    }
}

/// `x` as the fraction with the smallest denominator up to 100 that gives it (`16/9`, `1/60`),
/// or as a number when none does.
fn fraction(x: f64) -> String {
    (1..=100u32)
        .find_map(|d| {
            let n = (x * f64::from(d)).round();
            ((n / f64::from(d) - x).abs() < 1e-6 * x.abs().max(1.0)).then(|| {
                if d == 1 {
                    format!("{n}")
                } else {
                    format!("{n}/{d}")
                }
            })
        })
        .unwrap_or_else(|| format!("{x}"))
}

/// A workload level as docs write it: `0 µs`, `0.7 × S40` (S40: the step of a 40×40 mesh), or
/// its amount in a unit.
fn level_text(level: &crate::config::Level) -> String {
    match (
        level.micros,
        level.step_fraction,
        level.size,
        level.amount(),
    ) {
        (Some(us), _, _, _) => format!("{us} µs"),
        (_, Some(f), Some(n), _) => format!("{f} × S{n}"),
        (_, _, _, Some((unit, amount))) => format!("{amount} {unit}"),
        _ => "?".into(),
    }
}

/// Level `i` of `config` as `0.7 × the 40×40 step`.
fn level_against_step(config: &SweepConfig, i: usize) -> String {
    match config.workload_levels.get(i) {
        Some(crate::config::Level {
            step_fraction: Some(f),
            size: Some(n),
            ..
        }) => format!("{f} × the {n}×{n} step"),
        Some(level) => level_text(level),
        None => "?".into(),
    }
}

/// The built-in wave set.
fn default_waves() -> Vec<crate::ocean::Wave> {
    crate::ocean::WaveSet::default().waves
}

/// The octave counts the fog's check accepts, fewest first.
fn fog_octaves_accepted() -> impl Iterator<Item = u32> {
    (0..=crate::workload::fog::MAX_OCTAVES).filter(|&octaves| {
        crate::workload::FogParams {
            octaves,
            ..Default::default()
        }
        .validate()
        .is_ok()
    })
}

/// One field of every default fog octave, as `a, b, c`.
fn fog_default_octaves(field: impl Fn(&crate::workload::fog::noise::Octave) -> String) -> String {
    let octaves = crate::workload::FogParams::default().octaves();
    octaves.iter().map(field).collect::<Vec<_>>().join(", ")
}

/// The default blur's weights as whole numbers over their sum: `1 4 6 4 1 / 16`.
fn fog_default_blur_taps() -> String {
    let width = crate::workload::FogParams::default().blur_width as usize;
    let total = 2f64.powi(width as i32 - 1);
    let taps: Vec<String> = crate::workload::fog::blur::weights(width)
        .iter()
        .map(|&w| format!("{}", (f64::from(w) * total).round()))
        .collect();
    format!("{} / {total}", taps.join(" "))
}

/// A number written `2e-6` as docs write it: `2·10⁻⁶`.
fn scientific(text: &str) -> String {
    let (mantissa, exponent) = text.split_once('e').unwrap_or((text, "0"));
    let superscript: String = exponent
        .chars()
        .map(|c| match c {
            '-' => '⁻',
            d => "⁰¹²³⁴⁵⁶⁷⁸⁹"
                .chars()
                .nth(d.to_digit(10).unwrap_or(0) as usize)
                .unwrap_or(d),
        })
        .collect();
    format!("{mantissa}·10{superscript}")
}

/// The default of `doctor --seconds`, as the command line has it.
fn doctor_seconds() -> String {
    use clap::CommandFactory;
    crate::cli::Cli::command()
        .find_subcommand("doctor")
        .and_then(|c| {
            c.get_arguments()
                .find(|a| a.get_id() == "seconds")
                .and_then(|a| a.get_default_values().first())
                .map(|v| v.to_string_lossy().into_owned())
        })
        .unwrap_or_else(|| "?".into())
}
