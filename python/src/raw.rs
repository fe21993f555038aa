//! Raw files (ngspice's or LTspice's) and run results as numpy arrays.
//!
//! A [`RawFile`] holds its plots in file order; each [`Plot`] is a
//! read-only mapping from vector name (as the file spells it: `time`,
//! `v(in)`, `frequency`) to a 1-D array, `float64` for a real vector and
//! `complex128` for a complex one. The file itself reads as its last plot,
//! the one `chatterspice raw FILE` prints without `--plot`.
//!
//! The arrays of a file read by `read_raw` are views of the data the
//! reader parsed, not copies: the parsed file is kept alive by a Python
//! object ([`RawData`]) that every array names as its base, and the
//! arrays are read-only (numpy refuses to make them writeable again, as
//! that base offers no writeable buffer). A pickled plot carries copies,
//! read-only again when unpickled.

use chatterspice::rawfile::{self, Vector, export};
use numpy::ndarray::ArrayView1;
use numpy::{Element, PyArray1, PyArrayMethods};
use pyo3::exceptions::{PyIndexError, PyKeyError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyTuple};

use crate::results::same;

/// A parsed raw file, owned by Python so that arrays can view it.
#[pyclass(module = "chatterspice", frozen, name = "_RawData")]
pub struct RawData {
    raw: rawfile::RawFile,
}

/// A read-only array viewing `values`, which `owner` holds.
fn view<'py, T: Element>(values: &[T], owner: &Bound<'py, RawData>) -> Bound<'py, PyAny> {
    // SAFETY: `values` lies in `owner`'s RawFile, which is never changed
    // or moved once owned by Python, and the array keeps `owner` alive
    // as its base.
    let array =
        unsafe { PyArray1::borrow_from_array(&ArrayView1::from(values), owner.clone().into_any()) };
    array.readwrite().make_nonwriteable();
    array.into_any()
}

/// The vectors of plot `index` of `owner`'s file as read-only views, by
/// name, in the file's order (a name given twice keeps its first).
fn views<'py>(owner: &Bound<'py, RawData>, index: usize) -> PyResult<Bound<'py, PyDict>> {
    let py = owner.py();
    let plot = &owner.get().raw.plots[index];
    let out = PyDict::new(py);
    for (i, variable) in plot.variables.iter().enumerate() {
        if out.contains(&variable.name)? {
            continue;
        }
        let array = match plot.vector(i) {
            Some(Vector::Real(v)) => view(v, owner),
            Some(Vector::Complex(v)) => view(v, owner),
            None => PyArray1::<f64>::zeros(py, 0, false).into_any(),
        };
        out.set_item(&variable.name, array)?;
    }
    Ok(out)
}

/// Every array of `vectors` made read-only (after unpickling).
fn freeze(vectors: &Bound<'_, PyDict>) -> PyResult<()> {
    let kwargs = PyDict::new(vectors.py());
    kwargs.set_item("write", false)?;
    for array in vectors.values() {
        array.call_method("setflags", (), Some(&kwargs))?;
    }
    Ok(())
}

/// The vectors of `plot`, by name, in the file's order. A name given
/// twice keeps its first vector.
pub fn vectors<'py>(py: Python<'py>, plot: &rawfile::Plot) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    for (i, variable) in plot.variables.iter().enumerate() {
        if out.contains(&variable.name)? {
            continue;
        }
        let array = match plot.vector(i) {
            Some(Vector::Real(v)) => PyArray1::from_slice(py, v).into_any(),
            Some(Vector::Complex(v)) => PyArray1::from_slice(py, v).into_any(),
            None => PyArray1::<f64>::zeros(py, 0, false).into_any(),
        };
        out.set_item(&variable.name, array)?;
    }
    Ok(out)
}

/// One plot of a raw file: a read-only mapping from vector name to array.
#[pyclass(module = "chatterspice", frozen)]
pub struct Plot {
    /// The plot's name, e.g. `Transient Analysis` or `AC Analysis`.
    #[pyo3(get)]
    name: String,
    /// Its place in the file, from 0.
    #[pyo3(get)]
    index: usize,
    /// Whether its vectors are complex (the scale may still be real).
    #[pyo3(get)]
    complex: bool,
    /// The number of points.
    #[pyo3(get)]
    points: usize,
    /// The plot's entry of `chatterspice raw FILE --format json`: title,
    /// date, commands, dialect, encoding, step, flags, variables.
    #[pyo3(get)]
    metadata: Py<PyDict>,
    vectors: Py<PyDict>,
}

#[pymethods]
impl Plot {
    /// A plot from its fields, as pickle rebuilds it (the arrays made
    /// read-only).
    #[new]
    fn new(
        name: String,
        index: usize,
        complex: bool,
        points: usize,
        metadata: Bound<'_, PyDict>,
        vectors: Bound<'_, PyDict>,
    ) -> PyResult<Plot> {
        freeze(&vectors)?;
        Ok(Plot {
            name,
            index,
            complex,
            points,
            metadata: metadata.unbind(),
            vectors: vectors.unbind(),
        })
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let p = slf.get();
        let fields = (
            &p.name,
            p.index,
            p.complex,
            p.points,
            p.metadata.bind(py),
            p.vectors.bind(py),
        )
            .into_pyobject(py)?;
        PyTuple::new(py, [slf.get_type().into_any(), fields.into_any()])
    }

