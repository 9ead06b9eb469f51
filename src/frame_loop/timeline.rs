//! A traced trial's timeline: the instants the loops already read, kept per frame for the first
//! frames of a trial when a trace is asked for. The buffers are allocated before the first frame
//! and written in place, so a traced loop reads no extra clock and allocates nothing per frame;
//! an untraced loop keeps no capture at all.

use crate::measure::FrameRecord;
use std::time::{Duration, Instant};

/// A traced trial's frames, every time an offset in nanoseconds from the earliest instant kept.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Timeline {
    /// Helper threads; 0 in `serial`, whose step runs on the main thread (each frame still has
    /// one [`HelperSpan`], the main thread's step).
    pub helpers: usize,
    /// The captured frames, in order: the trial's first measured ones.
    pub frames: Vec<TracedFrame>,
    /// The trial's measured frames, captured or not.
    pub measured: u64,
    /// The most frames a trace keeps.
    pub cap: usize,
}

/// One captured frame: the main thread's parts and each helper's side of the mesh it consumed.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TracedFrame {
    /// The frame's index in the loop, warm-up frames included.
    pub index: u64,
    /// The frame the consumed mesh was computed for ([`FrameRecord::mesh_frame`]).
    pub mesh_frame: u64,
    /// Frames the helper had finished beyond the consumed one ([`FrameRecord::age_frames`]).
    pub age_frames: u32,
    /// From the mesh's publication to its consumption ([`FrameRecord::age_ns`]).
    pub age_ns: u64,
    /// The frame's start, which is the previous frame's end.
    pub start_ns: u64,
    /// The end of the work before the wait: the wait (in `serial`, the step) starts here.
    pub wait_ns: u64,
    /// The mesh in hand: the consume step starts here.
    pub consume_ns: u64,
    /// The end of the consume step and of the work on the mesh.
    pub done_ns: u64,
    /// The frame's end (after the loop's own bookkeeping).
    pub end_ns: u64,
    /// How long the work on the mesh took, within `consume_ns..done_ns`.
    pub on_mesh_ns: u64,
    /// Each helper's side of the consumed mesh, helper k at index k.
    pub helpers: Vec<HelperSpan>,
}

/// The most phases of a split step a trace draws apart.
pub(super) const TRACED_PHASES: usize = 4;

/// When each phase of a split step computed, after its barrier; `None` for phases not run.
pub(super) type PhaseMarks = [Option<(Instant, Instant)>; TRACED_PHASES];

/// One helper's side of a mesh: its wait for a free slot, then its step up to the publication.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct HelperSpan {
    /// The wait for a free slot started (equal to `step_ns` when it did not wait).
    pub wait_ns: u64,
    /// The step started.
    pub step_ns: u64,
    /// The band was published.
    pub publish_ns: u64,
    /// With a split step (several helpers, a model of several phases), each phase's start and
    /// end after its barrier, within the step.
    pub phases: Vec<[u64; 2]>,
}

/// A helper's instants as its stamp holds them.
#[derive(Clone, Copy)]
struct HelperMarks {
    waited: Duration,
    started: Instant,
    published: Instant,
    phases: PhaseMarks,
}

/// The main thread's instants of a frame, before it ends.
#[derive(Clone, Copy)]
struct Marks {
    start: Instant,
    main: [Instant; 3],
    on_mesh: Duration,
    end: Instant,
    index: u64,
    mesh_frame: u64,
    age_frames: u32,
    age_ns: u64,
}

/// The capture buffers of a traced loop.
pub(super) struct Capture {
    cap: usize,
    bands: usize,
    helpers: usize,
    frames: Vec<Marks>,
    /// `cap` × `bands` entries, frame f's band h at f · bands + h.
    bands_marks: Vec<HelperMarks>,
    current: Marks,
    measured: u64,
}

/// The current frame's marks, for a loop to fill.
pub(super) struct FrameMarks<'a> {
    current: &'a mut Marks,
    bands: &'a mut [HelperMarks],
}

