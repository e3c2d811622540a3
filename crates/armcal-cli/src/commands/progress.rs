//! The CLI's one progress display: an [`Observer`] drawn with indicatif on stderr, only
//! when stderr is a terminal and `--quiet` is not given (so nothing is printed when the
//! output is captured).

use armcal::Observer;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::time::Duration;

/// A spinner line showing the innermost running task (its label, its steps or the
/// solver's iteration and cost, and the elapsed time). Tasks nest as a stack; tasks of
/// parallel workers (the planner's starts) interleave on it, so the line shows whichever
/// reported last — a display, not a record.
pub struct Progress {
    bar: ProgressBar,
    /// The running tasks, outermost first.
    tasks: Vec<Task>,
}

/// A running task: label, number of steps if known, steps (or iterations) done.
#[derive(Clone, Default)]
struct Task {
    label: String,
    total: Option<usize>,
    done: u64,
}

impl Progress {
    /// A display that draws nothing if `quiet` or stderr is not a terminal.
    pub fn new(quiet: bool) -> Self {
        let bar = ProgressBar::new_spinner();
        if quiet || !std::io::stderr().is_terminal() {
            bar.set_draw_target(ProgressDrawTarget::hidden());
        } else {
            bar.enable_steady_tick(Duration::from_millis(120));
        }
        let mut p = Progress {
            bar,
            tasks: Vec::new(),
        };
        p.show_top();
        p
    }

    /// Shows the innermost task (after one started or ended).
    fn show_top(&mut self) {
        let Task { label, total, done } = self.tasks.last().cloned().unwrap_or_default();
        let template = match total {
            Some(n) => {
                self.bar.set_length(n as u64);
                "{spinner} {msg} {pos}/{len} ({elapsed})"
            }
            None => "{spinner} {msg} ({elapsed})",
        };
        self.bar
            .set_style(ProgressStyle::with_template(template).expect("valid template"));
        self.bar.set_position(done);
        self.bar.set_message(label);
    }
}

impl Observer for Progress {
    fn start(&mut self, task: &str, total: Option<usize>) {
        self.tasks.push(Task {
            label: task.to_string(),
            total,
            done: 0,
        });
        self.show_top();
    }

    fn step(&mut self) {
        if let Some(t) = self.tasks.last_mut() {
            t.done += 1;
        }
        self.bar.inc(1);
    }

    fn iteration(&mut self, iteration: usize, cost: f64, _damping: f64) {
        if let Some(t) = self.tasks.last_mut() {
            t.done = iteration as u64;
            self.bar.set_position(t.done);
            self.bar
                .set_message(format!("{}, cost {cost:.6e}", t.label));
        }
    }

    fn finish(&mut self) {
        self.tasks.pop();
        self.show_top();
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.bar.finish_and_clear();
    }
}
