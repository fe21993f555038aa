//! The rows of a sweep's CSV as Python dicts: all of them at once from
//! the text of a sweep kept in memory, or one by one from the file a
//! sweep wrote (`sweep(out=DIR)`), so that a sweep of millions of
//! samples is read without holding its rows.
//!
//! [`SweepRows`] reads its file only when asked: iteration streams it
//! from the start; `rows[k]` seeks to the nearest of the byte offsets
//! noted every [`STRIDE`] rows (found by one pass over the file, the
//! first time a row is asked for by position) and reads on from there.

use std::fs::File;
use std::io::BufReader;
use std::path::PathBuf;
use std::sync::Mutex;

use pyo3::exceptions::{PyIndexError, PyTypeError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PySlice, PyTuple};

use crate::error::Failure;

/// Rows between two noted byte offsets.
const STRIDE: u64 = 1024;

/// A cell as Python has it: a number as `int` or `float`, an empty cell
/// as `None`, anything else as `str`.
fn cell<'py>(py: Python<'py>, text: &str) -> PyResult<Bound<'py, PyAny>> {
    Ok(if text.is_empty() {
        py.None().into_bound(py)
    } else if let Ok(i) = text.parse::<i64>() {
        i.into_pyobject(py)?.into_any()
    } else if let Ok(f) = text.parse::<f64>() {
        f.into_pyobject(py)?.into_any()
    } else {
        text.into_pyobject(py)?.into_any()
    })
}

/// One row as a dict of the header's names.
fn row<'py>(
    py: Python<'py>,
    header: &csv::StringRecord,
    record: &csv::StringRecord,
) -> PyResult<Bound<'py, PyDict>> {
    let row = PyDict::new(py);
    for (name, text) in header.iter().zip(record.iter()) {
        row.set_item(name, cell(py, text)?)?;
    }
    Ok(row)
}

fn bad(what: &std::path::Path) -> impl Fn(csv::Error) -> PyErr + '_ {
    move |e| Failure::input(format!("{}: the sweep's CSV: {e}", what.display())).into()
}

/// Every row of a sweep's CSV text, as dicts.
pub fn all<'py>(py: Python<'py>, text: &str) -> PyResult<Bound<'py, PyList>> {
    let what = std::path::Path::new("<csv>");
    let mut reader = csv::Reader::from_reader(text.as_bytes());
    let header = reader.headers().map_err(bad(what))?.clone();
    let rows = PyList::empty(py);
    for record in reader.records() {
        rows.append(row(py, &header, &record.map_err(bad(what))?)?)?;
    }
    Ok(rows)
}

/// A reader of the file past its header.
fn open(path: &std::path::Path) -> PyResult<(csv::Reader<BufReader<File>>, csv::StringRecord)> {
    let file = File::open(path).map_err(|e| Failure::unreadable(path, "the sweep's CSV", &e))?;
    let mut reader = csv::Reader::from_reader(BufReader::new(file));
    let header = reader.headers().map_err(bad(path))?.clone();
    Ok((reader, header))
}

/// The rows of the `sweep.csv` a sweep wrote, read from the file when
/// asked: ``len(rows)``, ``rows[k]`` (a dict, as in ``Sweep.rows`` of a
/// sweep in memory), ``rows[a:b]`` (a list), iteration in index order.
/// Nothing is held but the file's name and a byte offset per 1024 rows.
#[pyclass(module = "chatterspice", frozen)]
pub struct SweepRows {
    path: PathBuf,
    len: u64,
    /// The byte offset of rows 0, STRIDE, 2·STRIDE, …, once needed.
    marks: Mutex<Option<Vec<csv::Position>>>,
}

impl SweepRows {
    pub fn new(path: PathBuf, len: u64) -> SweepRows {
        SweepRows {
            path,
            len,
            marks: Mutex::new(None),
        }
    }

    /// The positions of every STRIDE-th row, from one pass over the file.
    fn marks(&self) -> PyResult<Vec<csv::Position>> {
        let mut held = self.marks.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(marks) = held.as_ref() {
            return Ok(marks.clone());
        }
        let (mut reader, _) = open(&self.path)?;
        let mut marks = Vec::new();
        let mut record = csv::ByteRecord::new();
        let mut n = 0u64;
        loop {
            let at = reader.position().clone();
            if !reader
                .read_byte_record(&mut record)
                .map_err(bad(&self.path))?
            {
                break;
            }
            if n % STRIDE == 0 {
                marks.push(at);
            }
            n += 1;
        }
        *held = Some(marks.clone());
        Ok(marks)
    }

