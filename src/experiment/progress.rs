//! Progress of a long experiment, told to whoever runs it: the library only sends
//! [`Progress`] events to a [`ProgressSink`]; the command line draws them as a bar.

use std::fmt;
use std::sync::Arc;

/// What an experiment tells its caller while it works.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Progress<'a> {
    /// A stage begins (`simulating`, `recognizing`, `sweeping`, `seeds`) with this many steps.
    Start { stage: &'a str, steps: u64 },
    /// One step of the current stage is done (from any thread).
    Step,
    /// How the current stage goes, in a few words to show beside its count (e.g. `run`'s laps
    /// per second and memory).
    Status(&'a str),
    /// The current stage is over.
    Done,
}

/// The callback behind a [`ProgressSink`].
type Callback = Arc<dyn Fn(Progress<'_>) + Send + Sync>;

/// Where [`Progress`] goes: a callback shared by the threads of a stage, or nowhere (the
/// default).
#[derive(Clone, Default)]
pub struct ProgressSink(Option<Callback>);

impl ProgressSink {
    /// Sends every event to `f`.
    pub fn new(f: impl Fn(Progress<'_>) + Send + Sync + 'static) -> Self {
        ProgressSink(Some(Arc::new(f)))
    }

    /// Sends nothing.
    pub fn none() -> Self {
        ProgressSink(None)
    }

    /// Sends `event`.
    pub fn send(&self, event: Progress<'_>) {
        if let Some(f) = &self.0 {
            f(event);
        }
    }

    /// Sends `Start`.
    pub fn start(&self, stage: &str, steps: u64) {
        self.send(Progress::Start { stage, steps });
    }

    /// Sends `Step`.
    pub fn step(&self) {
        self.send(Progress::Step);
    }

    /// Sends `Status`.
    pub fn status(&self, text: &str) {
        self.send(Progress::Status(text));
    }

    /// Sends `Done`.
    pub fn done(&self) {
        self.send(Progress::Done);
    }
}

impl fmt::Debug for ProgressSink {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(if self.0.is_some() {
            "ProgressSink(callback)"
        } else {
            "ProgressSink(none)"
        })
    }
}

/// Two sinks are equal when both send nowhere or both send to the same callback.
impl PartialEq for ProgressSink {
    fn eq(&self, other: &Self) -> bool {
        match (&self.0, &other.0) {
            (None, None) => true,
            (Some(a), Some(b)) => Arc::ptr_eq(a, b),
            _ => false,
        }
    }
}
