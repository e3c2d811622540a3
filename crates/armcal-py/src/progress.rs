//! A Python callable as armcal's [`armcal::Observer`]: `progress(event, info)` with `event`
//! one of `"start"`, `"step"`, `"iteration"`, `"finish"` and `info` a dict (`task`, `total`
//! for a start; `iteration`, `cost`, `damping` for a solver iteration). The callable runs
//! with the GIL taken back (`Python::attach`) from armcal's worker thread; the first
//! exception it raises is kept, later events are dropped, and the call raises it at its end.

use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The observer of one call: the user's callable, if any, and its first error.
pub(crate) struct Progress {
    callback: Option<Py<PyAny>>,
    error: Option<PyErr>,
}

impl Progress {
    /// An observer calling `callback` (`None`: silent).
    pub(crate) fn new(callback: Option<Py<PyAny>>) -> Progress {
        Progress {
            callback,
            error: None,
        }
    }

    /// `result`, or the callback's first exception if it raised one.
    pub(crate) fn finish_call<T>(self, result: PyResult<T>) -> PyResult<T> {
        match self.error {
            Some(e) => Err(e),
            None => result,
        }
    }

    fn emit(&mut self, event: &str, fill: impl FnOnce(&Bound<'_, PyDict>) -> PyResult<()>) {
        let (Some(callback), None) = (&self.callback, &self.error) else {
            return;
        };
        let outcome = Python::attach(|py| -> PyResult<()> {
            let info = PyDict::new(py);
            fill(&info)?;
            callback.call1(py, (event, info))?;
            Ok(())
        });
        if let Err(e) = outcome {
            self.error = Some(e);
        }
    }
}

impl armcal::Observer for Progress {
    fn start(&mut self, task: &str, total: Option<usize>) {
        self.emit("start", |d| {
            d.set_item("task", task)?;
            d.set_item("total", total)
        });
    }

    fn step(&mut self) {
        self.emit("step", |_| Ok(()));
    }

    fn iteration(&mut self, iteration: usize, cost: f64, damping: f64) {
        self.emit("iteration", |d| {
            d.set_item("iteration", iteration)?;
            d.set_item("cost", cost)?;
            d.set_item("damping", damping)
        });
    }

    fn finish(&mut self) {
        self.emit("finish", |_| Ok(()));
    }
}