impl FrameMarks<'_> {
    /// Helper `h`'s stamp of the consumed mesh: its wait for the slot ended when the step
    /// started, so the wait's start is the step's start less the wait.
    pub fn helper(&mut self, h: usize, waited_ns: u64, started: Instant, published: Instant) {
        self.bands[h] = HelperMarks {
            waited: Duration::from_nanos(waited_ns),
            started,
            published,
            phases: [None; TRACED_PHASES],
        };
    }

    /// Helper `h`'s phases of the consumed mesh, after [`FrameMarks::helper`].
    pub fn phases(&mut self, h: usize, phases: PhaseMarks) {
        self.bands[h].phases = phases;
    }

    /// The main thread's instants after the frame's start: the wait's start, the mesh in hand,
    /// and the end of its consumption; `on_mesh` of work on the mesh ran within the last part.
    pub fn main(&mut self, [t1, t2, t3]: [Instant; 3], on_mesh: Duration) {
        self.current.main = [t1, t2, t3];
        self.current.on_mesh = on_mesh;
    }
}

impl Capture {
    /// Buffers for `cap` frames of a loop with `helpers` helper threads, allocated now.
    pub fn new(cap: usize, helpers: usize) -> Capture {
        let now = Instant::now();
        let bands = helpers.max(1);
        let blank = HelperMarks {
            waited: Duration::ZERO,
            started: now,
            published: now,
            phases: [None; TRACED_PHASES],
        };
        Capture {
            cap,
            bands,
            helpers,
            frames: Vec::with_capacity(cap),
            bands_marks: vec![blank; cap * bands],
            current: Marks {
                start: now,
                main: [now; 3],
                on_mesh: Duration::ZERO,
                end: now,
                index: 0,
                mesh_frame: 0,
                age_frames: 0,
                age_ns: 0,
            },
            measured: 0,
        }
    }

    /// The current frame's marks, if it is among the captured ones.
    pub fn marks(&mut self) -> Option<FrameMarks<'_>> {
        let f = self.frames.len();
        (f < self.cap).then(|| FrameMarks {
            current: &mut self.current,
            bands: &mut self.bands_marks[f * self.bands..(f + 1) * self.bands],
        })
    }

    /// Ends a measured frame `index` that ran from `start` to `end`, keeping it if there is room.
    pub fn finish(&mut self, index: u64, start: Instant, end: Instant, record: &FrameRecord) {
        self.measured += 1;
        if self.frames.len() < self.cap {
            self.current.start = start;
            self.current.end = end;
            self.current.index = index;
            self.current.mesh_frame = record.mesh_frame;
            self.current.age_frames = record.age_frames;
            self.current.age_ns = record.age_ns;
            self.frames.push(self.current);
        }
    }

    /// The captured frames as offsets from the earliest instant among them.
    pub fn timeline(self) -> Timeline {
        let bands = |f: usize| &self.bands_marks[f * self.bands..(f + 1) * self.bands];
        let wait_start = |b: &HelperMarks| b.started.checked_sub(b.waited).unwrap_or(b.started);
        let origin = (0..self.frames.len())
            .flat_map(|f| bands(f).iter().map(wait_start))
            .chain(self.frames.iter().map(|m| m.start))
            .min();
        let Some(origin) = origin else {
            return Timeline {
                helpers: self.helpers,
                frames: Vec::new(),
                measured: self.measured,
                cap: self.cap,
            };
        };
        let at = |i: Instant| i.saturating_duration_since(origin).as_nanos() as u64;
        let frames = self
            .frames
            .iter()
            .enumerate()
            .map(|(f, m)| TracedFrame {
                index: m.index,
                mesh_frame: m.mesh_frame,
                age_frames: m.age_frames,
                age_ns: m.age_ns,
                start_ns: at(m.start),
                wait_ns: at(m.main[0]),
                consume_ns: at(m.main[1]),
                done_ns: at(m.main[2]),
                end_ns: at(m.end),
                on_mesh_ns: m.on_mesh.as_nanos() as u64,
                helpers: bands(f)
                    .iter()
                    .map(|b| HelperSpan {
                        wait_ns: at(wait_start(b)),
                        step_ns: at(b.started),
                        publish_ns: at(b.published),
                        phases: b
                            .phases
                            .iter()
                            .flatten()
                            .map(|&(s, e)| [at(s), at(e)])
                            .collect(),
                    })
                    .collect(),
            })
            .collect();
        Timeline {
            helpers: self.helpers,
            frames,
            measured: self.measured,
            cap: self.cap,
        }
    }
}
