//! A run streamed to Python in chunks of events: the engine runs on a thread of its own, and a
//! bounded channel holds at most two chunks, so a long run never holds more than that.

use crate::collect::Columns;
use crate::{columns, value_error, Ask};
use poolsim::engine::{Event, Observer, RunError, Table, World};
use poolsim::run::execute;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::mpsc::{sync_channel, Receiver, SyncSender};
use std::sync::Mutex;

/// What the running thread sends.
enum Piece {
    /// A chunk of events.
    Events(Columns),
    /// The end: the summary's JSON text, or the run's error.
    Done(Result<String, String>),
}

/// Sends events on in chunks.
struct Chunker {
    table: Table,
    columns: Columns,
    chunk: usize,
    tx: SyncSender<Piece>,
}

impl Observer for Chunker {
    fn on_event(&mut self, ev: &Event, _: &dyn World) -> Result<(), RunError> {
        self.columns.push(ev, &self.table);
        if self.columns.len() >= self.chunk {
            let full = std::mem::take(&mut self.columns);
            self.tx
                .send(Piece::Events(full))
                .map_err(|_| RunError::Output("the stream was closed".into()))?;
        }
        Ok(())
    }

    fn reads_balls(&self) -> bool {
        false
    }
}

/// A run going on in the background, read chunk by chunk.
#[pyclass(module = "poolsim._native")]
pub struct Stream {
    rx: Mutex<Option<Receiver<Piece>>>,
    thread: Mutex<Option<std::thread::JoinHandle<()>>>,
    summary: Mutex<Option<String>>,
}

/// Starts a run of `scenario` as `ask` says, whose events come in chunks of at most `chunk`.
#[pyfunction]
pub fn stream(scenario: &str, ask: Ask, chunk: usize) -> PyResult<Stream> {
    if chunk == 0 {
        return Err(PyValueError::new_err("chunk: must be at least 1"));
    }
    let (scenario, cfg) = ask.prepare(scenario)?;
    let (tx, rx) = sync_channel(2);
    let thread = std::thread::spawn(move || {
        let mut chunker = Chunker {
            table: Table::new(&scenario),
            columns: Columns::default(),
            chunk,
            tx,
        };
        let done = execute(&scenario, &cfg, &mut chunker)
            .map(|r| serde_json::to_string(&r.summary).expect("a summary serializes"))
            .map_err(|e| e.to_string());
        let rest = std::mem::take(&mut chunker.columns);
        if rest.len() > 0 && chunker.tx.send(Piece::Events(rest)).is_err() {
            return;
        }
        let _ = chunker.tx.send(Piece::Done(done));
    });
    Ok(Stream {
        rx: Mutex::new(Some(rx)),
        thread: Mutex::new(Some(thread)),
        summary: Mutex::new(None),
    })
}

#[pymethods]
impl Stream {
    /// Itself: a stream is its own iterator.
    fn __iter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    /// The next chunk of events (a dict of columns), waiting for it with the lock released;
    /// `None` (the end of iteration) once the run has ended.
    fn __next__<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(rx) = self.rx.lock().expect("not poisoned").take() else {
            return Ok(None);
        };
        let (piece, rx) = py.detach(move || (rx.recv(), rx));
        *self.rx.lock().expect("not poisoned") = Some(rx);
        match piece {
            Ok(Piece::Events(c)) => Ok(Some(columns(py, c)?)),
            Ok(Piece::Done(done)) => {
                self.close();
                let summary = done.map_err(value_error)?;
                *self.summary.lock().expect("not poisoned") = Some(summary);
                Ok(None)
            }
            Err(_) => {
                self.close();
                Err(value_error("the run ended without a summary"))
            }
        }
    }

    /// The run summary's JSON text, once the stream has ended.
    #[getter]
    fn summary(&self) -> Option<String> {
        self.summary.lock().expect("not poisoned").clone()
    }

    /// Stops the run (if it still goes on) and waits for its thread.
    fn close(&self) {
        self.rx.lock().expect("not poisoned").take();
        if let Some(t) = self.thread.lock().expect("not poisoned").take() {
            let _ = t.join();
        }
    }
}

impl Drop for Stream {
    fn drop(&mut self) {
        self.close();
    }
}
