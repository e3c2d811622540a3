//! The one progress channel (argmin / clarabel style): solvers, the planner, the studies and
//! the demo report what they do to an [`Observer`]; none of them prints. A task starts
//! ([`Observer::start`]), reports steps ([`Observer::step`]) or solver iterations
//! ([`Observer::iteration`]), and finishes ([`Observer::finish`]). Tasks may nest (the
//! demo's stages run the planner and identification); an observer that draws one line can
//! simply show the latest task.
//!
//! Observers are `Send` so that parallel work (the planner's starts, a study's robots)
//! can report through a `Mutex` ([`Shared`]).

use std::sync::Mutex;

/// Receives progress. Every method has an empty default, so an observer implements only
/// what it shows.
pub trait Observer: Send {
    /// A task starts: `task` names it for people; `total` is its number of steps if known.
    fn start(&mut self, _task: &str, _total: Option<usize>) {}
    /// One step of the current task is done (an exchange start, a study robot).
    fn step(&mut self) {}
    /// A solver iteration: its index, the cost after it and the damping (0 for undamped
    /// solvers), after every accepted or rejected step.
    fn iteration(&mut self, _iteration: usize, _cost: f64, _damping: f64) {}
    /// The current task is finished.
    fn finish(&mut self) {}
}

/// An observer that ignores everything.
pub struct Silent;

impl Observer for Silent {}

/// An observer shared by parallel workers: `&Shared` is itself an observer, and each call
/// locks the underlying one for its duration (the workers' reports interleave).
pub struct Shared<'a>(Mutex<&'a mut dyn Observer>);

impl<'a> Shared<'a> {
    /// Shares `observer` between threads.
    pub fn new(observer: &'a mut dyn Observer) -> Self {
        Shared(Mutex::new(observer))
    }

    fn with(&self, f: impl FnOnce(&mut dyn Observer)) {
        // A worker that panicked while reporting leaves the observer usable.
        let mut o = self.0.lock().unwrap_or_else(|e| e.into_inner());
        f(&mut **o);
    }
}

impl Observer for &Shared<'_> {
    fn start(&mut self, task: &str, total: Option<usize>) {
        self.with(|o| o.start(task, total));
    }
    fn step(&mut self) {
        self.with(|o| o.step());
    }
    fn iteration(&mut self, iteration: usize, cost: f64, damping: f64) {
        self.with(|o| o.iteration(iteration, cost, damping));
    }
    fn finish(&mut self) {
        self.with(|o| o.finish());
    }
}