    /// Rows `start..start + count` (within the file).
    fn read<'py>(
        &self,
        py: Python<'py>,
        start: u64,
        count: u64,
    ) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let marks = self.marks()?;
        let (mut reader, header) = open(&self.path)?;
        let mark = usize::try_from(start / STRIDE).unwrap_or(usize::MAX);
        let Some(at) = marks.get(mark) else {
            return Ok(Vec::new());
        };
        reader.seek(at.clone()).map_err(bad(&self.path))?;
        let mut record = csv::StringRecord::new();
        let mut out = Vec::new();
        let mut n = mark as u64 * STRIDE;
        while out.len() as u64 != count
            && reader.read_record(&mut record).map_err(bad(&self.path))?
        {
            if n >= start {
                out.push(row(py, &header, &record)?);
            }
            n += 1;
        }
        Ok(out)
    }
}

#[pymethods]
impl SweepRows {
    /// Rows of the file at `path`, `len` of them, as pickle rebuilds them
    /// (the file is read again from where it is).
    #[new]
    fn py_new(path: PathBuf, len: u64) -> SweepRows {
        SweepRows::new(path, len)
    }

    /// The CSV the rows are read from.
    #[getter]
    fn path(&self) -> String {
        self.path.display().to_string()
    }

    fn __len__(&self) -> usize {
        usize::try_from(self.len).unwrap_or(usize::MAX)
    }

    fn __getitem__<'py>(
        &self,
        py: Python<'py>,
        key: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let len = self.len as isize;
        if let Ok(slice) = key.cast::<PySlice>() {
            let found = slice.indices(len)?;
            if found.step == 1 {
                let count = found.slicelength as u64;
                let rows = self.read(py, found.start.max(0) as u64, count)?;
                return Ok(PyList::new(py, rows)?.into_any());
            }
            let list = PyList::empty(py);
            let mut at = found.start;
            for _ in 0..found.slicelength {
                list.append(self.__getitem__(py, &at.into_pyobject(py)?.into_any())?)?;
                at += found.step;
            }
            return Ok(list.into_any());
        }
        let Ok(index) = key.extract::<isize>() else {
            return Err(PyTypeError::new_err(
                "sweep rows are indexed by an int or a slice",
            ));
        };
        let at = if index < 0 { index + len } else { index };
        if at < 0 || at >= len {
            return Err(PyIndexError::new_err(format!(
                "row {index} of a sweep of {len} rows"
            )));
        }
        match self.read(py, at as u64, 1)?.pop() {
            Some(row) => Ok(row.into_any()),
            None => Err(Failure::input(format!(
                "{}: has fewer than {} rows: the file changed since the sweep wrote it",
                self.path.display(),
                at + 1
            ))
            .into()),
        }
    }

    fn __iter__(&self) -> PyResult<SweepRowsIter> {
        let (reader, header) = open(&self.path)?;
        Ok(SweepRowsIter {
            state: Mutex::new(Some((reader, header))),
            path: self.path.clone(),
        })
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other
            .cast::<SweepRows>()
            .is_ok_and(|o| o.get().path == self.path && o.get().len == self.len)
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let r = slf.get();
        let fields = (r.path.clone(), r.len).into_pyobject(py)?;
        PyTuple::new(py, [slf.get_type().into_any(), fields.into_any()])
    }

    fn __repr__(&self) -> String {
        format!(
            "<chatterspice.SweepRows {} rows of {}>",
            self.len,
            self.path.display()
        )
    }
}

/// Iterates a sweep's rows from its file.
#[pyclass(module = "chatterspice")]
pub struct SweepRowsIter {
    state: Mutex<Option<(csv::Reader<BufReader<File>>, csv::StringRecord)>>,
    path: PathBuf,
}

#[pymethods]
impl SweepRowsIter {
    fn __iter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    fn __next__<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let mut state = self.state.lock().unwrap_or_else(|e| e.into_inner());
        let Some((reader, header)) = state.as_mut() else {
            return Ok(None);
        };
        let mut record = csv::StringRecord::new();
        if reader.read_record(&mut record).map_err(bad(&self.path))? {
            Ok(Some(row(py, header, &record)?))
        } else {
            *state = None;
            Ok(None)
        }
    }
}