    fn __eq__(slf: &Bound<'_, Self>, other: &Bound<'_, PyAny>) -> PyResult<bool> {
        let Ok(other) = other.cast::<Plot>() else {
            return Ok(false);
        };
        let (a, b) = (slf.get(), other.get());
        let py = slf.py();
        Ok(
            (&a.name, a.index, a.complex, a.points) == (&b.name, b.index, b.complex, b.points)
                && same(a.metadata.bind(py), b.metadata.bind(py))?
                && same(a.vectors.bind(py), b.vectors.bind(py))?,
        )
    }

    /// The vectors as a plain dict (the same arrays).
    #[getter]
    fn vectors<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.vectors.bind(py).copy()
    }

    fn __getitem__<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
        let vectors = self.vectors.bind(py);
        match vectors.get_item(name)? {
            Some(v) => Ok(v),
            None => Err(PyKeyError::new_err(format!(
                "plot {} ({}) has no vector `{name}`; it has {}",
                self.index,
                self.name,
                names(vectors)?
            ))),
        }
    }

    fn __len__(&self, py: Python<'_>) -> usize {
        self.vectors.bind(py).len()
    }

    fn __contains__(&self, py: Python<'_>, name: &str) -> PyResult<bool> {
        self.vectors.bind(py).contains(name)
    }

    fn __iter__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        Ok(self.vectors.bind(py).keys().try_iter()?.into_any())
    }

    /// The vector names, in the file's order.
    fn keys<'py>(&self, py: Python<'py>) -> Bound<'py, PyList> {
        self.vectors.bind(py).keys()
    }

    /// The arrays, in the file's order.
    fn values<'py>(&self, py: Python<'py>) -> Bound<'py, PyList> {
        self.vectors.bind(py).values()
    }

    /// `(name, array)` pairs, in the file's order.
    fn items<'py>(&self, py: Python<'py>) -> Bound<'py, PyList> {
        self.vectors.bind(py).items()
    }

    /// The vector `name`, or `default` when the plot has none of that name.
    #[pyo3(signature = (name, default=None))]
    fn get<'py>(
        &self,
        py: Python<'py>,
        name: &str,
        default: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Option<Bound<'py, PyAny>>> {
        Ok(self.vectors.bind(py).get_item(name)?.or(default))
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!(
            "<chatterspice.Plot {} {:?}: {} points of {}>",
            self.index,
            self.name,
            self.points,
            names(self.vectors.bind(py))?
        ))
    }
}

fn names(vectors: &Bound<'_, PyDict>) -> PyResult<String> {
    let names: Vec<String> = vectors.keys().extract()?;
    Ok(names
        .iter()
        .map(|n| format!("`{n}`"))
        .collect::<Vec<_>>()
        .join(", "))
}

/// A whole raw file: its plots, and the reader's warnings. Indexed by a
/// vector name, it is its last plot.
#[pyclass(module = "chatterspice", frozen)]
pub struct RawFile {
    /// The file as given.
    #[pyo3(get)]
    path: String,
    /// Every plot, in file order (each step of an LTspice `.step` run is
    /// one).
    #[pyo3(get)]
    plots: Py<PyList>,
    /// What the reader recovered from (a run cut short, extra points).
    #[pyo3(get)]
    warnings: Py<PyList>,
    /// `chatterspice raw FILE --format json`: every plot's metadata and
    /// the warnings.
    #[pyo3(get)]
    summary: Py<PyAny>,
}

impl RawFile {
    /// Read `path` whole.
    pub fn read(py: Python<'_>, path: &std::path::Path) -> PyResult<RawFile> {
        let raw = py
            .detach(|| rawfile::RawFile::read(path))
            .map_err(crate::error::Failure::from)?;
        let summary = crate::json(py, &export::summary_json(&raw))?;
        let warnings: Vec<String> = raw.warnings.iter().map(ToString::to_string).collect();
        let owner = Bound::new(py, RawData { raw })?;
        let plots = PyList::empty(py);
        for (index, plot) in owner.get().raw.plots.iter().enumerate() {
            let metadata = summary
                .get_item("plots")?
                .get_item(index)?
                .cast_into::<PyDict>()?;
            let p = Plot {
                name: plot.name.clone(),
                index,
                complex: plot.is_complex(),
                points: plot.points(),
                metadata: metadata.unbind(),
                vectors: views(&owner, index)?.unbind(),
            };
            plots.append(Py::new(py, p)?)?;
        }
        Ok(RawFile {
            path: path.display().to_string(),
            plots: plots.unbind(),
            warnings: PyList::new(py, warnings)?.unbind(),
            summary: summary.unbind(),
        })
    }

    fn last<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, Plot>> {
        let plots = self.plots.bind(py);
        match plots.len() {
            0 => Err(PyIndexError::new_err(format!("{}: no plot", self.path))),
            n => Ok(plots.get_item(n - 1)?.cast_into::<Plot>()?),
        }
    }
}

#[pymethods]
impl RawFile {
    /// A file from its fields, as pickle rebuilds it.
    #[new]
    fn new(
        path: String,
        plots: Bound<'_, PyList>,
        warnings: Bound<'_, PyList>,
        summary: Py<PyAny>,
    ) -> PyResult<RawFile> {
        for p in plots.iter() {
            p.cast::<Plot>()?;
        }
        Ok(RawFile {
            path,
            plots: plots.unbind(),
            warnings: warnings.unbind(),
            summary,
        })
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let r = slf.get();
        let fields = (
            &r.path,
            r.plots.bind(py),
            r.warnings.bind(py),
            r.summary.bind(py),
        )
            .into_pyobject(py)?;
        PyTuple::new(py, [slf.get_type().into_any(), fields.into_any()])
    }

    fn __eq__(slf: &Bound<'_, Self>, other: &Bound<'_, PyAny>) -> PyResult<bool> {
        let Ok(other) = other.cast::<RawFile>() else {
            return Ok(false);
        };
        let (a, b) = (slf.get(), other.get());
        let py = slf.py();
        if a.path != b.path
            || !same(a.warnings.bind(py), b.warnings.bind(py))?
            || !same(a.summary.bind(py), b.summary.bind(py))?
        {
            return Ok(false);
        }
        let (p, q) = (a.plots.bind(py), b.plots.bind(py));
        if p.len() != q.len() {
            return Ok(false);
        }
        for (x, y) in p.iter().zip(q.iter()) {
            if !x.eq(y)? {
                return Ok(false);
            }
        }
        Ok(true)
    }

    /// Plot `which`: its index in the file (negative counts from the end)
    /// or its name (the first plot of that name).
    fn plot<'py>(&self, py: Python<'py>, which: Bound<'py, PyAny>) -> PyResult<Bound<'py, Plot>> {
        let plots = self.plots.bind(py);
        if let Ok(name) = which.extract::<String>() {
            for p in plots.iter() {
                let p = p.cast_into::<Plot>()?;
                if p.get().name == name {
                    return Ok(p);
                }
            }
            let names: Vec<String> = plots
                .iter()
                .map(|p| p.cast_into::<Plot>().map(|p| format!("`{}`", p.get().name)))
                .collect::<Result<_, _>>()?;
            return Err(PyKeyError::new_err(format!(
                "{}: no plot named `{name}`; it has {}",
                self.path,
                names.join(", ")
            )));
        }
        let Ok(index) = which.extract::<isize>() else {
            return Err(crate::error::Failure::input(format!(
                "which = {} ({}): give a plot's index (an int, negative from the end) or its \
                 name (a str)",
                which.repr()?,
                which.get_type().name()?
            ))
            .into());
        };
        let n = plots.len() as isize;
        let at = if index < 0 { n + index } else { index };
        if !(0..n).contains(&at) {
            return Err(PyIndexError::new_err(format!(
                "{}: plot {index}, but the file has {n} plot(s) (0 to {})",
                self.path,
                n - 1
            )));
        }
        Ok(plots.get_item(at as usize)?.cast_into::<Plot>()?)
    }

    fn __getitem__<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
        self.last(py)?.get().__getitem__(py, name)
    }

    fn __len__(&self, py: Python<'_>) -> PyResult<usize> {
        Ok(self.last(py)?.get().__len__(py))
    }

    fn __contains__(&self, py: Python<'_>, name: &str) -> PyResult<bool> {
        self.last(py)?.get().__contains__(py, name)
    }

    fn __iter__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.last(py)?.get().__iter__(py)
    }

    /// The last plot's vector names.
    fn keys<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        Ok(self.last(py)?.get().keys(py))
    }

    /// The last plot's arrays.
    fn values<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        Ok(self.last(py)?.get().values(py))
    }

    /// The last plot's `(name, array)` pairs.
    fn items<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        Ok(self.last(py)?.get().items(py))
    }

    /// The last plot's vector `name`, or `default`.
    #[pyo3(signature = (name, default=None))]
    fn get<'py>(
        &self,
        py: Python<'py>,
        name: &str,
        default: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.last(py)?.get().get(py, name, default)
    }

    fn __repr__(&self, py: Python<'_>) -> String {
        let plots = self.plots.bind(py);
        let names: Vec<String> = plots
            .iter()
            .filter_map(|p| p.cast_into::<Plot>().ok())
            .map(|p| format!("{:?}", p.get().name))
            .collect();
        format!(
            "<chatterspice.RawFile {}: {} plot(s): {}>",
            self.path,
            plots.len(),
            names.join(", ")
        )
    }
}
